"""Metrics and operating regimes, checked against hand-computed values and analytic facts."""

from __future__ import annotations

import math

import numpy as np
import pytest

from greybox.data.log import AxisLog
from greybox.errors import LogError
from greybox.evaluate.regimes import REGIME_NAMES, RegimeThresholds, metrics_by_regime, regime_masks
from greybox.metrics import max_error, metrics_table, nmse, relative_error, relerr, rmse

# ----------------------------------------------------------------- metrics

Y = np.array([1.0, -2.0, 3.0, -4.0])
Y_HAT = np.array([1.0, -1.0, 3.0, -2.0])  # errors 0, 1, 0, 2


def test_hand_computed_values():
    # mean squared error 5/4; mean |y| 10/4; var(y) = 7.25 (mean -0.5); ||y||^2 = 30
    assert rmse(Y, Y_HAT) == pytest.approx(math.sqrt(1.25), rel=1e-15)
    assert relative_error(Y, Y_HAT) == pytest.approx(100 * math.sqrt(1.25) / 2.5, rel=1e-15)
    assert nmse(Y, Y_HAT) == pytest.approx(100 * 1.25 / 7.25, rel=1e-15)
    assert relerr(Y, Y_HAT) == pytest.approx(100 * math.sqrt(5 / 30), rel=1e-15)
    assert max_error(Y, Y_HAT) == 2.0


def test_metrics_table_collects_all_metrics():
    table = metrics_table(Y, Y_HAT)
    assert table == {
        "n": 4,
        "rmse": rmse(Y, Y_HAT),
        "re": relative_error(Y, Y_HAT),
        "nmse": nmse(Y, Y_HAT),
        "relerr": relerr(Y, Y_HAT),
        "max_error": max_error(Y, Y_HAT),
    }


def test_perfect_prediction_has_zero_error():
    y = np.random.default_rng(0).normal(size=200)
    assert all(v == 0 for k, v in metrics_table(y, y.copy()).items() if k != "n")


@pytest.mark.parametrize("scale_error", [-0.3, 0.05, 0.2])
def test_constant_scaling_error(scale_error):
    # y of constant magnitude (square wave): |y| = rms(y), so RE = relerr = 100 |c|
    y = 3.0 * np.sign(np.sin(np.linspace(0.1, 20.0, 501)))
    y_hat = (1 + scale_error) * y
    assert relerr(y, y_hat) == pytest.approx(100 * abs(scale_error), rel=1e-12)
    assert relative_error(y, y_hat) == pytest.approx(100 * abs(scale_error), rel=1e-12)
    assert rmse(y, y_hat) == pytest.approx(3.0 * abs(scale_error), rel=1e-12)
    # any signal: relerr of a scaling error is |c|; RE exceeds it by rms(y)/mean|y| >= 1
    z = np.random.default_rng(1).normal(size=1000)
    assert relerr(z, (1 + scale_error) * z) == pytest.approx(100 * abs(scale_error), rel=1e-12)
    ratio = np.sqrt(np.mean(z**2)) / np.mean(np.abs(z))
    assert relative_error(z, (1 + scale_error) * z) == pytest.approx(100 * abs(scale_error) * ratio, rel=1e-12)


def test_nmse_of_predicting_the_mean_is_100_percent():
    y = np.random.default_rng(2).normal(5.0, 2.0, size=1000)
    assert nmse(y, np.full_like(y, y.mean())) == pytest.approx(100.0, rel=1e-12)
    # and of predicting zero for a zero-mean signal, relerr is 100 % too
    z = y - y.mean()
    assert relerr(z, np.zeros_like(z)) == pytest.approx(100.0, rel=1e-12)


def test_metrics_are_symmetric_in_the_error_sign_and_order_free():
    rng = np.random.default_rng(3)
    y = rng.normal(size=300)
    e = rng.normal(size=300)
    order = rng.permutation(300)
    for metric in (rmse, relative_error, nmse, relerr, max_error):
        assert metric(y, y + e) == pytest.approx(metric(y, y - e), rel=1e-12)
        assert metric(y, y + e) == pytest.approx(metric(y[order], (y + e)[order]), rel=1e-12)


def test_zero_denominators_and_empty_input_give_nan():
    zeros = np.zeros(10)
    ones = np.ones(10)
    assert math.isnan(relative_error(zeros, ones))
    assert math.isnan(relerr(zeros, ones))
    assert math.isnan(nmse(ones, zeros))  # constant y: no variance
    assert rmse(zeros, ones) == 1.0
    table = metrics_table([], [])
    assert table["n"] == 0
    assert all(math.isnan(v) for k, v in table.items() if k != "n")


def test_length_mismatch_is_an_error():
    with pytest.raises(ValueError, match="differ in length"):
        rmse([1.0, 2.0], [1.0])


# ----------------------------------------------------------------- regimes

DT = 0.002


def _profile(segments, dt=DT):
    """Piecewise-constant acceleration [mm/s^2] for the given durations [s]; exact v and a."""
    accel = np.concatenate([np.full(int(round(d / dt)), a) for d, a in segments])
    velocity = np.concatenate(([0.0], np.cumsum(accel[:-1]) * dt))
    time = np.arange(accel.size) * dt
    position = np.cumsum(velocity) * dt
    return time, position, velocity, accel


def _log(segments, effort=None):
    time, position, velocity, accel = _profile(segments)
    effort = np.sign(velocity) * 2.0 + 0.001 * accel if effort is None else effort
    return AxisLog(time=time, position=position, effort=effort, velocity=velocity, acceleration=accel)


