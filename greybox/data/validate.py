"""Validation of axis logs: a uniform, strictly increasing time base and finite values."""

from __future__ import annotations

import numpy as np

from ..errors import LogError
from .log import AxisLog

__all__ = ["check_time", "check_increasing", "check_finite", "check_velocity_units", "check_time_units", "UNIT_SLIPS",
           "SAMPLE_TIME_RANGE_S"]

#: Plausible sample times of a drive log [s]: from a current loop's 62.5 us (16 kHz, with margin) to the
#: 0.5 s of a slowly polled machine; a median step outside is a time column in the wrong unit.
SAMPLE_TIME_RANGE_S = (1e-5, 0.5)

#: Factors by which a logged velocity can disagree with d(position)/dt when one column's unit is wrong,
#: and what the factor points to (the fix names the column's unit suffix, e.g. ``--columns position_m=NAME``),
#: per kind of axis.
_LINEAR_SLIPS = {
    1000.0: "the position is probably in m under a mm name (position_m=NAME), or the velocity in um/s, or "
            "the time in ms under an s name (time_ms=NAME)",
    1e-3: "the position is probably in um under a mm name (position_um=NAME), or the velocity in m/s "
          "(velocity_m_s=NAME), or the time in s under an ms name (time_s=NAME)",
    60.0: "the velocity is probably in mm/min under a mm/s name (velocity_mm_min=NAME)",
    1.0 / 60.0: "the velocity is probably in mm/s under a mm/min name (velocity_mm_s=NAME)",
    1000.0 / 60.0: "the velocity is probably in mm/min while the position is in m, or in m/min mislabelled",
    60.0 / 1000.0: "the velocity is probably in m/min under a mm/s name (velocity_m_min=NAME)",
}
_ROTARY_SLIPS = {
    180.0 / np.pi: "the position is probably in rad under a deg name (position_rad=NAME), or the velocity "
                   "in deg/s under a rad/s name (velocity_deg_s=NAME)",
    np.pi / 180.0: "the velocity is probably in rad/s under a deg/s name (velocity_rad_s=NAME), or the "
                   "position in deg under a rad name (position_deg=NAME)",
    60.0: "the velocity is probably in deg/min under a deg/s name (velocity_deg_min=NAME)",
    1.0 / 60.0: "the velocity is probably in deg/s under a deg/min name (velocity_deg_s=NAME)",
    1.0 / 6.0: "the velocity is probably in rpm under a deg/s name (velocity_rpm=NAME)",
    6.0: "the velocity is probably in deg/s under an rpm name (velocity_deg_s=NAME)",
    360.0: "the position is probably in revolutions under a deg name (position_rev=NAME)",
}
UNIT_SLIPS = {"linear": _LINEAR_SLIPS, "rotary": _ROTARY_SLIPS}

#: Relative deviation of the factor from one of :data:`UNIT_SLIPS` that still counts as that slip.
_SLIP_TOLERANCE = 0.15


def check_time(time, *, source=None, tolerance: float = 0.25, nominal: float | None = None, start: int = 0) -> float:
    """Check that sample times are finite, strictly increasing and uniform.

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s].
    source : str or path-like, optional
        File the times came from, named in the error message.
    tolerance : float, default 0.25
        Allowed deviation of a time step from the nominal (median) step, as a
        fraction of it. A longer step is reported as a gap, a shorter one as jitter.
    nominal : float, optional
        Nominal step [s] of a whole log of which ``time`` is a stretch (default: the median step of ``time``).
    start : int, default 0
        Index in the whole log of ``time[0]``, for the sample numbers in the messages.

    Returns
    -------
    float
        Nominal sample time [s]: the median time step (or ``nominal``).

    Raises
    ------
    LogError
        For fewer than 2 samples, non-finite times, time going backwards or
        repeating, a gap or jitter beyond ``tolerance``. The message gives the
        sample index and time of the first offence.
    """
    if not 0.0 < tolerance < 1.0:
        raise ValueError(f"tolerance must lie in (0, 1), got {tolerance!r}")
    time = np.asarray(time, dtype=np.float64)
    steps = check_increasing(time, source=source, start=start)
    nominal = float(np.median(steps)) if nominal is None else float(nominal)
    off = np.flatnonzero(np.abs(steps - nominal) > tolerance * nominal)
    if off.size:
        k = int(off[0])
        if steps[k] > nominal:
            raise LogError(
                source,
                f"gap of {steps[k] * 1e3:.6g} ms at t = {time[k]:.9g} s (nominal step {nominal * 1e3:.6g} ms, "
                f"tolerance {tolerance:.0%}); --resample S splits the log into runs at gaps longer than "
                "--max-gap steps and resamples the rest",
            )
        raise LogError(
            source,
            f"time step jitter: step of {steps[k] * 1e3:.6g} ms at t = {time[k]:.9g} s deviates from the "
            f"nominal {nominal * 1e3:.6g} ms by more than {tolerance:.0%}; --resample S puts the log on a "
            "uniform grid",
        )
    return nominal


