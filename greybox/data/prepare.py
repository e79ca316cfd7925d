"""Preparation of axis logs for the models: validation, resampling, derivatives.

Each run is prepared on its own (:func:`prepare`), so no filter or difference
ever spans the seam between two recordings.

Default derivative filter
-------------------------
Velocity and acceleration come from the position by a zero-phase Butterworth
low-pass (4th order, run forward and backward) and central differences. The
default cut-off (:func:`default_cutoff`) is ``min(50 Hz, 0.4 * Nyquist)``:
50 Hz at 500 Hz (2 ms) and 1 kHz, 2 Hz for a 10 Hz log. Feed-drive motion has
no content above a few tens of Hz (the EMPS position loop has a closed-loop
bandwidth of about 20 Hz); above that the position holds encoder quantisation
and noise, which differentiation amplifies. Checked on the EMPS benchmark at
1 kHz: an inverse-dynamics least-squares fit (M, Fv, Fc, offset) on
derivatives filtered at 50 Hz gives the same parameters within 0.1 % as the
benchmark's own 100 Hz filter, and the same error against the raw force
(4.42 % vs 4.43 %); at 30 Hz and below the filter cuts into the motion (5.9 %
at 30 Hz, 10.9 % at 20 Hz). The cap at 0.4 * Nyquist keeps the filter
well-defined for coarse logs.
"""

from __future__ import annotations

import functools
from typing import Iterable

import numpy as np

from ..errors import LogError
from .log import AxisLog, as_log_list
from .validate import check_finite, check_increasing, check_time, check_time_units, check_velocity_units

__all__ = ["MAX_GAP_STEPS", "default_cutoff", "derivative_filter", "derivative_margin", "derive", "gap_steps",
           "resample", "split_at_gaps", "trim", "prepare"]

#: Default cut-off of the derivative filter for fast logs [Hz].
DEFAULT_CUTOFF_HZ = 50.0


def default_cutoff(sample_time: float) -> float:
    """Default derivative-filter cut-off [Hz] for a sample time [s]: ``min(50, 0.4 * Nyquist)``.

    Parameters
    ----------
    sample_time : float
        Nominal sample time [s], positive.
    """
    return min(DEFAULT_CUTOFF_HZ, 0.4 * 0.5 / sample_time)


def _lowpass(values: np.ndarray, sos: np.ndarray) -> np.ndarray:
    from scipy.signal import sosfiltfilt

    return sosfiltfilt(sos, values)


def derivative_filter(sample_time: float, *, cutoff_hz: float | None = None, order: int = 4,
                      source=None) -> tuple[np.ndarray, float]:
    """The low-pass of :func:`derive`: Butterworth second-order sections and the cut-off [Hz].

    Parameters
    ----------
    sample_time : float
        Nominal sample time [s].
    cutoff_hz : float, optional
        Cut-off [Hz]; default :func:`default_cutoff`.
    order : int, default 4
        Butterworth order.
    source : str, optional
        Log named in the error message.

    Raises
    ------
    LogError
        For a cut-off not between 0 and the Nyquist frequency.
    """
    nyquist = 0.5 / sample_time
    cutoff = default_cutoff(sample_time) if cutoff_hz is None else float(cutoff_hz)
    if not 0.0 < cutoff < nyquist:
        raise LogError(source, f"filter cut-off {cutoff:g} Hz must lie between 0 and the Nyquist frequency "
                               f"{nyquist:g} Hz")
    if int(order) != order or order < 1:
        raise ValueError(f"filter order must be a positive integer, got {order!r}")
    return _butter_sos(int(order), cutoff, 1.0 / sample_time).copy(), cutoff


@functools.lru_cache(maxsize=64)
def _butter_sos(order: int, cutoff_hz: float, rate_hz: float) -> np.ndarray:
    """Butterworth low-pass sections, designed once per (order, cut-off, rate): a live stream derives often."""
    from scipy.signal import butter

    return butter(order, cutoff_hz, fs=rate_hz, output="sos")


