"""Derivatives, resampling, trimming and run-by-run preparation."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.io import read_log
from greybox.data.log import AxisLog
from greybox.data.prepare import default_cutoff, derive, prepare, resample, trim
from greybox.errors import LogError


def _sine(frequency_hz, n=5000, sample_time=0.002, amplitude_mm=50.0, **fields):
    time = np.arange(n) * sample_time
    return AxisLog(time=time, position=amplitude_mm * np.sin(2 * np.pi * frequency_hz * time), effort=np.zeros(n),
                   **fields)


def test_default_cutoff():
    assert default_cutoff(0.002) == 50.0  # 500 Hz log
    assert default_cutoff(0.001) == 50.0  # 1 kHz (EMPS)
    assert default_cutoff(0.01) == pytest.approx(20.0)  # 0.4 * Nyquist of 100 Hz
    assert default_cutoff(0.1) == pytest.approx(2.0)  # 10 Hz CNC-mill log


def test_derivatives_of_a_slow_sine_are_analytic():
    log = derive(_sine(0.5))
    omega = 2 * np.pi * 0.5
    inner = slice(100, -100)
    np.testing.assert_allclose(log.velocity[inner], 50 * omega * np.cos(omega * log.time[inner]),
                               atol=1e-3 * 50 * omega)
    np.testing.assert_allclose(log.acceleration[inner], -50 * omega**2 * np.sin(omega * log.time[inner]),
                               atol=1e-3 * 50 * omega**2)
    assert log.attrs["derivative_filter"] == {"cutoff_hz": 50.0, "order": 4, "derived": ["velocity", "acceleration"]}


def test_a_sine_at_the_cutoff_is_halved_without_phase_shift():
    # forward-backward Butterworth: |H(fc)|^2 = 1/2, zero phase
    log = derive(_sine(20.0, n=20000), cutoff_hz=20.0)
    omega = 2 * np.pi * 20.0
    inner = slice(2000, -2000)
    expected = 0.5 * 50 * omega * np.cos(omega * log.time[inner])
    central_difference_gain = np.sin(omega * 0.002) / (omega * 0.002)
    np.testing.assert_allclose(log.velocity[inner], central_difference_gain * expected, atol=2e-3 * 50 * omega)


def test_filter_suppresses_position_noise():
    clean = _sine(0.5)
    noise = np.random.default_rng(2).normal(0.0, 1e-3, len(clean))
    noisy = derive(clean.replace(position=clean.position + noise))
    exact = derive(clean)
    raw_error = np.gradient(noise, 0.002)
    assert np.std(noisy.velocity - exact.velocity) < 0.2 * np.std(raw_error)


def test_logged_velocity_is_kept_and_acceleration_comes_from_it():
    omega = 2 * np.pi * 0.5
    base = _sine(0.5)
    logged = 50 * omega * np.cos(omega * base.time)
    log = derive(base.replace(velocity=logged))
    assert np.array_equal(log.velocity, logged)
    inner = slice(100, -100)
    np.testing.assert_allclose(log.acceleration[inner], -50 * omega**2 * np.sin(omega * base.time[inner]),
                               atol=1e-3 * 50 * omega**2)
    assert log.attrs["derivative_filter"]["derived"] == ["acceleration"]


def test_prepared_log_is_returned_unchanged():
    log = _sine(0.5, velocity=np.ones(5000), acceleration=np.zeros(5000))
    assert derive(log) is log


def test_derive_errors():
    with pytest.raises(LogError, match="the log has 15 samples; the 4th-order filter needs at least 16"):
        derive(_sine(0.5, n=15, source="short.csv"))
    with pytest.raises(LogError, match="Nyquist frequency 250 Hz"):
        derive(_sine(0.5), cutoff_hz=300.0)
    jittery = _sine(0.5, n=100)
    time = jittery.time.copy()
    time[50] += 0.0015
    with pytest.raises(LogError, match="jitter|gap"):
        derive(jittery.replace(time=time))


def test_default_cutoff_matches_the_emps_benchmark_filter(real_data):
    """IDIM-LS fit of gtau*vir = M a + Fv v + Fc sign(v) + offset: default (50 Hz) vs the benchmark's 100 Hz."""
    log = read_log(real_data("EMPS") / "DATA_EMPS.mat")

    def fit(prepared):
        v, a = prepared.velocity / 1e3, prepared.acceleration / 1e3  # m/s, m/s^2
        regressors = np.c_[a, v, np.sign(v), np.ones_like(v)][50:-50]
        force = prepared.effort[50:-50]
        theta = np.linalg.lstsq(regressors, force, rcond=None)[0]
        return theta, np.linalg.norm(force - regressors @ theta) / np.linalg.norm(force)

    (default,) = prepare(log)
    theta_default, error_default = fit(default)
    theta_benchmark, error_benchmark = fit(derive(log, cutoff_hz=100.0))
    np.testing.assert_allclose(theta_default, theta_benchmark, rtol=5e-3)
    assert theta_benchmark[0] == pytest.approx(95.1, rel=0.01)  # published M = 95.1089 kg
    assert error_default <= error_benchmark + 1e-3
    _, error_low = fit(derive(log, cutoff_hz=20.0))
    assert error_low > 2 * error_default  # a cut-off inside the motion band distorts


