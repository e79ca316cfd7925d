"""Change detection on the fingerprint history: a baseline per feature and a two-sided CUSUM.

For every machine, axis and feature the daily value (the mean of that day's logs) is standardised with
the mean and standard deviation of the first ``baseline_days`` days that have a fingerprint:
``z_t = (x_t - m) / s``, clipped to ``[-clip, clip]`` so that one odd day (a log with an unusual motion)
adds at most ``clip - k`` to a sum and cannot raise an alarm alone. Two one-sided CUSUM sums run over all
days,

    S+_t = max(0, S+_{t-1} + z_t - k),   S-_t = max(0, S-_{t-1} - z_t - k),

and an alarm is raised on the first day either reaches ``h``. The reference value ``k = 1`` is half the
shift the detector is tuned to find quickly, two baseline standard deviations: the drifts watched for are
ramps that leave the day-to-day spread within days, and a sum with a larger ``k`` (and its calibrated,
lower ``h``) reaches its threshold on such a ramp sooner, at the cost of small sustained shifts (under one
standard deviation) being found later. (Until round 2 of issue 34 it was ``k = 0.5``, tuned to a shift of
one standard deviation; the change was chosen on development seeds, see docs/monitor.md.)

The threshold ``h`` is calibrated by simulation (:func:`calibrated_threshold`): with the baseline
estimated from only ``baseline_days`` days, the textbook ``h = 5`` of ``k = 0.5`` (an in-control run length
of about 900 days per sum when mean and deviation are known) raises several false alarms per axis and year,
because the estimated baseline is itself off by a fraction of a standard deviation. The calibration
simulates stable axes, estimates their baselines as the detector does and sets ``h`` so that the expected
number of false alarms is ``false_alarms_per_year`` per axis and year, by default 0.5: half the limit of
one that issue 34 sets, so that the rate measured on a finite number of stable axes can show the limit is
kept. The simulated days of each feature are drawn from that feature's shape on stable twin axes
(:func:`stable_shapes`, development seeds; until round 3 of issue 34 every feature was drawn standard
normal, which holds the total rate on the twin but puts twice the expected false alarms on the local
excess, whose days are skewed to high values, and half on its falls). The days are drawn independently:
on the twin's stable axes the lag-one autocorrelation of every feature is within +-0.04; a machine whose
features follow a slow temperature cycle from day to day would see more false alarms than calibrated.

The alarm names the feature, the direction of the change (``rises`` for S+, ``falls`` for S-), the day
the change started (the last day that sum was zero before it rose to ``h``), the day it was detected, the
mean shift since the start in baseline standard deviations, a one-sided Welch t-test p-value of the
days since the start against the baseline days (how sure), and where along the travel the friction departed
most from its baseline: the bin of the friction-along-travel map whose mean over the days since the start
differs most from its mean over the baseline days (:func:`travel_departure`).
"""

from __future__ import annotations

import datetime as dt
import functools
import json
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pyarrow as pa
from scipy import stats

from ..errors import ParameterError
from .fingerprint import FEATURES

__all__ = ["Alarm", "AxisTrend", "ChangeDetector", "STABLE_SHAPES_FILE", "calibrated_threshold", "cusum",
           "plant_shapes", "stable_shapes", "travel_departure"]


def cusum(z, *, k: float = 0.5, h: float = 5.0, clip: float = np.inf) -> tuple[np.ndarray, np.ndarray]:
    """The upper and lower CUSUM sums of a standardised series.

    Parameters
    ----------
    z : array_like, shape (n,)
        Standardised values (in baseline standard deviations); NaN (a day without a value) leaves the sums
        unchanged.
    k : float, default 0.5
        Allowance (reference value) per step [standard deviations].
    h : float, default 5.0
        Decision threshold [standard deviations]; the sums are not reset when they cross it.
    clip : float, default inf
        Values are clipped to ``[-clip, clip]`` first [standard deviations].

    Returns
    -------
    upper, lower : ndarray, shape (n,)
        ``S+`` and ``S-`` after each value (both non-negative).
    """
    z = np.clip(np.asarray(z, dtype=float), -clip, clip)
    upper, lower = np.zeros(len(z)), np.zeros(len(z))
    s_up = s_low = 0.0
    for i, value in enumerate(z):
        if np.isfinite(value):  # a day without a value leaves both sums as they were
            s_up = max(0.0, s_up + value - k)
            s_low = max(0.0, s_low - value - k)
        upper[i], lower[i] = s_up, s_low
    return upper, lower