def check_increasing(time, *, source=None, start: int = 0) -> np.ndarray:
    """Check that there are at least 2 sample times, finite and strictly increasing; return the steps [s].

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s].
    source : str or path-like, optional
        File the times came from, named in the error message.
    start : int, default 0
        Index in the whole log of ``time[0]``, for the sample numbers in the messages.

    Returns
    -------
    ndarray, shape (n - 1,)
        Time steps [s], all positive.

    Raises
    ------
    LogError
        For fewer than 2 samples, non-finite times, time going backwards or repeating.
    """
    time = np.asarray(time, dtype=np.float64)
    n = time.shape[0]
    if n < 2:
        raise LogError(source, f"the log has {n} sample{'s' if n != 1 else ''}; at least 2 are needed")
    bad = np.flatnonzero(~np.isfinite(time))
    if bad.size:
        k = int(bad[0])
        raise LogError(source, f"time holds {time[k]} at sample {k + start}")
    steps = np.diff(time)
    nonpositive = np.flatnonzero(steps <= 0.0)
    if nonpositive.size:
        k = int(nonpositive[0]) + 1
        if steps[k - 1] == 0.0:
            raise LogError(source, f"time repeats at sample {k + start}: t = {time[k]:.9g} s twice")
        raise LogError(source, f"time goes backwards at sample {k + start}: t = {time[k]:.9g} s after "
                               f"{time[k - 1]:.9g} s")
    return steps


def check_time_units(time, *, source=None) -> None:
    """Refuse a time base whose median step no drive log has: a time column in the wrong unit.

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s], strictly increasing (:func:`check_increasing`).
    source : str or path-like, optional
        File the times came from, named in the error message.

    Raises
    ------
    LogError
        When the median step lies outside :data:`SAMPLE_TIME_RANGE_S`; the message names the time column's
        probable unit (ms or us written under an s name, or s under an ms name) and the name that fixes it.
    """
    time = np.asarray(time, dtype=np.float64)
    if time.shape[0] < 2:
        return
    step = float(np.median(np.diff(time)))
    low, high = SAMPLE_TIME_RANGE_S
    if step > high:
        unit = "ms" if step < 500.0 else "us"
        raise LogError(source, f"the time steps by {step:.6g} s (a log of {time[-1] - time[0]:.6g} s): the time is "
                               f"probably in {unit} under an s name; name the column time_{unit} (--columns "
                               f"time_{unit}=NAME)")
    if 0.0 < step < low:
        raise LogError(source, f"the time steps by {step:.3g} s ({1.0 / step:.3g} Hz): the time is probably in s "
                               "under an ms or us name; name the column time_s (--columns time_s=NAME)")


def check_finite(log: AxisLog, *, start: int | None = None) -> None:
    """Check that every channel of a log holds finite values only.

    Parameters
    ----------
    log : AxisLog
        The log to check (time is checked by :func:`check_time`).
    start : int, optional
        When ``log`` is a stretch of a longer log read block by block: the index of its first sample
        there (for the sample number in the message, which then counts the bad values of the stretch).

    Raises
    ------
    LogError
        Naming the first channel with a NaN or infinite value and the time of
        its first bad sample.
    """
    for name, values in log.named_channels():
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            k = int(bad[0])
            where = "in all" if start is None else f"in samples {start} to {start + len(log) - 1}"
            raise LogError(
                log.source or None,
                f"channel '{name}' holds {values[k]} at t = {log.time[k]:.9g} s (sample {k + (start or 0)}; "
                f"{bad.size} non-finite value{'s' if bad.size != 1 else ''} {where})",
            )


def check_velocity_units(log: AxisLog) -> float | None:
    """Compare a logged velocity with d(position)/dt; name a probable unit error.

    Parameters
    ----------
    log : AxisLog
        One run, time strictly increasing (steps may vary); checked only when it carries a velocity.

    Returns
    -------
    float or None
        The factor ``k`` of the least-squares fit ``v_logged = k d(position)/dt`` over the samples in
        motion; None when there is no logged velocity or too little motion to tell.

    Raises
    ------
    LogError
        When ``k`` lies within 15 % of a factor of :data:`UNIT_SLIPS` for the log's kind of axis (a column
        in the wrong unit; the nearest such factor is taken: the
        message names the factor and the column name that fixes it) or near -1 (velocity of the
        opposite sign).
    """
    if log.velocity is None or len(log) < 3:
        return None
    slope = np.gradient(log.position, log.time)
    moving = np.abs(slope) > 0.1 * np.percentile(np.abs(slope), 99)
    if np.count_nonzero(moving) < 50:
        return None
    d, v = slope[moving], log.velocity[moving]
    k = float(v @ d / (d @ d))
    source = log.source or None
    if abs(k + 1.0) < _SLIP_TOLERANCE:
        raise LogError(source, f"the logged velocity has the opposite sign of d(position)/dt (factor {k:.3g}); "
                               "check the sign convention of the velocity column")
    if k > 0:  # the nearest slip within the tolerance (rad vs deg, 57.3, lies close to per minute, 60)
        distance, reason = min((abs(np.log(k / factor)), reason) for factor, reason in UNIT_SLIPS[log.motion].items())
        if distance < np.log1p(_SLIP_TOLERANCE):
            raise LogError(source, f"the logged velocity is {k:.4g} x d(position)/dt: {reason}; give the column "
                                   "its unit with --columns")
    return k