def test_resample_is_exact_for_linear_channels_and_decimates_uniform_logs():
    time = np.arange(101) * 0.001
    log = AxisLog(time=time, position=3.0 * time + 1.0, effort=-2.0 * time, extras={"ramp_A": time})
    coarse = resample(log, 0.002)
    np.testing.assert_allclose(coarse.time, np.arange(51) * 0.002)
    np.testing.assert_allclose(coarse.position, 3.0 * coarse.time + 1.0)
    np.testing.assert_allclose(coarse.extras["ramp_A"], coarse.time)
    assert np.array_equal(coarse.effort, log.effort[::2])
    fine = resample(log, 0.0003)
    assert fine.time[-1] <= time[-1] and fine.time[-1] > time[-1] - 0.0003
    np.testing.assert_allclose(fine.position, 3.0 * fine.time + 1.0)


def test_resample_removes_jitter():
    time = np.arange(200) * 0.002 + np.random.default_rng(4).uniform(-4e-4, 4e-4, 200)
    log = AxisLog(time=np.sort(time), position=np.sort(time), effort=np.zeros(200))
    uniform = resample(log, 0.002)
    assert np.ptp(np.diff(uniform.time)) < 1e-12


def test_resample_errors():
    log = _sine(0.5, n=10, source="a.csv")
    with pytest.raises(LogError, match="positive"):
        resample(log, 0.0)
    time = log.time.copy()
    time[4] = time[3]
    with pytest.raises(LogError, match="not strictly increasing at sample 4"):
        resample(log.replace(time=time), 0.001)


def test_trim_is_inclusive():
    log = _sine(0.5, n=100)
    window = trim(log, 0.010, 0.020)
    np.testing.assert_allclose(window.time, np.arange(5, 11) * 0.002)
    assert len(trim(log, stop_s=0.004)) == 3 and len(trim(log, start_s=0.194)) == 3
    with pytest.raises(LogError, match="no samples between 5 s and 6 s"):
        trim(log, 5, 6)


def test_prepare_never_filters_across_runs():
    first = _sine(0.5, n=1000, source="run1.csv")
    second = _sine(0.5, n=1000, source="run2.csv").replace(time=first.time + 2.0, position=first.position + 1000.0)
    prepared = prepare([first, second])
    assert len(prepared) == 2 and all(run.is_prepared for run in prepared)
    np.testing.assert_array_equal(prepared[0].velocity, derive(first).velocity)
    np.testing.assert_allclose(prepared[1].velocity, prepared[0].velocity, atol=1e-6)  # same motion, offset position
    assert max(np.abs(run.velocity).max() for run in prepared) < 1.02 * 50 * np.pi  # no spike from the 1000 mm seam


def test_prepare_resamples_and_validates_each_run():
    runs = prepare(_sine(0.5, n=1000, sample_time=0.001), sample_time=0.002)
    assert len(runs[0]) == 500 and runs[0].sample_time == pytest.approx(0.002)
    bad = _sine(0.5, n=100, source="run7.csv")
    effort = bad.effort.copy()
    effort[10] = np.nan
    with pytest.raises(LogError, match=r"^run7.csv: channel 'current_A' holds nan"):
        prepare([_sine(0.5), bad.replace(effort=effort)])
