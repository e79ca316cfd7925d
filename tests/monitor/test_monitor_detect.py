"""Change detection (greybox.monitor.detect): CUSUM sums, alarms naming feature, direction, start."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pyarrow as pa
import pytest

from greybox.errors import ParameterError
from greybox.monitor.detect import ChangeDetector, calibrated_threshold, cusum, plant_shapes, stable_shapes
from greybox.monitor.fingerprint import FEATURES
from greybox.monitor.history import SCHEMA, SCHEMA_VERSION

DAY0 = dt.date(2026, 1, 1)


def _table(series: dict, axis="X", machine="m", default=None) -> pa.Table:
    """A history table of one axis: one row per day, ``series[feature]`` or ``default`` (a noise series)."""
    n = len(next(iter(series.values()))) if series else len(default)
    rows = {"schema_version": [SCHEMA_VERSION] * n, "machine": [machine] * n, "axis": [axis] * n,
            "date": [DAY0 + dt.timedelta(days=i) for i in range(n)], "log_sha256": [f"{i:064x}" for i in range(n)],
            "source": ["log"] * n, "n_samples": [1000] * n}
    rng = np.random.default_rng(1)
    for name in FEATURES:
        values = np.asarray(series.get(name, rng.normal(1.0, 0.01, n) if default is None else default), float)
        rows[name], rows[f"{name}_lo"], rows[f"{name}_hi"] = values, values - 0.02, values + 0.02
    rows["map_position_mm"], rows["map_excess_A"] = [[]] * n, [[]] * n
    return pa.Table.from_pydict(rows, schema=SCHEMA)


def _reference_cusum(z, k, h):
    """The CUSUM recursion written out with lists."""
    up, low, s_up, s_low = [], [], 0.0, 0.0
    for value in z:
        s_up = max(0.0, s_up + value - k)
        s_low = max(0.0, s_low - value - k)
        up.append(s_up)
        low.append(s_low)
    return up, low


def test_cusum_agrees_with_its_recursion():
    z = np.random.default_rng(3).normal(0.2, 1.0, 300)
    up, low = cusum(z, k=0.5, h=5.0)
    ref_up, ref_low = _reference_cusum(z, 0.5, 5.0)
    np.testing.assert_allclose(up, ref_up)
    np.testing.assert_allclose(low, ref_low)
    assert np.all(cusum([10.0, -10.0], clip=3.0)[0] == [2.5, 0.0])


def _alternating(n):
    return 1.0 + 0.01 * (-1.0) ** np.arange(n)  # baseline mean 1, sd ~0.0104


def test_step_rise_named_with_its_start_and_day_of_detection():
    x = _alternating(40)
    x[26:] += 0.03  # +2.9 sd from day 26 (day 25 is a low day: the upper sum is 0 there)
    detector = ChangeDetector(baseline_days=14, k=0.5, h=5.0).fit(_table({"sliding_neg": x},
                                                                          default=_alternating(40)))
    (alarm,) = detector.alarms_
    assert (alarm.feature, alarm.direction, alarm.axis) == ("sliding_neg", "rises", "X")
    assert alarm.start == DAY0 + dt.timedelta(days=26)
    # z alternates 3.9 (clipped to 3) / 1.9 sd: 2.5 + 1.4 + 2.5 above the allowance 0.5 reach h = 5 on the third day
    assert alarm.detected == DAY0 + dt.timedelta(days=28)
    assert 2.0 < alarm.shift < 4.0 and alarm.p_value < 0.05  # three days since the start
    assert "sliding_neg rises since 2026-01-27" in alarm.describe()
    assert detector.trends_[0].severity >= 1.0


def test_fall_and_severity_order():
    x = _alternating(40)
    x[20:] -= 0.05
    stable = _table({}, axis="Y", default=_alternating(40))
    falling = _table({"breakaway_pos": x}, axis="X", default=_alternating(40))
    detector = ChangeDetector(baseline_days=14).fit(pa.concat_tables([stable, falling]))
    assert [t.axis for t in detector.trends_] == ["X", "Y"]  # most severe first
    assert [(a.feature, a.direction) for a in detector.alarms_] == [("breakaway_pos", "falls")]
    assert detector.trends_[1].severity < 1.0 and not detector.trends_[1].alarms


def test_one_odd_day_is_no_alarm():
    x = _alternating(40)
    x[30] += 1.0  # one wild day: clipped to 3 sd, 2.5 above the allowance, below h = 5
    assert not ChangeDetector(baseline_days=14, h=5.0).fit(_table({"noise": x}, default=_alternating(40))).alarms_


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_calibrated_threshold_holds_its_false_alarm_rate():
    rng = np.random.default_rng(2024)  # stable axes drawn apart from the calibration's own seed
    axes = [_table({name: rng.normal(1.0, 0.02, 28 + 365) for name in FEATURES}, axis=f"A{i}") for i in range(60)]
    detector = ChangeDetector(baseline_days=28, false_alarms_per_year=1.0, shapes="normal").fit(pa.concat_tables(axes))
    assert detector.threshold_ == pytest.approx(
        calibrated_threshold(baseline_days=28, n_features=len(FEATURES), false_alarms_per_year=1.0))
    per_axis_year = len(detector.alarms_) / 60
    assert 0.4 < per_axis_year < 1.8  # 1 asked; 60 axis-years leave a Monte-Carlo spread of about +-0.3
    textbook = ChangeDetector(baseline_days=28, k=0.5, h=5.0).fit(pa.concat_tables(axes))
    assert len(textbook.alarms_) / 60 > 2.0 * per_axis_year  # why h is calibrated


def _skewed_shapes(n_features):
    """Quantiles of a standardised log-normal (sigma 0.5): a magnitude skewed to high values, like a maximum."""
    sample = np.random.default_rng(77).lognormal(0.0, 0.5, 400_000)
    z = (sample - np.exp(0.125)) / np.sqrt((np.exp(0.25) - 1.0) * np.exp(0.25))
    return np.tile(np.quantile(z, np.linspace(0.0, 1.0, 201)), (n_features, 1))


def _false_alarms_per_axis_year(x, h, n_features, baseline_days=28, k=1.0, clip=3.0):
    """Stable series (one per row) watched as the detector does: the expected alarms of n_features such sums."""
    base = x[:, :baseline_days]
    z = np.clip((x - base.mean(axis=1, keepdims=True)) / base.std(axis=1, ddof=1, keepdims=True), -clip, clip)
    up, low = np.zeros(len(x)), np.zeros(len(x))
    crossed_up, crossed_low = np.zeros(len(x), bool), np.zeros(len(x), bool)
    for day in range(x.shape[1]):
        up = np.maximum(0.0, up + z[:, day] - k)
        low = np.maximum(0.0, low - z[:, day] - k)
        crossed_up |= up >= h
        crossed_low |= low >= h
    return n_features * (crossed_up.mean() + crossed_low.mean())


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_calibration_on_skewed_days_holds_the_rate_the_normal_one_misses():
    # stable days skewed to high values (not normal); the baselines estimated from 28 of them; drawn apart
    # from the calibration's seed
    x = np.random.default_rng(31).lognormal(0.0, 0.5, (20_000, 28 + 365))
    skewed = calibrated_threshold(baseline_days=28, n_features=10, false_alarms_per_year=1.0,
                                  shapes=_skewed_shapes(10))
    normal = calibrated_threshold(baseline_days=28, n_features=10, false_alarms_per_year=1.0)
    assert skewed > normal  # the upper sums of skewed days reach high more often
    # 1 asked; 20,000 series: a Monte-Carlo spread of about +-0.03 (sd) on top of the calibration's own
    assert abs(_false_alarms_per_axis_year(x, skewed, 10) - 1.0) < 0.12
    assert _false_alarms_per_axis_year(x, normal, 10) > 1.4  # the calibration on normal days under-states it
    # the same check on normal days holds the normal calibration
    y = np.random.default_rng(32).standard_normal((20_000, 28 + 365))
    assert abs(_false_alarms_per_axis_year(y, normal, 10) - 1.0) < 0.12


def test_twin_shapes_are_standardised_quantiles_and_set_the_default_threshold():
    shapes = stable_shapes()
    assert shapes.shape[0] == len(FEATURES) and np.all(np.diff(shapes, axis=1) >= 0.0)
    draws = np.array([np.interp(np.linspace(0.0, 1.0, 20001), np.linspace(0.0, 1.0, shapes.shape[1]), row)
                      for row in shapes])
    assert np.all(np.abs(draws.mean(axis=1)) < 0.05) and np.all(np.abs(draws.std(axis=1) - 1.0) < 0.05)
    local = draws[FEATURES.index("local_excess")]
    assert np.mean((local - local.mean()) ** 3) > 0.3  # a largest value along the travel: skewed to high values
    detector = ChangeDetector(shapes="twin", per_feature=False).fit(
        _table({}, default=np.random.default_rng(4).normal(1.0, 0.01, 40)))
    assert detector.threshold_ == pytest.approx(calibrated_threshold(
        baseline_days=28, n_features=len(FEATURES), false_alarms_per_year=0.5, shapes=shapes))
    assert detector.threshold_ > calibrated_threshold(baseline_days=28, n_features=len(FEATURES),
                                                      false_alarms_per_year=1.0, shapes=shapes)
    with pytest.raises(ParameterError, match="shapes"):
        ChangeDetector(shapes="gamma").fit(_table({}, default=np.ones(40)))
    with pytest.raises(ParameterError, match="ascending quantiles"):
        calibrated_threshold(baseline_days=28, n_features=2, shapes=shapes[:2, ::-1])


def test_threshold_rises_with_a_shorter_baseline_and_fewer_alarms():
    short = calibrated_threshold(baseline_days=14, n_features=7, k=0.5)
    long = calibrated_threshold(baseline_days=56, n_features=7, k=0.5)
    rare = calibrated_threshold(baseline_days=56, n_features=7, false_alarms_per_year=0.1, k=0.5)
    assert short > long and rare > long > 5.0  # above the textbook h = 5 of k = 0.5
    assert calibrated_threshold(baseline_days=56, n_features=7) < long  # the default k = 1: a lower h


def test_too_few_days_no_alarm_and_bad_settings():
    x = _alternating(10)
    x[5:] += 1.0
    detector = ChangeDetector(baseline_days=14, h=5.0).fit(_table({"sliding_pos": x}, default=_alternating(10)))
    assert detector.alarms_ == [] and detector.trends_[0].severity == 0.0
    with pytest.raises(ParameterError, match="baseline_days"):
        ChangeDetector(baseline_days=2).fit(_table({"sliding_pos": x}))
    with pytest.raises(ParameterError, match="unknown features bogus"):
        ChangeDetector(features=["bogus"]).fit(_table({"sliding_pos": x}))


def test_plant_shapes_weigh_the_plant_days_against_the_prior():
    prior = stable_shapes()[:1]
    rng = np.random.default_rng(5)
    skewed = [rng.lognormal(0.0, 0.6, 28) for _ in range(40)]  # 40 axes' baselines of one feature, skewed high
    none = plant_shapes([[]], prior, prior_days=28.0)[0]
    assert np.allclose(none[10:-10], np.interp(np.linspace(0, 1, 201), np.linspace(0, 1, prior.shape[1]),
                                               prior[0])[10:-10], atol=0.05)  # without plant days: the prior
    pooled = plant_shapes([skewed], prior, prior_days=28.0)[0]
    standardised = np.concatenate([(d - d.mean()) / d.std(ddof=1) for d in skewed])
    # 1120 plant days against 28 of the prior: the plant's quantiles, a long upper tail and a short lower one
    assert pooled[100] == pytest.approx(np.median(standardised), abs=0.05)
    assert pooled[-3] > 2.0 * -pooled[2]
    heavy = plant_shapes([skewed], prior, prior_days=1e6)[0]  # a prior of a million days: the prior
    assert heavy[100] == pytest.approx(prior[0][prior.shape[1] // 2], abs=0.02)


def test_threshold_of_each_feature_from_the_plant_baseline():
    rng = np.random.default_rng(6)
    tables = []
    for machine in range(12):  # a plant of 12 axes: 336 baseline days per feature
        series = {name: rng.normal(1.0, 0.01, 40) for name in FEATURES}
        series["noise"] = 1.0 + 0.01 * rng.lognormal(0.0, 0.8, 40)  # one feature skewed to high values
        tables.append(_table(series, machine=f"m{machine}"))
    plant = pa.concat_tables(tables)
    detector = ChangeDetector().fit(plant)
    h = detector.thresholds_
    assert h["noise"] > max(h[name] for name in FEATURES if name != "noise") + 0.3
    assert detector.threshold_ == max(h.values())
    # the twin's shapes alone, one threshold: the plant's skew does not reach it
    twin = ChangeDetector(shapes="twin", per_feature=False).fit(plant)
    assert set(twin.thresholds_.values()) == {twin.threshold_} and twin.threshold_ < h["noise"]
    # per feature, each for an equal share: on the twin's own shapes the thresholds are those of the calibration
    per_feature = ChangeDetector(shapes="twin").fit(plant).thresholds_
    expected = calibrated_threshold(baseline_days=28, n_features=len(FEATURES), false_alarms_per_year=0.5,
                                    shapes=stable_shapes(), per_feature=True)
    assert np.allclose([per_feature[name] for name in FEATURES], expected)


@pytest.mark.slow
def test_per_feature_thresholds_hold_the_rate_on_a_skewed_feature():
    # nine normal features and one skewed; simulated stable years drawn apart from the calibration's seed
    rng = np.random.default_rng(33)
    gaussian = np.quantile(np.random.default_rng(78).standard_normal(400_000), np.linspace(0.0, 1.0, 201))
    shapes = np.vstack([gaussian] * 9 + [_skewed_shapes(1)[0]])
    h = calibrated_threshold(baseline_days=28, n_features=10, false_alarms_per_year=1.0, shapes=shapes,
                             per_feature=True)
    assert h[-1] > h[0] + 0.3 and np.allclose(h[:9], h[0], atol=0.2)
    skewed = rng.lognormal(0.0, 0.5, (20_000, 28 + 365))
    gauss = rng.standard_normal((20_000, 28 + 365))
    # each feature raises its share, 1/10 of one false alarm a year: the skewed one no more than the others
    assert abs(_false_alarms_per_axis_year(skewed, h[-1], 10) - 1.0) < 0.2
    assert abs(_false_alarms_per_axis_year(gauss, h[0], 10) - 1.0) < 0.2
    # one threshold for all (the common calibration) lets the skewed feature raise more than its share
    common = calibrated_threshold(baseline_days=28, n_features=10, false_alarms_per_year=1.0, shapes=shapes)
    assert _false_alarms_per_axis_year(skewed, common, 10) > 1.3
