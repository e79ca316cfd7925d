"""Change detection on the fingerprint history: a baseline per feature and a two-sided CUSUM.

For every machine, axis and feature the daily value (the mean of that day's logs) is standardised with
the mean and standard deviation of the first ``baseline_days`` days that have a fingerprint:
``z_t = (x_t - m) / s``, clipped to ``[-clip, clip]`` so that one odd day (a log with an unusual motion)
adds at most ``clip - k`` to a sum and cannot raise an alarm alone. Two one-sided CUSUM sums run over all
days,

    S+_t = max(0, S+_{t-1} + z_t - k),   S-_t = max(0, S-_{t-1} - z_t - k),

and an alarm is raised on the first day either reaches ``h`` (``k = 0.5``: tuned to a shift of one standard
deviation). The threshold ``h`` is calibrated by simulation (:func:`calibrated_threshold`): with the
baseline estimated from only ``baseline_days`` days, the textbook ``h = 5`` (an in-control run length of
about 900 days per sum when mean and deviation are known) raises several false alarms per axis and year,
because the estimated baseline is itself off by a fraction of a standard deviation. The calibration
simulates stable axes (independent normal daily values), estimates their baseline as the detector does and
sets ``h`` so that the expected number of false alarms is ``false_alarms_per_year`` per axis and year.

The alarm names the feature, the direction of the change (``rises`` for S+, ``falls`` for S-), the day
the change started (the last day that sum was zero before it rose to ``h``), the day it was detected, the
mean shift since the start in baseline standard deviations, and a one-sided Welch t-test p-value of the
days since the start against the baseline days (how sure).
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass, field

import numpy as np
import pyarrow as pa
from scipy import stats

from ..errors import ParameterError
from .fingerprint import FEATURES

__all__ = ["Alarm", "AxisTrend", "ChangeDetector", "calibrated_threshold", "cusum"]


def cusum(z, *, k: float = 0.5, h: float = 5.0, clip: float = np.inf) -> tuple[np.ndarray, np.ndarray]:
    """The upper and lower CUSUM sums of a standardised series.

    Parameters
    ----------
    z : array_like, shape (n,)
        Standardised values (in baseline standard deviations).
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
        s_up = max(0.0, s_up + value - k)
        s_low = max(0.0, s_low - value - k)
        upper[i], lower[i] = s_up, s_low
    return upper, lower


def calibrated_threshold(*, baseline_days: int, n_features: int, false_alarms_per_year: float = 1.0,
                         k: float = 0.5, clip: float = 3.0, n_sim: int = 4000, seed: int = 0) -> float:
    """The CUSUM threshold that gives a set number of false alarms per axis and year on stable axes.

    Stable axes are simulated as independent standard normal daily values over ``baseline_days`` plus
    365 days; the baseline mean and standard deviation are estimated from the first ``baseline_days``
    (as :class:`ChangeDetector` does), and both CUSUM sums of each series run over all days. With
    ``2 * n_features`` independent sums per axis, the threshold is the quantile of the sums' yearly maxima
    at which ``false_alarms_per_year`` of them cross it per axis. Correlated features (the two directions'
    levels move together) make fewer independent sums: the calibration is then conservative.

    Parameters
    ----------
    baseline_days : int
        Days that set the baseline.
    n_features : int
        Features watched per axis.
    false_alarms_per_year : float, default 1.0
        Expected false alarms per axis and year (365 days of daily values).
    k : float, default 0.5
        CUSUM allowance [standard deviations].
    clip : float, default 3.0
        Standardised values are clipped to ``[-clip, clip]``.
    n_sim : int, default 4000
        Simulated stable series.
    seed : int, default 0
        Seed of the simulation.

    Returns
    -------
    float
        Threshold ``h`` [standard deviations].
    """
    share = false_alarms_per_year / (2.0 * n_features)
    if not 0.0 < share < 1.0:
        raise ParameterError(f"false_alarms_per_year must be in (0, {2 * n_features}), got {false_alarms_per_year}")
    x = np.random.default_rng(seed).standard_normal((n_sim, baseline_days + 365))
    base = x[:, :baseline_days]
    z = np.clip((x - base.mean(axis=1, keepdims=True)) / base.std(axis=1, ddof=1, keepdims=True), -clip, clip)
    s_up, s_low = np.zeros(n_sim), np.zeros(n_sim)
    top_up, top_low = np.zeros(n_sim), np.zeros(n_sim)
    for column in z.T:
        s_up = np.maximum(0.0, s_up + column - k)
        s_low = np.maximum(0.0, s_low - column - k)
        np.maximum(top_up, s_up, out=top_up)
        np.maximum(top_low, s_low, out=top_low)
    return float(np.quantile(np.concatenate([top_up, top_low]), 1.0 - share))


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
    """

    machine: str
    axis: str
    feature: str
    direction: str
    start: dt.date
    detected: dt.date
    shift: float
    p_value: float

    def describe(self) -> str:
        """One line for people: what changed, which way, since when, how sure."""
        sure = "" if not np.isfinite(self.p_value) else f", p = {self.p_value:.2g}"
        return (f"{self.machine}/{self.axis}: {self.feature} {self.direction} since {self.start.isoformat()} "
                f"(detected {self.detected.isoformat()}; shift {self.shift:+.1f} sd{sure})")


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


def _daily(table: pa.Table) -> tuple[list, dict, dict, dict]:
    """Dates and the daily means of every feature and interval end of one axis' rows."""
    dates = table.column("date").to_pylist()
    days = sorted(set(dates))
    index = np.array([days.index(d) for d in dates])
    counts = np.bincount(index, minlength=len(days))

    def mean(name):
        return np.bincount(index, weights=table.column(name).to_numpy(zero_copy_only=False),
                           minlength=len(days)) / counts

    values = {f: mean(f) for f in FEATURES}
    return days, values, {f: mean(f"{f}_lo") for f in FEATURES}, {f: mean(f"{f}_hi") for f in FEATURES}


