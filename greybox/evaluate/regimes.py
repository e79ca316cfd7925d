"""Operating regimes of a feed axis, and metrics per regime.

A friction model that fits the bulk of a log well can still be poor where
friction matters most: near zero velocity and at reversals. Tjahjowidodo et al.
(IFAC 2005) therefore judge models separately on a low-velocity and a
high-velocity envelope. This module splits a prepared :class:`~greybox.data.log.AxisLog`
into such regimes (boolean masks over its samples) and computes
:func:`~greybox.metrics.metrics_table` on each.

Regimes (a sample may belong to several):

``all``
    Every sample.
``low_velocity`` / ``high_velocity``
    ``|v| < v_low`` / ``|v| >= v_low``. The low-velocity envelope holds
    pre-sliding, break-away and the Stribeck dip; the high-velocity envelope
    is gross sliding, dominated by Coulomb and viscous friction.
``reversal``
    A window of total width ``reversal_width_s`` around every change of the
    direction of motion: the samples from ``reversal_width_s / 2`` before the
    last moving sample of one direction to ``reversal_width_s / 2`` after the
    first moving sample of the other. "Moving" means ``|v| >= v_standstill``,
    so noise at rest does not count as reversals. A direction change after a
    rest longer than ``reversal_width_s`` is a start from rest, not a reversal.
``constant_feed``
    ``|a| <= a_steady`` and ``|v| >= v_low`` without interruption for at least
    ``min_feed_duration_s``.
``acceleration``
    ``|a| > a_steady``: the acceleration and deceleration phases.

Given the samples a model was not trained on (``outside`` of
:func:`metrics_by_regime`: :func:`~greybox.models.estimator.outside_any` of
:meth:`~greybox.models.estimator.CurrentModel.outside_training`), two more
rows split the samples by that model's own training region:

``inside_training`` / ``outside_training``
    The samples inside / outside the positions, speeds (and, for kernel
    models, inputs) the model's training runs covered; for a memoryless model
    standstill counts as outside. Together they hold every sample once.

Default thresholds (:meth:`RegimeThresholds.from_logs`) scale with the motion
in the logs, using the 99th percentile of ``|v|`` and ``|a|`` as a robust
maximum (insensitive to single spikes of a differentiated signal):
``v_low`` = 10 % of it, ``v_standstill`` = 0.5 %, ``a_steady`` = 5 % of the
robust maximum acceleration. When a Stribeck velocity ``v_s`` of the axis is
known, ``v_low = 3 * v_s`` is a physical alternative: above it, the Stribeck
excess friction has decayed to ``exp(-3)``, i.e. 5 % of its value at rest.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Iterable, Sequence

import numpy as np

from ..data.log import AxisLog, as_log_list, split_runs
from ..errors import LogError
from ..metrics import metrics_table

__all__ = ["REGIME_NAMES", "TRAINING_REGION_NAMES", "RegimeThresholds", "regime_masks", "metrics_by_regime"]

#: Names of the regimes, in the order reports list them.
REGIME_NAMES = ("all", "low_velocity", "high_velocity", "reversal", "constant_feed", "acceleration")
#: Names of the rows that split the samples by a model's training region, after :data:`REGIME_NAMES`.
TRAINING_REGION_NAMES = ("inside_training", "outside_training")


@dataclass(frozen=True)
class RegimeThresholds:
    """Thresholds that split a prepared axis log into operating regimes.

    Parameters
    ----------
    low_velocity_mm_s : float
        Boundary ``v_low`` between the low- and high-velocity envelopes [mm/s].
    standstill_mm_s : float
        Speed below which the axis counts as at rest [mm/s]; the direction of
        motion is undefined there.
    steady_acceleration_mm_s2 : float
        Largest ``|a|`` of constant feed [mm/s^2]; above it, the axis accelerates.
    reversal_width_s : float, default 0.05
        Total width of the window around a reversal [s].
    min_feed_duration_s : float, default 0.1
        Shortest stretch of constant feed that counts [s].
    """

    low_velocity_mm_s: float
    standstill_mm_s: float
    steady_acceleration_mm_s2: float
    reversal_width_s: float = 0.05
    min_feed_duration_s: float = 0.1

    def __post_init__(self):
        for name, value in asdict(self).items():
            if not np.isfinite(value) or value < 0:
                raise ValueError(f"regime threshold {name} must be finite and >= 0, got {value}")
        if self.standstill_mm_s > self.low_velocity_mm_s:
            raise ValueError(
                f"standstill_mm_s ({self.standstill_mm_s}) must not exceed low_velocity_mm_s ({self.low_velocity_mm_s})"
            )

    @classmethod
    def from_logs(
        cls,
        logs: AxisLog | Iterable[AxisLog],
        *,
        low_velocity_fraction: float = 0.1,
        standstill_fraction: float = 0.005,
        acceleration_fraction: float = 0.05,
        reversal_width_s: float = 0.05,
        min_feed_duration_s: float = 0.1,
    ) -> "RegimeThresholds":
        """Thresholds scaled to the motion in ``logs`` (all runs together).

        Parameters
        ----------
        logs : AxisLog or iterable of AxisLog
            Prepared logs (velocity and acceleration present).
        low_velocity_fraction, standstill_fraction : float
            ``v_low`` and ``v_standstill`` as fractions of the 99th percentile of ``|v|``.
        acceleration_fraction : float
            ``a_steady`` as a fraction of the 99th percentile of ``|a|``.
        reversal_width_s, min_feed_duration_s : float
            Passed through, see the class.
        """
        runs = [_require_prepared(log) for log in as_log_list(logs)]
        speed = np.concatenate([np.abs(run.velocity) for run in runs])
        accel = np.concatenate([np.abs(run.acceleration) for run in runs])
        v_max = float(np.percentile(speed, 99.0))
        a_max = float(np.percentile(accel, 99.0))
        return cls(
            low_velocity_mm_s=low_velocity_fraction * v_max,
            standstill_mm_s=standstill_fraction * v_max,
            steady_acceleration_mm_s2=acceleration_fraction * a_max,
            reversal_width_s=reversal_width_s,
            min_feed_duration_s=min_feed_duration_s,
        )


def _require_prepared(log: AxisLog) -> AxisLog:
    if not log.is_prepared:
        raise LogError(log.source or None, "regimes need velocity and acceleration; prepare the log first")
    return log


def _reversal_mask(time: np.ndarray, velocity: np.ndarray, thresholds: RegimeThresholds) -> np.ndarray:
    moving = np.flatnonzero(np.abs(velocity) >= thresholds.standstill_mm_s)
    mask = np.zeros(time.shape[0], dtype=bool)
    if moving.size < 2:
        return mask
    direction = np.sign(velocity[moving])
    change = np.flatnonzero(direction[1:] != direction[:-1])
    last, first = moving[change], moving[change + 1]
    keep = time[first] - time[last] <= thresholds.reversal_width_s
    half = 0.5 * thresholds.reversal_width_s
    starts = np.searchsorted(time, time[last[keep]] - half, side="left")
    stops = np.searchsorted(time, time[first[keep]] + half, side="right")
    coverage = np.zeros(time.shape[0] + 1, dtype=np.int64)
    np.add.at(coverage, starts, 1)
    np.add.at(coverage, stops, -1)
    return np.cumsum(coverage[:-1]) > 0


def _long_stretches(candidate: np.ndarray, time: np.ndarray, min_duration_s: float, sample_time: float) -> np.ndarray:
    """Keep the stretches of consecutive True samples lasting at least ``min_duration_s``."""
    edges = np.diff(np.concatenate(([0], candidate.astype(np.int8), [0])))
    starts = np.flatnonzero(edges == 1)
    stops = np.flatnonzero(edges == -1)  # exclusive
    mask = np.zeros(candidate.shape[0], dtype=bool)
    for start, stop in zip(starts, stops):
        if time[stop - 1] - time[start] + sample_time >= min_duration_s:
            mask[start:stop] = True
    return mask


def regime_masks(log: AxisLog, thresholds: RegimeThresholds | None = None) -> dict[str, np.ndarray]:
    """Boolean masks of the operating regimes of one prepared run.

    Parameters
    ----------
    log : AxisLog
        One prepared run (velocity [mm/s] and acceleration [mm/s^2] present).
    thresholds : RegimeThresholds, optional
        Defaults to :meth:`RegimeThresholds.from_logs` of this log.

    Returns
    -------
    dict of str to ndarray of bool, shape (n,)
        One mask per name in :data:`REGIME_NAMES`.

    Raises
    ------
    LogError
        If the log is not prepared.
    """
    _require_prepared(log)
    if thresholds is None:
        thresholds = RegimeThresholds.from_logs(log)
    speed = np.abs(log.velocity)
    accel = np.abs(log.acceleration)
    low = speed < thresholds.low_velocity_mm_s
    steady = accel <= thresholds.steady_acceleration_mm_s2
    sample_time = log.sample_time if len(log) > 1 else 0.0
    return {
        "all": np.ones(len(log), dtype=bool),
        "low_velocity": low,
        "high_velocity": ~low,
        "reversal": _reversal_mask(log.time, log.velocity, thresholds),
        "constant_feed": _long_stretches(steady & ~low, log.time, thresholds.min_feed_duration_s, sample_time),
        "acceleration": ~steady,
    }


def metrics_by_regime(
    logs: AxisLog | Sequence[AxisLog],
    predictions,
    thresholds: RegimeThresholds | None = None,
    *,
    outside=None,
) -> dict[str, dict[str, float | int]]:
    """Metrics of modelled against measured effort, overall and per regime.

    Parameters
    ----------
    logs : AxisLog or sequence of AxisLog
        Prepared runs; their ``effort`` is the measured value [A or N].
    predictions : array_like or sequence of array_like
        Modelled effort, same unit: one array per run, or one 1-D array of
        all runs concatenated in order (what a model's ``predict`` returns
        for a list of runs).
    thresholds : RegimeThresholds, optional
        Defaults to :meth:`RegimeThresholds.from_logs` of all runs together,
        so that every run is split by the same thresholds.
    outside : sequence of array_like of bool, optional
        Per run, True at the samples outside the model's training region
        (:func:`~greybox.models.estimator.outside_any`); adds the rows of
        :data:`TRAINING_REGION_NAMES`.

    Returns
    -------
    dict
        ``{regime: metrics_table(...)}`` for every name in :data:`REGIME_NAMES`
        (and :data:`TRAINING_REGION_NAMES` with ``outside``); the samples of
        all runs in a regime are pooled. A regime without samples has
        ``n == 0`` and nan metrics.
    """
    runs = as_log_list(logs)
    if isinstance(logs, AxisLog) or (isinstance(predictions, np.ndarray) and predictions.ndim == 1):
        predictions = split_runs(runs, np.asarray(predictions, dtype=np.float64))
    predictions = [np.asarray(p, dtype=np.float64).ravel() for p in predictions]
    if len(predictions) != len(runs):
        raise ValueError(f"{len(runs)} runs but {len(predictions)} predictions")
    for run, prediction in zip(runs, predictions):
        if prediction.shape[0] != len(run):
            raise ValueError(f"a run of {len(run)} samples has a prediction of {prediction.shape[0]}")
    if thresholds is None:
        thresholds = RegimeThresholds.from_logs(runs)
    masks = [regime_masks(run, thresholds) for run in runs]
    measured = np.concatenate([run.effort for run in runs])
    modelled = np.concatenate(predictions)
    result = {}
    for name in REGIME_NAMES:
        selected = np.concatenate([m[name] for m in masks])
        result[name] = metrics_table(measured[selected], modelled[selected])
    if outside is not None:
        flags = [np.asarray(f, dtype=bool).ravel() for f in outside]
        if [f.shape[0] for f in flags] != [len(run) for run in runs]:
            raise ValueError(f"runs of {[len(run) for run in runs]} samples but training-region flags of "
                             f"{[f.shape[0] for f in flags]}")
        beyond = np.concatenate(flags) if flags else np.zeros(0, dtype=bool)
        for name, selected in zip(TRAINING_REGION_NAMES, (~beyond, beyond)):
            result[name] = metrics_table(measured[selected], modelled[selected])
    return result
