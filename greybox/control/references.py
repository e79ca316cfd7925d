"""Position references for the closed-loop comparison of friction feed-forwards.

Tjahjowidodo et al. (IFAC 2005) compare friction compensators on two
*filtered random* position references: white noise through a 4th-order
Butterworth low-pass at 1 Hz, scaled once to a small stroke (motion mostly
in pre-sliding and at low speed, many reversals) and once to a large stroke
(gross sliding). :func:`filtered_random_reference` builds such a signal from
a seed; :func:`stroke_reference` gives the two strokes used here for a
ball-screw axis; :func:`reference_from_log` turns a recorded (prepared) axis
log into a reference.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..data.log import AxisLog
from ..errors import GreyboxError, LogError

__all__ = ["Reference", "STROKES_MM", "filtered_random_reference", "stroke_reference", "reference_from_log"]

#: Peak-to-peak stroke [mm] of the two references of the comparison: "low"
#: stays within a few pre-sliding ranges of a ball screw (tens of um) and
#: below the Stribeck velocity of a few mm/s; "high" reaches some hundreds of
#: mm/min to a few m/min (gross sliding).
STROKES_MM = {"low": 0.2, "high": 20.0}


@dataclass(frozen=True, eq=False)
class Reference:
    """A position reference on a uniform time grid, with its derivatives.

    Parameters
    ----------
    name : str
        Label used in tables and file names (e.g. ``"low-stroke"``).
    time : ndarray, shape (n,)
        Sample times [s], uniform step.
    position : ndarray, shape (n,)
        Reference position [mm].
    velocity : ndarray, shape (n,)
        Reference velocity [mm/s].
    acceleration : ndarray, shape (n,)
        Reference acceleration [mm/s^2].
    attrs : dict, optional
        JSON-serialisable description (generator, seed, stroke, source file).
    """

    name: str
    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    attrs: dict = field(default_factory=dict)

    def __post_init__(self):
        arrays = {}
        for channel in ("time", "position", "velocity", "acceleration"):
            values = np.ascontiguousarray(getattr(self, channel), dtype=float)
            if values.ndim != 1:
                raise GreyboxError(f"reference {self.name!r}: {channel} must be one-dimensional")
            if not np.all(np.isfinite(values)):
                raise GreyboxError(f"reference {self.name!r}: {channel} holds non-finite values")
            arrays[channel] = values
            object.__setattr__(self, channel, values)
        n = arrays["time"].size
        if n < 2 or any(values.size != n for values in arrays.values()):
            raise GreyboxError(f"reference {self.name!r}: needs at least 2 samples and equal channel lengths")
        steps = np.diff(arrays["time"])
        if np.any(steps <= 0.0):
            raise GreyboxError(f"reference {self.name!r}: time must increase")
        object.__setattr__(self, "attrs", dict(self.attrs))

    def __len__(self) -> int:
        return self.time.size

    @property
    def sample_time(self) -> float:
        """Step [s] of the time grid (the median step)."""
        return float(np.median(np.diff(self.time)))

    @property
    def duration(self) -> float:
        """Time from the first to the last sample [s]."""
        return float(self.time[-1] - self.time[0])

    def to_log(self, *, motion: str = "linear", effort_unit: str = "A") -> AxisLog:
        """The reference as a prepared :class:`AxisLog` (effort zero), to evaluate models on it.

        Parameters
        ----------
        motion : {"linear", "rotary"}, default "linear"
            Kind of axis the positions belong to (mm or deg).
        effort_unit : str, default "A"
            Unit of the (zero) effort, that of the model evaluated on the log.
        """
        return AxisLog(time=self.time, position=self.position, effort=np.zeros(self.time.size),
                       velocity=self.velocity, acceleration=self.acceleration, effort_unit=effort_unit,
                       motion=motion, dataset=self.name, attrs=self.attrs)


def _derivatives(position: np.ndarray, sample_time: float) -> tuple[np.ndarray, np.ndarray]:
    velocity = np.gradient(position, sample_time, edge_order=2)
    return velocity, np.gradient(velocity, sample_time, edge_order=2)


def filtered_random_reference(stroke_mm: float, duration_s: float, seed, *, sample_time_s: float = 0.002,
                              cutoff_hz: float = 1.0, order: int = 4, start_mm: float = 0.0,
                              name: str = "random") -> Reference:
    """White noise through a Butterworth low-pass, scaled to a peak-to-peak stroke.

    Standard normal white noise at the sample rate (drawn from
    ``numpy.random.default_rng(seed)``) is filtered causally from a zero
    filter state, so the reference starts at ``start_mm`` practically at
    rest, and is scaled so that ``max - min`` of the position equals
    ``stroke_mm``. Velocity and acceleration are central differences of the
    position; the signal has no content above a few times ``cutoff_hz``, so
    they are exact to a relative ``(2 pi f T)^2 / 6`` (3e-5 at 1 Hz, 2 ms).

    Parameters
    ----------
    stroke_mm : float
        Peak-to-peak position range [mm], positive.
    duration_s : float
        Length [s].
    seed : int or sequence of int
        Seed of the noise (anything :func:`numpy.random.default_rng` takes).
    sample_time_s : float, default 0.002
        Step [s].
    cutoff_hz : float, default 1.0
        Cut-off of the low-pass [Hz].
    order : int, default 4
        Order of the Butterworth low-pass.
    start_mm : float, default 0.0
        Position of the first sample [mm].
    name : str, default "random"
        Label of the reference.

    Returns
    -------
    Reference
    """
    from scipy.signal import butter, sosfilt

    if not (np.isfinite(stroke_mm) and stroke_mm > 0.0):
        raise GreyboxError(f"reference stroke must be positive, got {stroke_mm} mm")
    if not (np.isfinite(sample_time_s) and sample_time_s > 0.0):
        raise GreyboxError(f"reference sample time must be positive, got {sample_time_s} s")
    if not 0.0 < cutoff_hz < 0.5 / sample_time_s:
        raise GreyboxError(f"reference cut-off {cutoff_hz} Hz must lie between 0 and the Nyquist frequency "
                           f"{0.5 / sample_time_s:g} Hz")
    if not (np.isfinite(duration_s) and duration_s >= 20.0 * sample_time_s):
        raise GreyboxError(f"reference duration must be at least 20 samples, got {duration_s} s")
    n = int(np.floor(duration_s / sample_time_s + 1e-9)) + 1
    sos = butter(int(order), cutoff_hz, fs=1.0 / sample_time_s, output="sos")
    signal = sosfilt(sos, np.random.default_rng(seed).standard_normal(n))
    signal -= signal[0]
    position = start_mm + signal * (stroke_mm / np.ptp(signal))
    velocity, acceleration = _derivatives(position, sample_time_s)
    attrs = {"generator": "filtered_random_reference", "seed": np.asarray(seed).tolist(), "stroke_mm": float(stroke_mm),
             "cutoff_hz": float(cutoff_hz), "order": int(order)}
    return Reference(name, np.arange(n) * sample_time_s, position, velocity, acceleration, attrs)


def stroke_reference(kind: str, duration_s: float = 60.0, seed: int = 0, *, sample_time_s: float = 0.002,
                     start_mm: float = 0.0) -> Reference:
    """The low-stroke or high-stroke filtered random reference (see :data:`STROKES_MM`).

    Parameters
    ----------
    kind : {"low", "high"}
        Which stroke.
    duration_s : float, default 60.0
        Length [s].
    seed : int, default 0
        Seed of the noise; the two kinds draw different noise for one seed.
    sample_time_s : float, default 0.002
        Step [s].
    start_mm : float, default 0.0
        Position of the first sample [mm].

    Returns
    -------
    Reference
        Named ``"low-stroke"`` or ``"high-stroke"``.
    """
    if kind not in STROKES_MM:
        raise GreyboxError(f"unknown reference {kind!r}; choose from {', '.join(STROKES_MM)} or give a log")
    return filtered_random_reference(STROKES_MM[kind], duration_s, [int(seed), list(STROKES_MM).index(kind)],
                                     sample_time_s=sample_time_s, start_mm=start_mm, name=f"{kind}-stroke")


def reference_from_log(log: AxisLog, name: str | None = None) -> Reference:
    """The motion of a prepared axis log as a reference (its effort is ignored).

    Parameters
    ----------
    log : AxisLog
        Prepared run (velocity and acceleration present), uniform time step.
    name : str, optional
        Label; default the log's file stem, dataset id or ``"log"``.

    Returns
    -------
    Reference
        Time shifted to start at 0 s.
    """
    source = log.source or None
    if not log.is_prepared:
        raise LogError(source, "log is not prepared: a reference needs velocity and acceleration "
                               "(derive them with greybox.data.prepare first)")
    if len(log) < 20:
        raise LogError(source, f"log has {len(log)} samples; a reference needs at least 20")
    if name is None:
        from pathlib import Path

        name = Path(log.source).stem if log.source else (log.dataset or "log")
    attrs = {"generator": "reference_from_log", "source": log.source}
    try:
        return Reference(name, log.time - log.time[0], log.position, log.velocity, log.acceleration, attrs)
    except GreyboxError as error:
        raise LogError(source, str(error)) from None