#: Relative size below which the edge transient of the derivative filter counts as gone.
_SETTLED = 1e-18


def derivative_margin(sample_time: float, *, cutoff_hz: float | None = None, order: int = 4) -> int:
    """Samples on each side of a stretch of a log that make :func:`derive` inside it the whole log's result.

    The forward-backward filter starts from the values at the ends of what it is given; the transient
    of that start decays with the slowest pole ``r`` of the filter as ``r^k`` over ``k`` samples. With
    this many samples beyond each end of the stretch (or the log's own end), it has decayed below
    ``1e-18`` of the signal by the time it reaches the stretch (plus the two samples of the central
    differences).

    Parameters
    ----------
    sample_time : float
        Nominal sample time [s].
    cutoff_hz : float, optional
        Cut-off [Hz]; default :func:`default_cutoff`.
    order : int, default 4
        Butterworth order.

    Returns
    -------
    int
    """
    sos, _ = derivative_filter(sample_time, cutoff_hz=cutoff_hz, order=order)
    slowest = max(float(np.max(np.abs(np.roots(section[3:])))) for section in sos)
    return int(np.ceil(np.log(_SETTLED) / np.log(slowest))) + 2


def derive(log: AxisLog, *, cutoff_hz: float | None = None, order: int = 4, tolerance: float = 0.25,
           sample_time: float | None = None) -> AxisLog:
    """Fill in velocity and acceleration where the log lacks them.

    Without logged velocity, the position is low-pass filtered (zero-phase
    Butterworth, ``sosfiltfilt``) and differentiated twice by central
    differences (:func:`numpy.gradient`) at the nominal sample time. With
    logged velocity, the velocity is kept as logged and the acceleration is
    the central difference of the filtered velocity. A log with both is
    returned unchanged.

    Parameters
    ----------
    log : AxisLog
        One run with a uniform time base (the median step is taken as the sample time).
    cutoff_hz : float, optional
        Filter cut-off [Hz]; default :func:`default_cutoff` of the sample time.
    order : int, default 4
        Butterworth order (the forward-backward run doubles the attenuation).
    tolerance : float, default 0.25
        Time-step tolerance of the uniformity check (see :func:`check_time`).
    sample_time : float, optional
        Nominal step [s] of the whole log when ``log`` is a stretch of it whose time steps have been
        checked already (:mod:`greybox.data.stream`); default: checked here, the median step.

    Returns
    -------
    AxisLog
        The log with velocity [mm/s] and acceleration [mm/s^2]; ``attrs``
        gains ``"derivative_filter"`` (cut-off, order, derived channels).

    Raises
    ------
    LogError
        For a time base that is not uniform within ``tolerance``, a cut-off
        not below the Nyquist frequency, or a log too short for the filter.
    """
    if log.is_prepared:
        return log
    source = log.source or None
    if sample_time is None:
        sample_time = check_time(log.time, source=source, tolerance=tolerance)
    sos, cutoff = derivative_filter(sample_time, cutoff_hz=cutoff_hz, order=order, source=source)
    needed = 3 * (2 * sos.shape[0] + 1) + 1
    if len(log) < needed:
        raise LogError(source, f"the log has {len(log)} samples; the {order}th-order filter needs at least {needed}")
    if log.velocity is None:
        velocity = np.gradient(_lowpass(log.position, sos), sample_time)
        acceleration = np.gradient(velocity, sample_time) if log.acceleration is None else log.acceleration
        derived = ["velocity"] + (["acceleration"] if log.acceleration is None else [])
    else:
        velocity = log.velocity
        acceleration = np.gradient(_lowpass(log.velocity, sos), sample_time)
        derived = ["acceleration"]
    attrs = dict(log.attrs)
    attrs["derivative_filter"] = {"cutoff_hz": cutoff, "order": int(order), "derived": derived}
    return log.replace(velocity=velocity, acceleration=acceleration, attrs=attrs)


