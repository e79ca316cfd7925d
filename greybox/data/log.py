"""The in-memory axis log: one contiguous recording (run) of one feed axis.

Several runs are kept as a list of :class:`AxisLog` objects and are never
joined into one array before differentiation or simulation, so nothing is ever
computed across the seam between two recordings.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Iterable, Mapping, Sequence

import numpy as np

from ..errors import LogError
from .quantities import MOTIONS, Motion

__all__ = ["AxisLog", "as_log_list", "split_runs", "EFFORT_UNITS"]

#: Units of the drive effort a log may carry: motor current [A] or, for drives
#: that log their load instead (e.g. the EMPS benchmark), force on the load side
#: [N] of a linear axis or torque [Nm] of a rotary one.
EFFORT_UNITS = ("A", "N", "Nm")


def _as_channel(values, name: str, n: int | None, source) -> np.ndarray:
    array = np.ascontiguousarray(values, dtype=np.float64)
    if array.ndim != 1:
        raise LogError(source, f"channel '{name}' must be one-dimensional, got shape {array.shape}")
    if n is not None and array.shape[0] != n:
        raise LogError(source, f"channel '{name}' has {array.shape[0]} samples, expected {n}")
    return array


@dataclass(frozen=True, eq=False)
class AxisLog:
    """One contiguous recording of one feed axis.

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s], strictly increasing.
    position : array_like, shape (n,)
        Axis position [mm], or [deg] for a rotary axis.
    effort : array_like, shape (n,)
        Drive effort: motor current [A], or the load in ``effort_unit``
        (force [N] of a linear axis, torque [Nm] of a rotary one).
    velocity : array_like, shape (n,), optional
        Axis velocity [mm/s or deg/s]; ``None`` until derived by :func:`greybox.data.prepare`.
    acceleration : array_like, shape (n,), optional
        Axis acceleration [mm/s^2 or deg/s^2]; ``None`` until derived.
    effort_unit : {"A", "N", "Nm"}, default "A"
        Unit of ``effort``; "N" for a linear axis only, "Nm" for a rotary one.
    axis : str, default ""
        Axis name, e.g. ``"X"``.
    dataset : str, default ""
        Dataset id, e.g. ``"A"``.
    source : str, default ""
        File the log was read from (empty for an in-memory log).
    motion : {"linear", "rotary"}, default "linear"
        Kind of axis (:mod:`greybox.data.quantities`): it sets the units of
        position, velocity, acceleration and load.
    extras : mapping of str to array_like, optional
        Further channels of the same length, e.g. the truth components of a
        synthetic log (``"truth_friction_A"``). Names carry their unit suffix.
    attrs : mapping, optional
        Free-form JSON-serialisable metadata (seed, trajectory description, ...).

    Notes
    -----
    The object is immutable; use :meth:`replace` to derive a modified copy.
    Validation of the time base (gaps, jitter, monotonicity) is done by
    :func:`greybox.data.validate.check_time`, not here, so that readers can
    report the file name with the problem.
    """

    time: np.ndarray
    position: np.ndarray
    effort: np.ndarray
    velocity: np.ndarray | None = None
    acceleration: np.ndarray | None = None
    effort_unit: str = "A"
    axis: str = ""
    dataset: str = ""
    source: str = ""
    motion: str = "linear"
    extras: Mapping[str, np.ndarray] = field(default_factory=dict)
    attrs: Mapping[str, object] = field(default_factory=dict)

    def __post_init__(self):
        src = self.source or None
        time = _as_channel(self.time, "time", None, src)
        n = time.shape[0]
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "position", _as_channel(self.position, "position", n, src))
        object.__setattr__(self, "effort", _as_channel(self.effort, "effort", n, src))
        for name in ("velocity", "acceleration"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, _as_channel(value, name, n, src))
        if self.motion not in MOTIONS:
            raise LogError(src, f"unknown motion {self.motion!r}; expected one of {', '.join(MOTIONS)}")
        if self.effort_unit not in self.units.effort_units:
            raise LogError(src, f"effort unit {self.effort_unit!r} does not fit a {self.motion} axis; expected one "
                                f"of {self.units.effort_units}")
        extras = {str(k): _as_channel(v, str(k), n, src) for k, v in dict(self.extras).items()}
        object.__setattr__(self, "extras", extras)
        object.__setattr__(self, "attrs", dict(self.attrs))

    # ------------------------------------------------------------------ basics
    def __len__(self) -> int:
        return self.time.shape[0]

    def __repr__(self) -> str:
        name = "/".join(p for p in (self.axis, self.dataset) if p) or "log"
        return (
            f"AxisLog({name}, n={len(self)}, duration={self.duration:.3f} s, "
            f"dt={self.sample_time * 1e3:.3f} ms, effort in {self.effort_unit}, "
            f"prepared={self.is_prepared}, extras={sorted(self.extras)})"
        )

    @property
    def current(self) -> np.ndarray:
        """Motor current [A]; raises if the log carries force instead."""
        if self.effort_unit != "A":
            raise LogError(self.source or None, f"log carries effort in {self.effort_unit}, not current in A")
        return self.effort

    @property
    def units(self) -> Motion:
        """Units and column names of the axis's motion (mm and N, or deg and Nm)."""
        return MOTIONS[self.motion]

    @property
    def effort_column(self) -> str:
        """Canonical column name of the effort: ``current_A``, ``force_N`` or ``torque_Nm``."""
        return self.units.effort_column(self.effort_unit)

    @property
    def sample_time(self) -> float:
        """Nominal sample time [s]: the median time step (NaN for fewer than 2 samples)."""
        if len(self) < 2:
            return float("nan")
        return float(np.median(np.diff(self.time)))

    @property
    def duration(self) -> float:
        """Time from the first to the last sample [s]."""
        return float(self.time[-1] - self.time[0]) if len(self) else 0.0

    @property
    def is_prepared(self) -> bool:
        """True when velocity and acceleration are present."""
        return self.velocity is not None and self.acceleration is not None

    def replace(self, **changes) -> "AxisLog":
        """Return a copy with the given fields replaced (see :func:`dataclasses.replace`)."""
        return dataclasses.replace(self, **changes)

    # ------------------------------------------------------------ selection
    def select(self, index) -> "AxisLog":
        """Return the samples selected by a slice or boolean/integer index.

        A selection that is not contiguous joins separate stretches of time;
        call :func:`greybox.data.prepare.trim` for time windows instead.

        Parameters
        ----------
        index : slice or ndarray of bool or int
            Applied to every channel alike: a slice, a boolean mask of shape ``(n,)``, or sample indices.
        """

        def pick(a):
            return None if a is None else a[index]

        return self.replace(
            time=self.time[index],
            position=self.position[index],
            effort=self.effort[index],
            velocity=pick(self.velocity),
            acceleration=pick(self.acceleration),
            extras={k: v[index] for k, v in self.extras.items()},
        )

    # ------------------------------------------------------------- tables
    def to_frame(self):
        """Return the log as a :class:`pandas.DataFrame` with canonical column names."""
        import pandas as pd

        return pd.DataFrame(dict(self.named_channels(time=True)))

    def named_channels(self, *, time: bool = False) -> list[tuple[str, np.ndarray]]:
        """The channels under their canonical column names: base channels present, then the extras.

        Parameters
        ----------
        time : bool, default False
            Start with ``("time_s", time)``.

        Returns
        -------
        list of (str, ndarray)
            E.g. ``position_mm``, ``velocity_mm_s``, ``acceleration_mm_s2``, ``current_A``, extras
            (``position_deg``, ``velocity_deg_s``, ... for a rotary axis).
        """
        units = self.units
        columns = [("time_s", self.time)] if time else []
        columns.append((units.position_column, self.position))
        if self.velocity is not None:
            columns.append((units.velocity_column, self.velocity))
        if self.acceleration is not None:
            columns.append((units.acceleration_column, self.acceleration))
        columns.append((self.effort_column, self.effort))
        columns += list(self.extras.items())
        return columns