#: Quantiles of each feature's standardised daily values on stable twin axes (scripts/stable_twin_shapes.py).
STABLE_SHAPES_FILE = Path(__file__).with_name("stable_twin_shapes.json")


def stable_shapes(features=FEATURES) -> np.ndarray:
    """The shapes of the features' daily values on stable twin axes, which :class:`ChangeDetector` calibrates on.

    Read from :data:`STABLE_SHAPES_FILE`, written by ``scripts/stable_twin_shapes.py`` from 30 stable twin
    axes of development seeds (200-229), 393 days each: every feature's series standardised by its own mean
    and standard deviation, pooled over the axes.

    Parameters
    ----------
    features : sequence of str, default FEATURES
        Features, in the order wanted.

    Returns
    -------
    ndarray, shape (len(features), m)
        Per feature, quantiles of its standardised stable daily values at ``m`` evenly spaced levels from 0
        to 1 [standard deviations], ascending.
    """
    document = json.loads(STABLE_SHAPES_FILE.read_text())
    return np.array([document["quantiles"][name] for name in features], dtype=float)


def plant_shapes(baseline_days, prior, *, prior_days: float, levels: int = 201) -> np.ndarray:
    """The shapes of the features' daily values on a plant's own baseline days, with the twin's as a prior.

    Per feature, the baseline days of every axis are standardised by that axis' baseline mean and standard
    deviation and pooled; the twin's shape (``prior``, quantiles) joins them with the weight of
    ``prior_days`` days, spread evenly over its quantiles. The result is the weighted quantiles of the pool.

    Parameters
    ----------
    baseline_days : sequence of sequence of ndarray
        Per feature, the baseline days of each axis (values in the feature's unit; NaN left out).
    prior : array_like, shape (n_features, m)
        Per feature, quantiles of the prior shape at ``m`` evenly spaced levels [standard deviations].
    prior_days : float
        Weight of the prior [days]; the plant's days weigh one each.
    levels : int, default 201
        Quantile levels returned, evenly spaced from 0 to 1.

    Returns
    -------
    ndarray, shape (n_features, levels)
        Per feature, the quantiles [standard deviations], ascending.
    """
    prior = np.asarray(prior, dtype=float)
    rows = []
    for feature_days, prior_row in zip(baseline_days, prior):
        pooled = []
        for days in feature_days:
            days = np.asarray(days, dtype=float)
            days = days[np.isfinite(days)]
            if len(days) >= 3 and np.std(days, ddof=1) > 0.0:
                pooled.append((days - days.mean()) / np.std(days, ddof=1))
        values = np.concatenate([prior_row] + pooled)
        weights = np.concatenate([np.full(len(prior_row), prior_days / len(prior_row)),
                                  np.ones(sum(len(p) for p in pooled))])
        order = np.argsort(values)
        cumulative = (np.cumsum(weights[order]) - 0.5 * weights[order]) / weights.sum()
        rows.append(np.interp(np.linspace(0.0, 1.0, levels), cumulative, values[order]))
    return np.array(rows)


@functools.lru_cache(maxsize=32)
def _yearly_maxima(shape: tuple | None, baseline_days: int, k: float, clip: float, n_sim: int,
                   seed: int) -> np.ndarray:
    """Largest upper and lower CUSUM sums over ``baseline_days`` + 365 simulated stable days (2 n_sim values)."""
    rng = np.random.default_rng(seed)
    if shape is None:
        x = rng.standard_normal((n_sim, baseline_days + 365))
    else:
        x = np.interp(rng.random((n_sim, baseline_days + 365)), np.linspace(0.0, 1.0, len(shape)), shape)
    base = x[:, :baseline_days]
    z = np.clip((x - base.mean(axis=1, keepdims=True)) / base.std(axis=1, ddof=1, keepdims=True), -clip, clip)
    s_up, s_low = np.zeros(n_sim), np.zeros(n_sim)
    top_up, top_low = np.zeros(n_sim), np.zeros(n_sim)
    for column in z.T:
        s_up = np.maximum(0.0, s_up + column - k)
        s_low = np.maximum(0.0, s_low - column - k)
        np.maximum(top_up, s_up, out=top_up)
        np.maximum(top_low, s_low, out=top_low)
    return np.concatenate([top_up, top_low])