def resample(log: AxisLog, sample_time: float, *, origin: float | None = None, first: int = 0) -> AxisLog:
    """Resample all channels to a uniform grid by linear interpolation.

    The grid's points are ``origin + k * sample_time`` for ``k = first, first + 1, ...``, up to the last
    sample: by default it starts at the first sample. There is no anti-alias filter: downsampling by an
    integer factor keeps every k-th sample of a uniform log. A stream resampled piece by piece
    (:mod:`greybox.live.timeline`) gives a piece the grid of its run with ``origin`` and ``first``.

    Parameters
    ----------
    log : AxisLog
        One run with strictly increasing time.
    sample_time : float
        New sample time [s].
    origin : float, optional
        Time of the grid's point 0 [s]; default the first sample's.
    first : int, default 0
        The first grid point wanted; ``origin + first * sample_time`` must not precede the first sample.

    Returns
    -------
    AxisLog
        The samples at the grid's points (none when no point lies within the log).
    """
    source = log.source or None
    if not np.isfinite(sample_time) or sample_time <= 0:
        raise LogError(source, f"sample time must be a positive number of seconds, got {sample_time!r}")
    if len(log) < 2:
        raise LogError(source, f"the log has {len(log)} samples; resampling needs at least 2")
    bad = np.flatnonzero(~(np.diff(log.time) > 0))
    if bad.size:
        k = int(bad[0]) + 1
        raise LogError(source, f"time is not strictly increasing at sample {k} (t = {log.time[k]:.9g} s); "
                               "cannot resample")
    origin = float(log.time[0]) if origin is None else float(origin)
    count = int(np.floor((log.time[-1] - origin) / sample_time * (1 + 1e-12))) + 1
    grid = origin + np.arange(first, max(first, count)) * sample_time
    if first == 0 and count == len(log) and np.allclose(log.time, grid, rtol=0.0, atol=1e-9 * sample_time):
        return log  # already on the grid: rounding of the time stamps must not interpolate every channel

    def interp(values):
        return None if values is None else np.interp(grid, log.time, values)

    return log.replace(
        time=grid,
        position=interp(log.position),
        effort=interp(log.effort),
        velocity=interp(log.velocity),
        acceleration=interp(log.acceleration),
        extras={name: interp(values) for name, values in log.extras.items()},
    )


def trim(log: AxisLog, start_s: float | None = None, stop_s: float | None = None) -> AxisLog:
    """Keep the samples with ``start_s <= time <= stop_s`` (times in s; None = open end).

    Parameters
    ----------
    log : AxisLog
        Log with increasing time.
    start_s : float, optional
        Start of the window on the log's time axis [s]; None keeps from the first sample.
    stop_s : float, optional
        End of the window on the log's time axis [s], inclusive; None keeps to the last sample.

    Raises
    ------
    LogError
        When no sample lies in the window.
    """
    keep = np.ones(len(log), dtype=bool)
    if start_s is not None:
        keep &= log.time >= start_s
    if stop_s is not None:
        keep &= log.time <= stop_s
    index = np.flatnonzero(keep)
    if not index.size:
        raise LogError(log.source or None, f"no samples between {start_s} s and {stop_s} s")
    return log.select(slice(index[0], index[-1] + 1))


#: Default of ``max_gap_steps``: a step longer than this many nominal steps splits a resampled log into runs.
MAX_GAP_STEPS = 5.0


def gap_steps(steps: np.ndarray, nominal: float, max_gap_steps: float) -> np.ndarray:
    """Which time steps are gaps: longer than ``max_gap_steps`` nominal steps (shorter ones are interpolated over).

    Parameters
    ----------
    steps : ndarray
        Time steps [s].
    nominal : float
        Nominal step [s] (a log's median step; a live stream's nominal step).
    max_gap_steps : float
        Longest step that stays inside a run, in nominal steps.

    Returns
    -------
    ndarray of int
        Indices into ``steps`` of the gaps.
    """
    return np.flatnonzero(steps > max_gap_steps * nominal)


