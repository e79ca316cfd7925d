"""Where a model's residual lives: by operating regime, direction, position and time.

:func:`residual_by_regime` tabulates the residual (measured minus modelled
effort) over the operating regimes of :mod:`greybox.evaluate.regimes`
(reversals and low velocity, where pre-sliding lives; constant feed;
acceleration phases), the direction of motion, stretches of the position
range and of the time since the start of the run. :func:`residual_profiles`
gives binned mean residuals for plots, and :func:`structure_basis` the
indicator columns with which the discovery workflow tests whether structure
is left that no library effect explains.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
import scipy.sparse

from ..data.log import AxisLog
from ..evaluate.regimes import REGIME_NAMES, RegimeThresholds, regime_masks

__all__ = ["MOTION_STATES", "motion_states", "residual_by_regime", "residual_profiles", "structure_basis"]

#: Motion states of a sample: moving up or down, at rest after moving up or down.
MOTION_STATES = ("positive", "negative", "rest_after_positive", "rest_after_negative")

#: Edges [s] of the bins of time since the motion state last changed.
_CHANGE_EDGES_S = (0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, np.inf)


def motion_states(run: AxisLog, standstill_mm_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Motion state of every sample and the time since it last changed.

    Parameters
    ----------
    run : AxisLog
        One prepared run.
    standstill_mm_s : float
        Speed below which the axis is at rest [mm/s].

    Returns
    -------
    state : ndarray of int, shape (n,)
        Index into :data:`MOTION_STATES`; rest before the first motion counts
        as rest after positive motion.
    since_change_s : ndarray, shape (n,)
        Time since the state last changed [s] (since the start for the first stretch).
    """
    v = run.velocity
    moving = np.abs(v) >= standstill_mm_s
    direction = np.where(moving, np.where(v > 0, 0, 1), -1)
    index = np.where(direction >= 0, np.arange(v.size), 0)
    np.maximum.accumulate(index, out=index)
    last = np.where(direction[index] >= 0, direction[index], 0)
    state = np.where(moving, direction, 2 + last)
    change = np.flatnonzero(np.diff(state) != 0) + 1
    start_of_stretch = np.zeros(v.size, dtype=np.int64)
    start_of_stretch[change] = change
    np.maximum.accumulate(start_of_stretch, out=start_of_stretch)
    return state, run.time - run.time[start_of_stretch]


def _indicators(codes: np.ndarray, n_codes: int) -> scipy.sparse.csr_matrix:
    used = np.unique(codes)
    remap = np.full(n_codes, -1)
    remap[used] = np.arange(used.size)
    rows = np.arange(codes.size)
    return scipy.sparse.csr_matrix((np.ones(codes.size), (rows, remap[codes])), shape=(codes.size, used.size))


def _quantile_codes(values: np.ndarray, n_bins: int) -> tuple[np.ndarray, int]:
    edges = np.unique(np.quantile(values, np.linspace(0.0, 1.0, n_bins + 1)[1:-1]))
    return np.searchsorted(edges, values, side="right"), edges.size + 1


