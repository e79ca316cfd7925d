"""Validation of axis logs: a uniform, strictly increasing time base and finite values."""

from __future__ import annotations

import numpy as np

from ..errors import LogError
from .log import AxisLog

__all__ = ["check_time", "check_finite"]


def check_time(time, *, source=None, tolerance: float = 0.25) -> float:
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

    Returns
    -------
    float
        Nominal sample time [s]: the median time step.

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
    n = time.shape[0]
    if n < 2:
        raise LogError(source, f"the log has {n} sample{'s' if n != 1 else ''}; at least 2 are needed")
    bad = np.flatnonzero(~np.isfinite(time))
    if bad.size:
        k = int(bad[0])
        raise LogError(source, f"time holds {time[k]} at sample {k}")
    steps = np.diff(time)
    nonpositive = np.flatnonzero(steps <= 0.0)
    if nonpositive.size:
        k = int(nonpositive[0]) + 1
        if steps[k - 1] == 0.0:
            raise LogError(source, f"time repeats at sample {k}: t = {time[k]:.9g} s twice")
        raise LogError(source, f"time goes backwards at sample {k}: t = {time[k]:.9g} s after {time[k - 1]:.9g} s")
    nominal = float(np.median(steps))
    off = np.flatnonzero(np.abs(steps - nominal) > tolerance * nominal)
    if off.size:
        k = int(off[0])
        if steps[k] > nominal:
            raise LogError(
                source,
                f"gap of {steps[k] * 1e3:.6g} ms at t = {time[k]:.9g} s (nominal step {nominal * 1e3:.6g} ms, "
                f"tolerance {tolerance:.0%}); split the log into runs at the gap",
            )
        raise LogError(
            source,
            f"time step jitter: step of {steps[k] * 1e3:.6g} ms at t = {time[k]:.9g} s deviates from the "
            f"nominal {nominal * 1e3:.6g} ms by more than {tolerance:.0%}; resample the log to a uniform grid",
        )
    return nominal


def check_finite(log: AxisLog) -> None:
    """Check that every channel of a log holds finite values only.

    Parameters
    ----------
    log : AxisLog
        The log to check (time is checked by :func:`check_time`).

    Raises
    ------
    LogError
        Naming the first channel with a NaN or infinite value and the time of
        its first bad sample.
    """
    channels = {"position_mm": log.position, log.effort_column: log.effort}
    if log.velocity is not None:
        channels["velocity_mm_s"] = log.velocity
    if log.acceleration is not None:
        channels["acceleration_mm_s2"] = log.acceleration
    channels.update(log.extras)
    for name, values in channels.items():
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            k = int(bad[0])
            raise LogError(
                log.source or None,
                f"channel '{name}' holds {values[k]} at t = {log.time[k]:.9g} s (sample {k}; "
                f"{bad.size} non-finite value{'s' if bad.size != 1 else ''} in all)",
            )
