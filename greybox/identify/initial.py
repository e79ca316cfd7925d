"""Initial guesses of friction parameters from the data.

The static levels come from the *sliding* samples, those where the axis has
travelled a given distance since the last reversal of its direction, so that
the pre-sliding transition after a reversal does not bias them: a Stribeck +
viscous least-squares fit (:func:`greybox.identify.static.fit_stribeck`) on
them gives the Coulomb and static levels, the Stribeck velocity, the viscous
coefficient and the inertia (acceleration phases of the sliding samples).
The pre-sliding deflection comes from how far the axis travels after a
reversal until the friction has recovered most of its sliding level.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ..data.log import AxisLog
from ..errors import LogError
from .static import fit_coulomb, fit_stribeck, stribeck_curve

__all__ = ["SLIDING_DISTANCE_MM", "DEFAULT_DEFLECTION_MM", "motion_direction", "distance_since_reversal",
           "sliding_mask", "samples_at_speed", "static_initial_guess", "direction_level_ratio", "presliding_deflection",
           "presliding_travels", "largest_friction",
           "check_motion"]

#: Travel since the last reversal [mm] after which a sample counts as sliding.
#: Ball-screw pre-sliding ends within some 0.01 mm; 0.1 mm leaves a margin.
SLIDING_DISTANCE_MM = 0.1

#: Break-away deflection assumed when the data have no reversal from sliding [mm].
DEFAULT_DEFLECTION_MM = 0.01

#: Fewest sliding samples for a fit on sliding samples only; with fewer, all
#: moving samples are used.
_MIN_SLIDING_SAMPLES = 50


def check_motion(runs: Sequence[AxisLog]) -> None:
    """Raise :class:`LogError` if no run moves (velocity zero throughout).

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs, at least one; the error names the first one's source.
    """
    if not any(np.any(run.velocity != 0.0) for run in runs):
        raise LogError(runs[0].source or None,
                       "the velocity is zero throughout: friction cannot be identified from a standing axis")


def _stack(runs, masks):
    """Velocity, acceleration and effort of the masked samples of all runs, concatenated."""
    return tuple(np.concatenate([getattr(run, name)[m] for run, m in zip(runs, masks)])
                 for name in ("velocity", "acceleration", "effort"))


def samples_at_speed(runs: Sequence[AxisLog], min_speed: float = 0.0):
    """Velocity [mm/s], acceleration [mm/s^2] and effort [A] of the samples with ``|v| >= min_speed``.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs, at least one.
    min_speed : float, default 0.0
        Least speed ``|v|`` of a sample kept [mm/s]; 0 keeps every sample.

    Returns
    -------
    tuple of ndarray
        Velocity, acceleration and effort of the kept samples, the runs concatenated.

    Raises
    ------
    LogError
        If no sample of any run is that fast.
    """
    masks = [np.abs(run.velocity) >= min_speed for run in runs]
    if not any(np.any(m) for m in masks):
        raise LogError(runs[0].source or None, f"no sample moves at min_speed = {min_speed} mm/s or faster")
    return _stack(runs, masks)


def motion_direction(velocity: np.ndarray) -> np.ndarray:
    """Direction of motion per sample (+1/-1), zeros of the velocity take the previous direction.

    Samples before the first non-zero velocity get 0.

    Parameters
    ----------
    velocity : ndarray, shape (n,)
        Velocity [mm/s].

    Returns
    -------
    ndarray of int8, shape (n,)
    """
    sign = np.sign(velocity).astype(np.int8)
    last_moving = np.maximum.accumulate(np.where(sign != 0, np.arange(sign.size), 0))
    return sign[last_moving]


def _segment_starts(direction: np.ndarray) -> np.ndarray:
    """Index of the first sample of the constant-direction segment of every sample."""
    change = np.ones(direction.size, dtype=bool)
    change[1:] = direction[1:] != direction[:-1]
    return np.maximum.accumulate(np.where(change, np.arange(direction.size), 0))


def distance_since_reversal(time: np.ndarray, velocity: np.ndarray) -> np.ndarray:
    """Travel since the last reversal of the direction of motion [mm].

    Parameters
    ----------
    time : ndarray, shape (n,)
        Sample times [s].
    velocity : ndarray, shape (n,)
        Velocity [mm/s].

    Returns
    -------
    ndarray, shape (n,)
        At sample ``k``: ``sum |v_j| dt_j`` over the samples ``j < k`` since
        the direction last changed (the distance a forward-Euler simulation has
        moved before sample ``k``). The first segment of a run counts from its
        first sample.
    """
    dt = np.diff(time)
    dt = np.append(dt, np.median(dt) if dt.size else 0.0)
    travel = np.concatenate(([0.0], np.cumsum(np.abs(velocity) * dt)[:-1]))
    starts = _segment_starts(motion_direction(velocity))
    return travel - travel[starts]


def sliding_mask(run: AxisLog, min_distance: float = SLIDING_DISTANCE_MM) -> np.ndarray:
    """Samples of a prepared run that are moving and at least ``min_distance`` [mm] past a reversal.

    Parameters
    ----------
    run : AxisLog
        One prepared run.
    min_distance : float, default :data:`SLIDING_DISTANCE_MM`
        Travel since the last reversal from which a sample counts as sliding [mm].

    Returns
    -------
    ndarray of bool, shape (n,)
    """
    return (run.velocity != 0.0) & (distance_since_reversal(run.time, run.velocity) >= min_distance)


def static_initial_guess(runs: Sequence[AxisLog], *, fit_offset: bool = False,
                         min_distance: float = SLIDING_DISTANCE_MM) -> dict[str, float]:
    """Stribeck + viscous levels and inertia from the sliding samples of the runs.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs.
    fit_offset : bool, default False
        Fit a constant offset [A].
    min_distance : float, default :data:`SLIDING_DISTANCE_MM`
        Travel since the last reversal from which a sample counts as sliding [mm].

    Returns
    -------
    dict
        As :func:`greybox.identify.static.fit_stribeck`: ``J``, ``coulomb``,
        ``static``, ``v_s``, ``viscous``, ``offset``, ``sse``. When fewer than
        50 samples slide, all moving samples are used.
    """
    masks = [sliding_mask(run, min_distance) for run in runs]
    if sum(int(m.sum()) for m in masks) < _MIN_SLIDING_SAMPLES:
        masks = [run.velocity != 0.0 for run in runs]
    return fit_stribeck(*_stack(runs, masks), fit_offset=fit_offset)


def direction_level_ratio(runs: Sequence[AxisLog], *, min_distance: float = SLIDING_DISTANCE_MM,
                          bounds: tuple[float, float] = (0.05, 20.0)) -> float:
    """Ratio of the sliding friction level of negative to that of positive motion.

    An asymmetric Coulomb + viscous fit (:func:`greybox.identify.static.fit_coulomb`)
    of the sliding samples (all moving samples if fewer than 50 slide); the
    ratio of its two Coulomb levels, clipped to ``bounds``. 1 when either
    direction's level is not positive.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs.
    min_distance : float, default :data:`SLIDING_DISTANCE_MM`
        Travel since the last reversal from which a sample counts as sliding [mm].
    bounds : (float, float)
        Smallest and largest ratio returned.

    Returns
    -------
    float
        ``F_c- / F_c+``, dimensionless.
    """
    masks = [sliding_mask(run, min_distance) for run in runs]
    if sum(int(m.sum()) for m in masks) < _MIN_SLIDING_SAMPLES:
        masks = [run.velocity != 0.0 for run in runs]
    levels = fit_coulomb(*_stack(runs, masks), asymmetric=True)
    if not (levels["coulomb_pos"] > 0.0 and levels["coulomb_neg"] > 0.0):
        return 1.0
    return float(np.clip(levels["coulomb_neg"] / levels["coulomb_pos"], *bounds))


def largest_friction(runs: Sequence[AxisLog], static: dict[str, float]) -> float:
    """The largest friction measured: ``|effort - J a - offset|`` over all samples, with the static fit's ``J``.

    Every run starts from rest, so the drive overcame the break-away friction in it: no friction level of
    a model of these runs, at rest or at a speed they covered, lies beyond this measured one.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs.
    static : dict
        Static fit (:func:`static_initial_guess`): ``J`` [A s^2/mm] and ``offset`` [A] used.

    Returns
    -------
    float
        [A] (or the effort unit of the runs).
    """
    return float(max(np.max(np.abs(run.effort - static["J"] * run.acceleration - static["offset"])) for run in runs))


def presliding_travels(runs: Sequence[AxisLog], static: dict[str, float], *, fraction: float = 0.8,
                       min_distance: float = SLIDING_DISTANCE_MM) -> np.ndarray:
    """Travel after each reversal from sliding until the friction recovered ``fraction`` of its new level [mm].

    Parameters
    ----------
    runs, static, fraction, min_distance
        As in :func:`presliding_deflection`.

    Returns
    -------
    ndarray
        One travel [mm] per reversal that starts and ends in sliding and recovers; empty when none does.
    """
    travels = []
    for run in runs:
        v = run.velocity
        friction = run.effort - static["J"] * run.acceleration - static["offset"] - static["viscous"] * v
        level = stribeck_curve(v, static["static"], static["coulomb"], static["v_s"])
        direction = motion_direction(v)
        distance = distance_since_reversal(run.time, v)
        starts = np.flatnonzero((direction[1:] != direction[:-1]) & (direction[1:] != 0)
                                & (direction[:-1] != 0)) + 1
        ends = np.append(starts[1:], v.size)
        for start, end in zip(starts, ends):
            if distance[start - 1] < min_distance or distance[end - 1] < min_distance:
                continue
            d = direction[start]
            recovered = np.flatnonzero(d * friction[start:end] >= fraction * level[start:end])
            if recovered.size and distance[start + recovered[0]] > 0.0:
                travels.append(distance[start + recovered[0]])
    return np.asarray(travels, dtype=float)


def presliding_deflection(runs: Sequence[AxisLog], static: dict[str, float], *, fraction: float = 0.8,
                          min_distance: float = SLIDING_DISTANCE_MM) -> float | None:
    """Break-away deflection of an equivalent single spring from the reversals [mm].

    After a reversal from sliding, the friction goes from the sliding level in
    one direction to the level in the other. For a single spring that breaks
    away at deflection ``delta`` it reaches ``fraction`` of the new level after
    a travel of ``(1 + fraction) delta``. The travel is measured at every
    reversal that starts and ends in sliding (segments of at least
    ``min_distance`` on both sides); the median gives ``delta``.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs.
    static : dict
        Static fit with keys ``J``, ``coulomb``, ``static``, ``v_s``,
        ``viscous``, ``offset`` (see :func:`static_initial_guess`).
    fraction : float, default 0.8
        Fraction of the sliding level that marks the end of the transition.
    min_distance : float, default :data:`SLIDING_DISTANCE_MM`
        Travel that makes a segment sliding [mm].

    Returns
    -------
    float or None
        ``delta`` [mm], or ``None`` when the data have no such reversal.
    """
    travels = presliding_travels(runs, static, fraction=fraction, min_distance=min_distance)
    return float(np.median(travels)) / (1.0 + fraction) if travels.size else None