# accelerate to 100 mm/s, cruise 0.5 s, decelerate through zero to -100 mm/s, cruise, stop
STROKES = [(0.1, 1000.0), (0.5, 0.0), (0.2, -1000.0), (0.5, 0.0), (0.1, 1000.0), (0.2, 0.0)]
THRESHOLDS = RegimeThresholds(
    low_velocity_mm_s=10.0, standstill_mm_s=0.5, steady_acceleration_mm_s2=50.0, reversal_width_s=0.05
)


def test_velocity_envelopes_and_phases_follow_their_definitions():
    log = _log(STROKES)
    masks = regime_masks(log, THRESHOLDS)
    assert set(masks) == set(REGIME_NAMES)
    assert masks["all"].all()
    np.testing.assert_array_equal(masks["low_velocity"], np.abs(log.velocity) < 10.0)
    np.testing.assert_array_equal(masks["high_velocity"], ~masks["low_velocity"])
    np.testing.assert_array_equal(masks["acceleration"], log.acceleration != 0)
    # both cruises (|v| = 100 mm/s, a = 0) are constant feed; the final rest is not (|v| < v_low)
    np.testing.assert_array_equal(masks["constant_feed"], (log.acceleration == 0) & (np.abs(log.velocity) > 99.0))
    assert masks["constant_feed"].sum() == 2 * 250


def test_reversal_window_is_centred_on_the_zero_crossing():
    log = _log(STROKES)
    mask = regime_masks(log, THRESHOLDS)["reversal"]
    # v = 100 - 1000 (t - 0.6) crosses zero at t = 0.7 s; the only direction change
    distance = np.abs(log.time - 0.7)
    assert mask[distance <= 0.025 + 1e-9].all()
    assert not mask[distance > 0.025 + DT + 1e-9].any()


def test_start_from_rest_after_a_long_dwell_is_not_a_reversal():
    segments = [(0.1, 1000.0), (0.1, -1000.0), (0.5, 0.0), (0.1, -1000.0), (0.1, 1000.0)]
    log = _log(segments)
    assert not regime_masks(log, THRESHOLDS)["reversal"].any()
    short_dwell = [(0.1, 1000.0), (0.1, -1000.0), (0.02, 0.0), (0.1, -1000.0), (0.1, 1000.0)]
    assert regime_masks(_log(short_dwell), THRESHOLDS)["reversal"].any()


def test_short_cruise_is_not_constant_feed():
    segments = [(0.1, 1000.0), (0.05, 0.0), (0.1, -1000.0)]
    assert not regime_masks(_log(segments), THRESHOLDS)["constant_feed"].any()


def test_default_thresholds_scale_with_the_motion():
    log = _log(STROKES)
    thresholds = RegimeThresholds.from_logs(log)
    assert thresholds.low_velocity_mm_s == pytest.approx(0.1 * np.percentile(np.abs(log.velocity), 99))
    assert thresholds.standstill_mm_s == pytest.approx(0.005 * np.percentile(np.abs(log.velocity), 99))
    assert thresholds.steady_acceleration_mm_s2 == pytest.approx(0.05 * 1000.0)
    fast = log.replace(velocity=3 * log.velocity, acceleration=3 * log.acceleration)
    assert RegimeThresholds.from_logs(fast).low_velocity_mm_s == pytest.approx(3 * thresholds.low_velocity_mm_s)


def test_bad_thresholds_are_rejected():
    with pytest.raises(ValueError):
        RegimeThresholds(low_velocity_mm_s=1.0, standstill_mm_s=2.0, steady_acceleration_mm_s2=1.0)
    with pytest.raises(ValueError):
        RegimeThresholds(low_velocity_mm_s=-1.0, standstill_mm_s=0.0, steady_acceleration_mm_s2=1.0)


def test_metrics_by_regime_localises_an_error_at_the_reversal():
    log = _log(STROKES)
    reversal = regime_masks(log, THRESHOLDS)["reversal"]
    prediction = log.effort + np.where(reversal, 0.5, 0.0)
    result = metrics_by_regime(log, prediction, THRESHOLDS)
    assert set(result) == set(REGIME_NAMES)
    assert result["reversal"]["rmse"] == pytest.approx(0.5)
    assert result["reversal"]["n"] == reversal.sum()
    assert result["constant_feed"]["rmse"] == 0.0
    assert result["all"]["rmse"] == pytest.approx(0.5 * math.sqrt(reversal.mean()))


def test_metrics_by_regime_pools_runs():
    first, second = _log(STROKES), _log(STROKES[:3])
    rng = np.random.default_rng(4)
    predictions = [run.effort + rng.normal(size=len(run)) for run in (first, second)]
    result = metrics_by_regime([first, second], predictions, THRESHOLDS)
    pooled = metrics_table(np.concatenate([first.effort, second.effort]), np.concatenate(predictions))
    assert result["all"] == pooled
    assert metrics_by_regime([first, second], np.concatenate(predictions), THRESHOLDS) == result
    assert result["constant_feed"]["n"] == 2 * 250 + 250
    with pytest.raises(ValueError, match="predictions"):
        metrics_by_regime([first, second], predictions[:1], THRESHOLDS)
    with pytest.raises(ValueError, match="prediction of"):
        metrics_by_regime([first, second], np.concatenate(predictions)[:-1], THRESHOLDS)


def test_empty_regime_gives_nan_metrics():
    log = _log([(0.3, 0.0)])  # at rest throughout
    result = metrics_by_regime(log, log.effort, THRESHOLDS)
    assert result["high_velocity"]["n"] == 0
    assert math.isnan(result["high_velocity"]["rmse"])


def test_unprepared_log_is_refused():
    log = _log(STROKES).replace(velocity=None, acceleration=None, source="x.csv")
    with pytest.raises(LogError, match="x.csv"):
        regime_masks(log, THRESHOLDS)