def as_log_list(logs: AxisLog | Iterable[AxisLog]) -> list[AxisLog]:
    """Return ``logs`` as a list of runs, accepting a single :class:`AxisLog`.

    Parameters
    ----------
    logs : AxisLog or iterable of AxisLog
        One log, or several.

    Raises
    ------
    TypeError
        If an element is not an :class:`AxisLog`.
    ValueError
        If the list is empty.
    """
    if isinstance(logs, AxisLog):
        return [logs]
    runs: Sequence = list(logs)
    if not runs:
        raise ValueError("no axis logs given")
    for run in runs:
        if not isinstance(run, AxisLog):
            raise TypeError(f"expected AxisLog, got {type(run).__name__}")
    return list(runs)


def split_runs(runs: Sequence[AxisLog], prediction) -> list[np.ndarray]:
    """Split a prediction of concatenated runs into one array per run (a list passes through).

    Parameters
    ----------
    runs : sequence of AxisLog
        The runs the prediction is of; their lengths set the split.
    prediction : ndarray, shape (n,), or sequence of array_like
        Prediction of the runs concatenated (``n`` the total number of samples), or one array per run
        (checked against the runs' lengths and returned as float arrays).

    Raises
    ------
    ValueError
        If the lengths do not match the runs.
    """
    if isinstance(prediction, np.ndarray) and prediction.ndim == 1:
        lengths = [len(run) for run in runs]
        if prediction.size != sum(lengths):
            raise ValueError(f"runs of {sum(lengths)} samples in all but a prediction of {prediction.size}")
        return np.split(prediction, np.cumsum(lengths)[:-1])
    parts = [np.asarray(p, dtype=np.float64) for p in prediction]
    if [p.size for p in parts] != [len(run) for run in runs]:
        raise ValueError("the predictions do not match the runs in number or length")
    return parts