def structure_basis(runs: Sequence[AxisLog], thresholds: RegimeThresholds | None = None, *,
                    n_velocity_bins: int = 16, n_position_bins: int = 12, n_time_bins: int = 10,
                    n_acceleration_bins: int = 10) -> dict[str, scipy.sparse.csr_matrix]:
    """Indicator columns of generic residual structure, by family.

    Each family partitions the samples of all runs (concatenated); a
    residual with structure along it has bin means that differ.

    ``velocity``
        Quantile bins of the signed velocity.
    ``position_direction``
        Bins of equal width over the position range, separately for each
        direction of motion, plus one bin for rest.
    ``time``
        Bins of equal width of the time since the start of the run.
    ``acceleration``
        Quantile bins of the signed acceleration.
    ``after_change``
        Time since the motion state (see :func:`motion_states`) last changed,
        in bins from 10 ms to 1 s, per state: transients after reversals,
        starts and stops (pre-sliding, frictional memory at rest).

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs.
    thresholds : RegimeThresholds, optional
        Regime thresholds, of which the standstill speed [mm/s] is used; from the runs by default.
    n_velocity_bins : int, default 16
        Quantile bins of the velocity (fewer when quantiles coincide).
    n_position_bins : int, default 12
        Bins of the position range per direction of motion.
    n_time_bins : int, default 10
        Bins of the time since the start of the run.
    n_acceleration_bins : int, default 10
        Quantile bins of the acceleration (fewer when quantiles coincide).

    Returns
    -------
    dict of str to scipy.sparse.csr_matrix
        Family name -> indicator matrix ``(n_samples, n_bins_used)``.
    """
    if thresholds is None:
        thresholds = RegimeThresholds.from_logs(runs)
    v = np.concatenate([run.velocity for run in runs])
    a = np.concatenate([run.acceleration for run in runs])
    x = np.concatenate([run.position for run in runs])
    t = np.concatenate([run.time - run.time[0] for run in runs])
    states, since = zip(*(motion_states(run, thresholds.standstill_mm_s) for run in runs))
    state, since = np.concatenate(states), np.concatenate(since)

    velocity_codes, n_velocity = _quantile_codes(v, n_velocity_bins)
    acceleration_codes, n_acceleration = _quantile_codes(a, n_acceleration_bins)
    span = max(float(x.max() - x.min()), np.finfo(float).tiny)
    position_bin = np.minimum(((x - x.min()) / span * n_position_bins).astype(np.int64), n_position_bins - 1)
    position_codes = np.where(state < 2, state * n_position_bins + position_bin, 2 * n_position_bins)
    longest = max(float(t.max()), np.finfo(float).tiny)
    time_codes = np.minimum((t / longest * n_time_bins).astype(np.int64), n_time_bins - 1)
    change_bin = np.searchsorted(_CHANGE_EDGES_S, since, side="right") - 1
    n_change = len(_CHANGE_EDGES_S) - 1
    return {
        "velocity": _indicators(velocity_codes, n_velocity),
        "position_direction": _indicators(position_codes, 2 * n_position_bins + 1),
        "time": _indicators(time_codes, n_time_bins),
        "acceleration": _indicators(acceleration_codes, n_acceleration),
        "after_change": _indicators(state * n_change + change_bin, len(MOTION_STATES) * n_change),
    }


def _row(residual: np.ndarray, mask: np.ndarray, total_squares: float) -> dict:
    n = int(mask.sum())
    if n == 0:
        return {"n": 0, "fraction": 0.0, "rmse": float("nan"), "mean": float("nan"), "share_of_squares": 0.0}
    part = residual[mask]
    squares = float(part @ part)
    return {"n": n, "fraction": n / residual.size, "rmse": float(np.sqrt(squares / n)),
            "mean": float(part.mean()), "share_of_squares": squares / total_squares if total_squares > 0 else 0.0}