def calibrated_threshold(*, baseline_days: int, n_features: int, false_alarms_per_year: float = 0.5,
                         k: float = 1.0, clip: float = 3.0, shapes=None, per_feature: bool = False,
                         n_sim: int = 2000, seed: int = 0):
    """The CUSUM threshold that gives a set number of false alarms per axis and year on stable axes.

    Stable axes are simulated over ``baseline_days`` plus 365 days: independent daily values of each
    feature, drawn from its ``shapes`` (standard normal without them). The baseline mean and standard
    deviation are estimated from the first ``baseline_days`` (as :class:`ChangeDetector` does: the
    estimation error is part of the simulation), and both CUSUM sums of each series run over all days. The
    threshold is the level that ``false_alarms_per_year`` of the ``2 * n_features`` sums of an axis are
    expected to reach per year: the quantile of all simulated sums' yearly maxima at
    ``1 - false_alarms_per_year / (2 * n_features)``. An expected count is a sum over the sums, whatever
    their correlation: correlated features (the two directions' levels move together) leave the rate as it
    is but make false alarms come in groups.

    Parameters
    ----------
    baseline_days : int
        Days that set the baseline.
    n_features : int
        Features watched per axis.
    false_alarms_per_year : float, default 0.5
        Expected false alarms per axis and year (365 days of daily values).
    k : float, default 1.0
        CUSUM allowance [standard deviations].
    clip : float, default 3.0
        Standardised values are clipped to ``[-clip, clip]``.
    shapes : array_like, shape (n_features, m), optional
        Per feature, quantiles of its standardised stable daily values at ``m`` evenly spaced levels from 0
        to 1 [standard deviations] (:func:`stable_shapes`); the days are drawn from them by interpolation.
        Without them every feature's days are standard normal.
    per_feature : bool, default False
        With ``shapes``: one threshold per feature, each set so that the feature's two sums raise an equal
        share, ``false_alarms_per_year / n_features``, of the false alarms (a feature with heavy tails gets a
        higher threshold, the others keep a lower one); without it one threshold for all.
    n_sim : int, default 2000
        Simulated stable series per feature.
    seed : int, default 0
        Seed of the simulation.

    Returns
    -------
    float or ndarray of shape (n_features,)
        Threshold ``h`` [standard deviations]; per feature with ``per_feature``.
    """
    share = false_alarms_per_year / (2.0 * n_features)
    if not 0.0 < share < 1.0:
        raise ParameterError(f"false_alarms_per_year must be in (0, {2 * n_features}), got {false_alarms_per_year}")
    if shapes is None:
        maxima = _yearly_maxima(None, baseline_days, float(k), float(clip), n_sim * n_features, seed)
    else:
        shapes = np.asarray(shapes, dtype=float)
        if shapes.ndim != 2 or len(shapes) != n_features or shapes.shape[1] < 2 \
                or not np.all(np.isfinite(shapes)) or np.any(np.diff(shapes, axis=1) < 0.0):
            raise ParameterError(f"shapes must hold {n_features} rows of at least 2 ascending quantiles, "
                                 f"got shape {shapes.shape}")
        per_row = [_yearly_maxima(tuple(row), baseline_days, float(k), float(clip), n_sim, seed + i)
                   for i, row in enumerate(shapes)]
        if per_feature:
            return np.array([np.quantile(row, 1.0 - share) for row in per_row])
        maxima = np.concatenate(per_row)
    return float(np.quantile(maxima, 1.0 - share))


@dataclass(frozen=True)
class Alarm:
    """A detected change of one feature of one axis.

    Parameters
    ----------
    machine, axis, feature : str
        Where and what changed.
    direction : {"rises", "falls"}
        Direction of the change.
    start : datetime.date
        Estimated first day of the change.
    detected : datetime.date
        Day the CUSUM crossed its threshold.
    shift : float
        Mean change since ``start`` [baseline standard deviations], signed.
    p_value : float
        One-sided Welch t-test of the days since ``start`` against the baseline days (NaN with fewer
        than two days since the start).
    position_mm : float, default NaN
        Where along the travel [mm] the friction departed most from its baseline since ``start`` (NaN
        without a friction-along-travel map).
    departure_A : float, default NaN
        That departure [A], signed.
    """

    machine: str
    axis: str
    feature: str
    direction: str
    start: dt.date
    detected: dt.date
    shift: float
    p_value: float
    position_mm: float = float("nan")
    departure_A: float = float("nan")

    def describe(self) -> str:
        """One line for people: what changed, which way, since when, how sure, where along the travel."""
        sure = "" if not np.isfinite(self.p_value) else f", p = {self.p_value:.2g}"
        where = "" if not np.isfinite(self.position_mm) else \
            f"; friction departs most at {self.position_mm:.1f} mm ({self.departure_A:+.3f} A)"
        return (f"{self.machine}/{self.axis}: {self.feature} {self.direction} since {self.start.isoformat()} "
                f"(detected {self.detected.isoformat()}; shift {self.shift:+.1f} sd{sure}{where})")