class ChangeDetector:
    """Baseline and two-sided CUSUM per feature of every axis in a fingerprint history.

    Parameters
    ----------
    baseline_days : int, default 28
        Number of first days (with a fingerprint) that set each feature's baseline; at least 3.
    k : float, default 0.5
        CUSUM allowance [baseline standard deviations].
    h : float, optional
        CUSUM threshold [baseline standard deviations]; by default :func:`calibrated_threshold` for
        ``false_alarms_per_year``.
    false_alarms_per_year : float, default 1.0
        Expected false alarms per axis and year on stable axes, which sets the default ``h``.
    clip : float, default 3.0
        Standardised daily values are clipped to ``[-clip, clip]`` [baseline standard deviations].
    features : sequence of str, optional
        Features watched; all of :data:`~greybox.monitor.fingerprint.FEATURES` by default.

    Attributes
    ----------
    threshold_ : float
        The threshold ``h`` used [baseline standard deviations].
    trends_ : list of AxisTrend
        One per machine and axis, most severe first.
    alarms_ : list of Alarm
        Every alarm, most severe axis first, earliest first within an axis.
    """

    def __init__(self, *, baseline_days: int = 28, k: float = 0.5, h: float | None = None,
                 false_alarms_per_year: float = 1.0, clip: float = 3.0, features=None):
        self.baseline_days = baseline_days
        self.k = k
        self.h = h
        self.false_alarms_per_year = false_alarms_per_year
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
        self.threshold_ = self.h if self.h is not None else calibrated_threshold(
            baseline_days=self.baseline_days, n_features=len(features),
            false_alarms_per_year=self.false_alarms_per_year, k=self.k, clip=self.clip)
        trends = []
        keys = sorted(set(zip(table.column("machine").to_pylist(), table.column("axis").to_pylist())))
        machines, axes = np.array(table.column("machine").to_pylist()), np.array(table.column("axis").to_pylist())
        for machine, axis in keys:
            rows = table.filter(pa.array((machines == machine) & (axes == axis)))
            trends.append(self._trend(machine, axis, rows, features))
        trends.sort(key=lambda t: (-t.severity, t.machine, t.axis))
        self.trends_ = trends
        self.alarms_ = [alarm for trend in trends for alarm in trend.alarms]
        return self

    def _trend(self, machine: str, axis: str, rows: pa.Table, features) -> AxisTrend:
        days, values, lower, upper = _daily(rows)
        trend = AxisTrend(machine, axis, days, values, lower, upper)
        n_base = min(self.baseline_days, len(days))
        for feature in features:
            x = values[feature]
            base = x[:n_base]
            mean = float(np.mean(base))
            sd = float(np.std(base, ddof=1)) if n_base > 1 else 0.0
            if not sd > 0.0:  # a constant baseline: the intervals give the scale
                sd = float(np.median(upper[feature][:n_base] - lower[feature][:n_base])) / (2 * 1.96) or 1e-12
            trend.baseline[feature] = (mean, sd)
            up, low = cusum((x - mean) / sd, k=self.k, h=self.threshold_, clip=self.clip)
            trend.upper_sum[feature], trend.lower_sum[feature] = up, low
            if len(days) <= self.baseline_days:
                continue
            trend.severity = max(trend.severity, float(max(up.max(), low.max())) / self.threshold_)
            for direction, sums in (("rises", up), ("falls", low)):
                alarm = self._alarm(machine, axis, feature, direction, days, x, base, mean, sd, sums)
                if alarm is not None:
                    trend.alarms.append(alarm)
        trend.alarms.sort(key=lambda a: (a.detected, -abs(a.shift)))
        return trend

    def _alarm(self, machine, axis, feature, direction, days, x, base, mean, sd, sums) -> Alarm | None:
        """The first crossing of ``h`` by the sum ``sums`` of ``direction``, if any."""
        crossed = np.flatnonzero(sums >= self.threshold_)
        if not len(crossed):
            return None
        detected = int(crossed[0])
        zeros = np.flatnonzero(sums[:detected] == 0.0)
        start = int(zeros[-1]) + 1 if len(zeros) else 0
        since = x[start:detected + 1]
        p_value = np.nan
        if len(since) >= 2:
            p_value = float(stats.ttest_ind(since, base, equal_var=False,
                                            alternative="greater" if direction == "rises" else "less").pvalue)
        return Alarm(machine, axis, feature, direction, days[start], days[detected],
                     float((np.mean(since) - mean) / sd), p_value)
