"""The process share of every axis of a machine, and the resultant process force of its linear axes.

``greybox predict`` with a machine model (:mod:`greybox.models.machine`) runs
:func:`~greybox.predict.process.predict_process` on each axis and joins the
results on one time base: the first axis's time stamps. Axes logged on the
same clock (one CSV, a TDMS group) share them already; channels with their
own stamps (one MCAP channel per axis) are interpolated linearly onto the
first axis's time, and the metadata say so.

Where two or more linear axes have force from their axis files, the
resultant process force is the norm of their process forces,
``|F| = sqrt(F_X^2 + F_Y^2 + F_Z^2)`` [N], the magnitude of the force vector
the drives exert on the table (the machine's linear axes are orthogonal);
rotary axes' torques stay apart.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Mapping, Sequence

import numpy as np

from ..data.axis_config import AxisConfig
from ..data.log import AxisLog
from ..errors import GreyboxError
from ..models.chunked import DEFAULT_CHUNK_S
from .interval import ProcessInterval
from .process import ProcessResult, predict_process

__all__ = ["MachineProcessResult", "predict_machine", "RESULTANT_COLUMN"]

#: Column of the resultant process force of the linear axes.
RESULTANT_COLUMN = "force_process_resultant_N"


@dataclass(frozen=True)
class MachineProcessResult:
    """Process current (and force or torque) of every axis of a machine, on one time base.

    Attributes
    ----------
    results : mapping of str to ProcessResult
        Each axis's result on its own time stamps, in the machine's axis order.
    time : ndarray
        The common time [s]: the first axis's.
    name : str
        Machine name.
    attrs : dict
        JSON-able description: the machine, the axes, whether and which axes were interpolated.
    dataset : str
        Dataset id of the first axis's log.
    """

    results: Mapping[str, ProcessResult]
    time: np.ndarray
    name: str = ""
    attrs: dict = field(default_factory=dict)
    dataset: str = ""

    @property
    def axis(self) -> str:
        """The axes joined, e.g. ``"X+Y+Z"`` (names the MCAP topic ``/process/X+Y+Z``)."""
        return "+".join(self.results)

    @property
    def effort_unit(self) -> str:
        """Effort unit of the axes' logs, or ``"mixed"``."""
        units = {result.effort_unit for result in self.results.values()}
        return units.pop() if len(units) == 1 else "mixed"

    def _on_common_time(self, result: ProcessResult, values: np.ndarray) -> np.ndarray:
        if result.time.shape == self.time.shape and np.array_equal(result.time, self.time):
            return values
        return np.interp(self.time, result.time, values)

    def forces(self) -> dict[str, np.ndarray]:
        """Process force [N] of each linear axis whose force is known, on the common time."""
        return {axis: self._on_common_time(result, result.load) for axis, result in self.results.items()
                if result.motion == "linear" and result.load is not None}

    def resultant(self) -> np.ndarray | None:
        """Norm of the linear axes' process forces [N]; None with fewer than two such axes."""
        forces = self.forces()
        if len(forces) < 2:
            return None
        return np.sqrt(np.sum(np.square(list(forces.values())), axis=0))

    def columns(self) -> dict[str, np.ndarray]:
        """``time_s``, every axis's columns prefixed with its name (``X_current_process_A``,
        ``X_force_process_N``, ``C_torque_process_Nm``, ...), and :data:`RESULTANT_COLUMN` when two or
        more linear axes have force."""
        out = {"time_s": self.time}
        for axis, result in self.results.items():
            for name, values in result.columns().items():
                if name != "time_s":
                    out[f"{axis}_{name}"] = self._on_common_time(result, values)
        resultant = self.resultant()
        if resultant is not None:
            out[RESULTANT_COLUMN] = resultant
        return out

    def to_frame(self):
        """The columns of :meth:`columns` as a :class:`pandas.DataFrame`."""
        import pandas as pd

        return pd.DataFrame(self.columns())


def predict_machine(models: Mapping[str, object], runs: Mapping[str, Sequence[AxisLog]], *,
                    axis_configs: Mapping[str, AxisConfig | None] | None = None,
                    intervals: Mapping[str, ProcessInterval | None] | None = None, name: str = "",
                    chunk_s: float = DEFAULT_CHUNK_S,
                    progress: Callable[[str], Callable | None] | None = None) -> MachineProcessResult:
    """Process share of every axis of a cutting log.

    Parameters
    ----------
    models : mapping of str to CurrentModel
        A fitted model per axis (:class:`greybox.models.machine.MachineModel`'s ``models``).
    runs : mapping of str to sequence of AxisLog
        Each axis's prepared run(s) of the log.
    axis_configs : mapping of str to AxisConfig or None, optional
        Each axis's mechanics (force or torque); an axis without is predicted as current only.
    intervals : mapping of str to ProcessInterval or None, optional
        Each axis's calibrated interval.
    name : str, default ""
        Machine name.
    chunk_s : float, default 60.0
        Chunk length [s] of the predictions.
    progress : callable, optional
        ``progress(axis)`` returns the chunk progress callback of that axis (or None).

    Returns
    -------
    MachineProcessResult

    Raises
    ------
    GreyboxError
        When ``runs`` lacks an axis of ``models``, or the errors of
        :func:`~greybox.predict.process.predict_process` (named by axis).
    """
    missing = [axis for axis in models if axis not in runs]
    if missing:
        raise GreyboxError(f"no log of axis {', '.join(missing)} for the machine model")
    axis_configs, intervals = dict(axis_configs or {}), dict(intervals or {})
    results = {}
    for axis, model in models.items():
        try:
            results[axis] = predict_process(model, runs[axis], axis_config=axis_configs.get(axis),
                                            interval=intervals.get(axis), chunk_s=chunk_s,
                                            progress=progress(axis) if progress else None)
        except GreyboxError as error:
            raise GreyboxError(f"axis {axis}: {error}") from None
    first = next(iter(results.values()))
    interpolated = [axis for axis, result in results.items()
                    if not (result.time.shape == first.time.shape and np.array_equal(result.time, first.time))]
    attrs = {"machine": name, "axes": {axis: result.attrs for axis, result in results.items()},
             "time_of": next(iter(results)), "interpolated_axes": interpolated}
    return MachineProcessResult(results=results, time=first.time, name=name, attrs=attrs, dataset=first.dataset)