def residual_by_regime(runs: Sequence[AxisLog], residual, thresholds: RegimeThresholds | None = None, *,
                       n_position_bins: int = 5, n_time_bins: int = 5) -> dict[str, dict]:
    """The residual tabulated by regime.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs.
    residual : ndarray, shape (n_samples,)
        Measured minus modelled effort over the runs, concatenated [A, or N].
    thresholds : RegimeThresholds, optional
        Regime thresholds; from the runs by default.
    n_position_bins, n_time_bins : int
        Stretches of the position range and of the time since the run's start.

    Returns
    -------
    dict
        Regime name -> ``{"n", "fraction" (of the samples), "rmse", "mean"
        (the bias), "share_of_squares" (of the residual's sum of squares)}``.
        Regimes: those of :data:`greybox.evaluate.regimes.REGIME_NAMES`, the
        directions ``positive``, ``negative``, ``standstill``, then
        ``position lo..hi mm`` and ``time lo..hi s`` stretches.
    """
    residual = np.asarray(residual, dtype=float)
    if thresholds is None:
        thresholds = RegimeThresholds.from_logs(runs)
    masks = [regime_masks(run, thresholds) for run in runs]
    total = float(residual @ residual)
    table = {name: _row(residual, np.concatenate([m[name] for m in masks]), total) for name in REGIME_NAMES}
    v = np.concatenate([run.velocity for run in runs])
    moving = np.abs(v) >= thresholds.standstill_mm_s
    table["positive"] = _row(residual, moving & (v > 0), total)
    table["negative"] = _row(residual, moving & (v < 0), total)
    table["standstill"] = _row(residual, ~moving, total)
    x = np.concatenate([run.position for run in runs])
    edges = np.linspace(x.min(), x.max(), n_position_bins + 1)
    for low, high in zip(edges[:-1], edges[1:]):
        mask = (x >= low) & ((x < high) | (high == edges[-1]))
        table[f"position {low:.4g}..{high:.4g} mm"] = _row(residual, mask, total)
    t = np.concatenate([run.time - run.time[0] for run in runs])
    edges = np.linspace(0.0, t.max(), n_time_bins + 1)
    for low, high in zip(edges[:-1], edges[1:]):
        mask = (t >= low) & ((t < high) | (high == edges[-1]))
        table[f"time {low:.4g}..{high:.4g} s"] = _row(residual, mask, total)
    return table


def _binned_mean(values: np.ndarray, residual: np.ndarray, edges: np.ndarray) -> dict:
    index = np.clip(np.searchsorted(edges, values, side="right") - 1, 0, edges.size - 2)
    counts = np.bincount(index, minlength=edges.size - 1)
    sums = np.bincount(index, residual, minlength=edges.size - 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(counts > 0, sums / np.maximum(counts, 1), np.nan)
    return {"centre": 0.5 * (edges[:-1] + edges[1:]), "mean": mean, "n": counts}


def residual_profiles(runs: Sequence[AxisLog], residual, thresholds: RegimeThresholds | None = None,
                      n_bins: int = 60) -> dict[str, dict]:
    """Binned mean residual along position (per direction), velocity, time and time since reversal.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs.
    residual : ndarray, shape (n_samples,)
        Measured minus modelled effort over the runs, concatenated [A, or N].
    thresholds : RegimeThresholds, optional
        Regime thresholds, of which the standstill speed [mm/s] is used; from the runs by default.
    n_bins : int, default 60
        Number of bins of each profile.

    Returns
    -------
    dict
        ``position_positive``, ``position_negative`` (position [mm]),
        ``velocity`` [mm/s], ``time`` [s since the run's start],
        ``after_reversal`` [s since the last change of the motion state, moving
        samples]: each ``{"centre", "mean", "n"}`` arrays.
    """
    residual = np.asarray(residual, dtype=float)
    if thresholds is None:
        thresholds = RegimeThresholds.from_logs(runs)
    x = np.concatenate([run.position for run in runs])
    v = np.concatenate([run.velocity for run in runs])
    t = np.concatenate([run.time - run.time[0] for run in runs])
    states, since = zip(*(motion_states(run, thresholds.standstill_mm_s) for run in runs))
    state, since = np.concatenate(states), np.concatenate(since)
    position_edges = np.linspace(x.min(), x.max(), n_bins + 1)
    speed = float(np.percentile(np.abs(v), 99.5)) or 1.0
    moving = state < 2
    profiles = {}
    for name, mask in (("position_positive", state == 0), ("position_negative", state == 1)):
        profiles[name] = _binned_mean(x[mask], residual[mask], position_edges)
    profiles["velocity"] = _binned_mean(v, residual, np.linspace(-speed, speed, n_bins + 1))
    profiles["time"] = _binned_mean(t, residual, np.linspace(0.0, t.max(), n_bins + 1))
    since_edges = np.concatenate(([0.0], np.geomspace(1e-3, max(1.0, float(since.max())), n_bins)))
    signed = np.where(state == 0, 1.0, -1.0)
    profiles["after_reversal"] = _binned_mean(since[moving], (residual * signed)[moving], since_edges)
    return profiles