@dataclass
class AxisTrend:
    """The daily fingerprint of one axis with its baselines, CUSUM sums and alarms.

    Parameters
    ----------
    machine, axis : str
        The axis.
    dates : list of datetime.date
        Days with a fingerprint, in order.
    values, lower, upper : dict of str to ndarray
        Per feature, the daily mean of the point estimates and of the interval ends.
    baseline : dict of str to (float, float)
        Per feature, the baseline mean and standard deviation.
    upper_sum, lower_sum : dict of str to ndarray
        Per feature, the CUSUM sums ``S+`` and ``S-``.
    alarms : list of Alarm
        The first alarm of each feature and direction that has one, earliest first.
    severity : float
        Largest CUSUM sum of any feature over the threshold ``h`` (1 or more: an alarm).
    travel_map : tuple of (ndarray, ndarray)
        The friction-along-travel map per day: bin centres [mm] (shape (m,)) and the days' mean excess [A]
        (shape (n_days, m), NaN where a day has no value); empty arrays without maps.
    """

    machine: str
    axis: str
    dates: list
    values: dict
    lower: dict
    upper: dict
    baseline: dict = field(default_factory=dict)
    upper_sum: dict = field(default_factory=dict)
    lower_sum: dict = field(default_factory=dict)
    alarms: list = field(default_factory=list)
    severity: float = 0.0
    travel_map: tuple = (np.empty(0), np.empty((0, 0)))


def _daily_map(table: pa.Table, days: list) -> tuple[np.ndarray, np.ndarray]:
    """Bin centres [mm] and the daily mean excess [A] (days x bins, NaN where missing) of one axis' rows."""
    if "map_position_mm" not in table.column_names:
        return np.empty(0), np.empty((len(days), 0))
    positions = table.column("map_position_mm").to_pylist()
    excess = table.column("map_excess_A").to_pylist()
    centres = np.unique(np.round(np.concatenate([np.empty(0)] + [np.asarray(p or [], float) for p in positions]), 6))
    sums, counts = np.zeros((len(days), len(centres))), np.zeros((len(days), len(centres)))
    for date, where, values in zip(table.column("date").to_pylist(), positions, excess):
        if not where:
            continue
        columns = np.searchsorted(centres, np.round(np.asarray(where, float), 6))
        sums[days.index(date), columns] += np.asarray(values, float)
        counts[days.index(date), columns] += 1.0
    with np.errstate(invalid="ignore"):
        return centres, np.where(counts > 0, sums / np.maximum(counts, 1.0), np.nan)


def travel_departure(centres, daily, baseline: slice, since: slice) -> tuple[float, float]:
    """Where along the travel the friction departs most from its baseline, and by how much.

    Parameters
    ----------
    centres : ndarray, shape (m,)
        Bin centres [mm] of the friction-along-travel map.
    daily : ndarray, shape (n_days, m)
        Daily mean friction excess [A] per bin (NaN where missing).
    baseline, since : slice
        Days of the baseline and days since the change started.

    Returns
    -------
    (float, float)
        The bin centre [mm] of the largest absolute difference of the two periods' means, and that
        difference [A] (both NaN when no bin has values in both periods).
    """
    daily = np.asarray(daily, dtype=float)
    if daily.size == 0:
        return np.nan, np.nan
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        change = np.nanmean(daily[since], axis=0) - np.nanmean(daily[baseline], axis=0)
    if not np.any(np.isfinite(change)):
        return np.nan, np.nan
    worst = int(np.nanargmax(np.abs(change)))
    return float(centres[worst]), float(change[worst])


def _daily(table: pa.Table) -> tuple[list, dict, dict, dict]:
    """Dates and the daily means of every feature and interval end of one axis' rows."""
    dates = table.column("date").to_pylist()
    days = sorted(set(dates))
    index = np.array([days.index(d) for d in dates])

    def mean(name):
        values = table.column(name).to_numpy(zero_copy_only=False).astype(float)
        finite = np.isfinite(values)
        total = np.bincount(index[finite], weights=values[finite], minlength=len(days))
        counts = np.bincount(index[finite], minlength=len(days))
        return np.where(counts > 0, total / np.maximum(counts, 1), np.nan)

    with np.errstate(invalid="ignore"):
        values = {f: mean(f) for f in FEATURES}
    return days, values, {f: mean(f"{f}_lo") for f in FEATURES}, {f: mean(f"{f}_hi") for f in FEATURES}