def split_at_gaps(log: AxisLog, max_gap_steps: float = MAX_GAP_STEPS) -> list[AxisLog]:
    """Split one log into runs at every time step longer than ``max_gap_steps`` nominal (median) steps.

    Parameters
    ----------
    log : AxisLog
        One log with strictly increasing time (steps may vary).
    max_gap_steps : float, default :data:`MAX_GAP_STEPS`
        Longest step that stays inside a run, in nominal steps (> 1).

    Returns
    -------
    list of AxisLog
        The runs in time order; pieces of a single sample between two gaps are left out. Each run's
        ``attrs["split"]`` says which piece of how many it is and from which time it starts [s].

    Raises
    ------
    LogError
        For time not strictly increasing, or when no piece keeps two samples.
    """
    if not max_gap_steps > 1.0:
        raise ValueError(f"max_gap_steps must be larger than 1, got {max_gap_steps!r}")
    source = log.source or None
    steps = check_increasing(log.time, source=source)
    cuts = gap_steps(steps, float(np.median(steps)), max_gap_steps) + 1
    if not cuts.size:
        return [log]
    edges = np.concatenate(([0], cuts, [len(log)]))
    pieces = [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if b - a >= 2]
    if not pieces:
        raise LogError(source, f"every stretch between the {cuts.size} gaps holds a single sample")
    runs = []
    for index, (a, b) in enumerate(pieces):
        attrs = {**log.attrs, "split": {"run": index, "runs": len(pieces), "start_s": float(log.time[a]),
                                        "max_gap_steps": float(max_gap_steps)}}
        runs.append(log.select(slice(a, b)).replace(attrs=attrs))
    return runs


def prepare(
    logs: AxisLog | Iterable[AxisLog],
    *,
    cutoff_hz: float | None = None,
    sample_time: float | None = None,
    tolerance: float = 0.25,
    max_gap_steps: float = MAX_GAP_STEPS,
) -> list[AxisLog]:
    """Validate, optionally resample, and derive velocity/acceleration, run by run.

    A logged velocity is compared with d(position)/dt first: a factor of 1000 or 60 between them (metres
    under a millimetre name, per minute under per second) is an error that names the probable unit slip
    (:func:`~greybox.data.validate.check_velocity_units`).

    Parameters
    ----------
    logs : AxisLog or iterable of AxisLog
        One run or several; each is prepared on its own.
    cutoff_hz : float, optional
        Derivative-filter cut-off [Hz]; default :func:`default_cutoff`.
    sample_time : float, optional
        Resample to this sample time [s] before deriving: time stamps may then be irregular, and every
        log is first split into runs at steps longer than ``max_gap_steps`` (:func:`split_at_gaps`).
        Without it the time base must be uniform within ``tolerance``.
    tolerance : float, default 0.25
        Time-step tolerance of the validation without resampling (see :func:`check_time`).
    max_gap_steps : float, default :data:`MAX_GAP_STEPS`
        With ``sample_time``: the longest step, in nominal steps, that is interpolated over.

    Returns
    -------
    list of AxisLog
        Prepared runs (velocity and acceleration present), in input order; with ``sample_time`` a
        log split at gaps gives several consecutive runs.
    """
    prepared = []
    for run in as_log_list(logs):
        check_finite(run)
        check_time_units(run.time, source=run.source or None)
        check_velocity_units(run)
        if sample_time is None:
            check_time(run.time, source=run.source or None, tolerance=tolerance)
            pieces = [run]
        else:
            pieces = [resample(piece, sample_time) for piece in split_at_gaps(run, max_gap_steps)]
        prepared += [derive(piece, cutoff_hz=cutoff_hz, tolerance=tolerance) for piece in pieces]
    return prepared
