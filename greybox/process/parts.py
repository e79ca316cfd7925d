"""The watched signal of each part of a log: the process force or current by a model, or the raw current.

With a model file (``greybox train``, trained on air cuts) the signal is what ``greybox predict`` computes
(:func:`~greybox.predict.process.predict_process`): the process force [N] (torque [Nm] on a rotary axis) with
an axis file, else the process current [A]. Without a model it is the measured current itself, as the
field's process monitors watch it (the raw signal). The log is read and prepared as ``greybox predict`` reads
it, then split into parts (:func:`~greybox.process.alignment.part_slices`); the model runs over each part from
its initial state, so that a part reads the same in a file of its own and in a long log.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping

import numpy as np

from ..errors import GreyboxError
from ..provenance import file_sha256
from .alignment import PART_COLUMN, part_slices

__all__ = ["Part", "PartSignal"]


@dataclass(frozen=True)
class Part:
    """One part of a series: its samples from its first one.

    Attributes
    ----------
    source : str
        Log file.
    number : int
        Part number: the part counter's value, else the part's place in the log (from 1).
    start_s : float
        Log time [s] of the part's first sample.
    time : ndarray
        Time [s] since the part's first sample.
    velocity : ndarray
        Axis velocity [mm/s or deg/s].
    signal : ndarray
        The watched signal (force [N], torque [Nm] or current [A]).
    extras : dict
        The log's further channels over the part (e.g. the twin's truth channels).
    level : ndarray or None
        The model's current without process [A] (inertia and friction), which re-levelling scales; None for
        the raw signal.
    current : ndarray or None
        The process current [A] behind a force (torque) signal, which re-levelling corrects before it is
        converted again; None for a signal that is a current.
    convert : callable or None
        ``convert(current_A, velocity)``: the force (torque) of a process current
        (:meth:`~greybox.data.axis_config.AxisConfig.process_load`); None for a signal that is a current.
    """

    source: str
    number: int
    start_s: float
    time: np.ndarray
    velocity: np.ndarray
    signal: np.ndarray
    extras: dict = field(default_factory=dict)
    level: np.ndarray | None = None
    current: np.ndarray | None = None
    convert: Callable | None = None

    @property
    def sample_time(self) -> float:
        """Median sample time [s]."""
        return float(np.median(np.diff(self.time))) if len(self.time) > 1 else 0.0


class PartSignal:
    """How the watched signal of a part is computed.

    Parameters
    ----------
    model : str, optional
        Model file; without it the signal is the raw measured current.
    axis_config : str, optional
        Axis file of the model's axis: the signal is then the process force (torque).
    read : mapping, optional
        Options of reading and preparing the logs (:func:`greybox.data.reading.read_prepared`).
    min_rest_s : float, default 2.0
        Shortest standstill [s] between two parts of a long log without a part counter.
    """

    def __init__(self, *, model: str | None = None, axis_config: str | None = None, read: Mapping | None = None,
                 min_rest_s: float = 2.0):
        if axis_config is not None and model is None:
            raise GreyboxError("an axis file converts a model's process current; the raw current needs none")
        if not min_rest_s > 0:
            raise GreyboxError(f"the rest between parts must be positive, got {min_rest_s}")
        self.model = model
        self.axis_config = axis_config
        self.read = dict(read or {})
        self.min_rest_s = float(min_rest_s)
        self._loaded = None

    @property
    def kind(self) -> str:
        """``"force"`` (process force or torque), ``"current"`` (process current) or ``"raw"`` (measured)."""
        if self.model is None:
            return "raw"
        return "force" if self.axis_config is not None else "current"

    def describe(self) -> dict:
        """JSON-able description: the kind, the model and axis files with their SHA-256."""
        return {"kind": self.kind, "model": self.model, "model_sha256": file_sha256(self.model) if self.model else None,
                "axis_config": self.axis_config, "min_rest_s": self.min_rest_s, "read": self.read}

    def _model(self):
        if self._loaded is None:
            from ..data.axis_config import read_axis_config
            from ..models.files import load_model

            config = read_axis_config(self.axis_config) if self.axis_config else None
            self._loaded = (load_model(self.model), config)
        return self._loaded

    def signal(self, runs) -> dict:
        """The watched signal of the prepared runs of one log, with what re-levelling needs.

        Parameters
        ----------
        runs : list of AxisLog
            The prepared runs of one log.

        Returns
        -------
        dict
            ``time`` [s], ``velocity``, ``signal``, ``unit``; ``level`` (the model's current [A]), ``current``
            (the process current [A] behind a force) and ``convert`` (current to force), each None where it does
            not apply.
        """
        if self.model is None:
            return {"time": np.concatenate([run.time for run in runs]),
                    "velocity": np.concatenate([run.velocity for run in runs]),
                    "signal": np.concatenate([run.effort for run in runs]), "unit": runs[0].effort_unit,
                    "level": None, "current": None, "convert": None}
        from ..predict.process import predict_process

        model, config = self._model()
        result = predict_process(model, runs, axis_config=config)
        found = {"time": result.time, "velocity": result.velocity, "level": result.model}
        if result.load is not None:
            return {**found, "signal": result.load, "unit": result.units.load_unit, "current": result.process,
                    "convert": config.process_load}
        return {**found, "signal": result.process, "unit": result.effort_unit, "current": None, "convert": None}

    def parts(self, path: str) -> tuple[list[Part], str]:
        """The parts of one log file and the signal's unit.

        Parameters
        ----------
        path : str
            Log file: one part, or a series (split by its part counter or at rests).

        Raises
        ------
        GreyboxError
            For a log that cannot be read or holds no motion.
        """
        from ..data.reading import read_prepared

        runs = read_prepared(str(path), self.read)
        parts, unit = [], ""
        for run in runs:
            counter = run.extras.get(PART_COLUMN)
            for part in part_slices(run.velocity, counter=counter, sample_time=run.sample_time,
                                    min_rest_s=self.min_rest_s):
                piece = run.select(part)
                if len(piece) < 2:
                    continue
                found = self.signal([piece])  # each part from the model's initial state, as a file of one part
                number = int(counter[part.start]) if counter is not None else len(parts) + 1
                parts.append(Part(str(path), number, float(piece.time[0]), found["time"] - piece.time[0],
                                  found["velocity"], found["signal"], dict(piece.extras), found["level"],
                                  found["current"], found["convert"]))
                unit = found["unit"]
        if not parts:
            raise GreyboxError(f"{Path(path).name}: the axis never moves; no part found")
        return parts, unit