class ChangeDetector:
    """Baseline and two-sided CUSUM per feature of every axis in a fingerprint history.

    Parameters
    ----------
    baseline_days : int, default 28
        Number of first days (with a fingerprint) that set each feature's baseline; at least 3.
    k : float, default 1.0
        CUSUM allowance [baseline standard deviations]: half the shift the detector is tuned to.
    h : float, optional
        CUSUM threshold [baseline standard deviations]; by default :func:`calibrated_threshold` for
        ``false_alarms_per_year`` on days drawn from ``shapes``.
    false_alarms_per_year : float, default 0.5
        Expected false alarms per axis and year on stable axes, which sets the default ``h``: half the
        issue's limit of one, so that a measured rate can confirm the limit.
    shapes : {"plant", "twin", "normal"}, default "plant"
        What the threshold's calibration draws stable days from: each feature's daily values on stable twin
        axes (:func:`stable_shapes`: the local excess, a largest value along the travel, is skewed to high
        values); the plant's own baseline days, every axis of the history standardised by its baseline and
        pooled per feature, with the twin's shapes as a prior worth ``prior_days`` days
        (:func:`plant_shapes`); or independent standard normal values.
    prior_days : float, default 28.0
        Weight [days] of the twin's shapes in ``shapes="plant"``: one axis' baseline.
    per_feature : bool, default True
        One threshold per feature, each calibrated on its own shape for an equal share of the false alarms
        (:func:`calibrated_threshold`); without it one threshold for all features.
    clip : float, default 3.0
        Standardised daily values are clipped to ``[-clip, clip]`` [baseline standard deviations].
    features : sequence of str, optional
        Features watched; all of :data:`~greybox.monitor.fingerprint.FEATURES` by default.

    Attributes
    ----------
    threshold_ : float
        The threshold ``h`` used, the largest of ``thresholds_`` [baseline standard deviations].
    thresholds_ : dict of str to float
        The threshold of each feature watched [baseline standard deviations] (all the same unless
        ``per_feature``).
    trends_ : list of AxisTrend
        One per machine and axis, most severe first.
    alarms_ : list of Alarm
        Every alarm, most severe axis first, earliest first within an axis.
    """

    def __init__(self, *, baseline_days: int = 28, k: float = 1.0, h: float | None = None,
                 false_alarms_per_year: float = 0.5, shapes: str = "plant", prior_days: float = 28.0,
                 per_feature: bool = True, clip: float = 3.0, features=None):
        self.baseline_days = baseline_days
        self.k = k
        self.h = h
        self.false_alarms_per_year = false_alarms_per_year
        self.shapes = shapes
        self.prior_days = prior_days
        self.per_feature = per_feature
        self.clip = clip
        self.features = features

    def _check_params(self) -> tuple:
        if isinstance(self.baseline_days, bool) or not isinstance(self.baseline_days, (int, np.integer)) \
                or self.baseline_days < 3:
            raise ParameterError(f"baseline_days must be a whole number of at least 3, got {self.baseline_days!r}")
        h = 1.0 if self.h is None else self.h
        if not (np.isfinite(self.k) and self.k >= 0.0 and np.isfinite(h) and h > 0.0 and self.clip > self.k):
            raise ParameterError(f"need k >= 0, h > 0 and clip > k, got k = {self.k}, h = {self.h}, "
                                 f"clip = {self.clip}")
        features = tuple(FEATURES if self.features is None else self.features)
        unknown = [f for f in features if f not in FEATURES]
        if unknown or not features:
            raise ParameterError(f"unknown features {', '.join(unknown) or '(none given)'}; "
                                 f"choose from {', '.join(FEATURES)}")
        if self.shapes not in ("plant", "twin", "normal"):
            raise ParameterError(f"shapes must be 'plant', 'twin' or 'normal', got {self.shapes!r}")
        if not (np.isfinite(self.prior_days) and self.prior_days > 0.0):
            raise ParameterError(f"prior_days must be a positive number of days, got {self.prior_days!r}")
        return features

    def fit(self, table: pa.Table) -> "ChangeDetector":
        """Detect changes in every axis of a history table.

        Parameters
        ----------
        table : pyarrow.Table
            Rows of :func:`greybox.monitor.history.read_history`.

        Returns
        -------
        ChangeDetector
            ``self``. An axis with no more days than ``baseline_days`` gets its trend but no alarm.
        """
        features = self._check_params()
        keys = sorted(set(zip(table.column("machine").to_pylist(), table.column("axis").to_pylist())))
        machines, axes = np.array(table.column("machine").to_pylist()), np.array(table.column("axis").to_pylist())
        axis_rows = [table.filter(pa.array((machines == machine) & (axes == axis))) for machine, axis in keys]
        daily = [_daily(rows) for rows in axis_rows]
        shapes = None
        if self.shapes == "twin":
            shapes = stable_shapes(features)
        elif self.shapes == "plant":
            shapes = plant_shapes([[values[f][:self.baseline_days] for _, values, _, _ in daily] for f in features],
                                  stable_shapes(features), prior_days=self.prior_days)
        calibrated = self.h if self.h is not None else calibrated_threshold(
            baseline_days=self.baseline_days, n_features=len(features),
            false_alarms_per_year=self.false_alarms_per_year, k=self.k, clip=self.clip, shapes=shapes,
            per_feature=self.per_feature and shapes is not None)
        self.thresholds_ = dict(zip(features, np.broadcast_to(np.asarray(calibrated, float), len(features)).tolist()))
        self.threshold_ = max(self.thresholds_.values())
        trends = [self._trend(machine, axis, rows, features, days)
                  for (machine, axis), rows, days in zip(keys, axis_rows, daily)]
        trends.sort(key=lambda t: (-t.severity, t.machine, t.axis))
        self.trends_ = trends
        self.alarms_ = [alarm for trend in trends for alarm in trend.alarms]
        return self

    def _trend(self, machine: str, axis: str, rows: pa.Table, features, daily) -> AxisTrend:
        days, values, lower, upper = daily
        trend = AxisTrend(machine, axis, days, values, lower, upper, travel_map=_daily_map(rows, days))
        n_base = min(self.baseline_days, len(days))
        for feature in features:
            x = values[feature]
            base = x[:n_base][np.isfinite(x[:n_base])]
            if len(base) < 2:  # a feature without values in the baseline days (e.g. no reversals) is not watched
                continue
            mean = float(np.mean(base))
            sd = float(np.std(base, ddof=1))
            if not sd > 0.0:  # a constant baseline: the intervals give the scale
                width = (upper[feature][:n_base] - lower[feature][:n_base])
                sd = float(np.nanmedian(width)) / (2 * 1.96) if np.any(np.isfinite(width)) else 0.0
                sd = sd or 1e-12
            trend.baseline[feature] = (mean, sd)
            h = self.thresholds_[feature]
            up, low = cusum((x - mean) / sd, k=self.k, h=h, clip=self.clip)
            trend.upper_sum[feature], trend.lower_sum[feature] = up, low
            if len(days) <= self.baseline_days:
                continue
            trend.severity = max(trend.severity, float(max(up.max(), low.max())) / h)
            for direction, sums in (("rises", up), ("falls", low)):
                alarm = self._alarm(machine, axis, feature, direction, days, x, base, mean, sd, sums, h)
                if alarm is not None:
                    start, detected = days.index(alarm.start), days.index(alarm.detected)
                    where, departure = travel_departure(trend.travel_map[0], trend.travel_map[1], slice(0, n_base),
                                                        slice(start, detected + 1))
                    trend.alarms.append(replace(alarm, position_mm=where, departure_A=departure))
        trend.alarms.sort(key=lambda a: (a.detected, -abs(a.shift)))
        return trend

    def _alarm(self, machine, axis, feature, direction, days, x, base, mean, sd, sums, h) -> Alarm | None:
        """The first crossing of the threshold ``h`` by the sum ``sums`` of ``direction``, if any."""
        crossed = np.flatnonzero(sums >= h)
        if not len(crossed):
            return None
        detected = int(crossed[0])
        zeros = np.flatnonzero(sums[:detected] == 0.0)
        start = int(zeros[-1]) + 1 if len(zeros) else 0
        since = x[start:detected + 1]
        since = since[np.isfinite(since)]
        p_value = np.nan
        if len(since) >= 2:
            p_value = float(stats.ttest_ind(since, base, equal_var=False,
                                            alternative="greater" if direction == "rises" else "less").pvalue)
        return Alarm(machine, axis, feature, direction, days[start], days[detected],
                     float((np.mean(since) - mean) / sd), p_value)
