"""Synthetic datasets: determinism, truth channels, noise, sensors."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.errors import GreyboxError
from greybox.twin import CurrentNoise, Sensors, make_dataset
from greybox.twin.datasets import SAMPLE_TIME_S, dataset_streams
from greybox.twin.plant import default_plant_parameters
from greybox.twin.sensors import quantise


@pytest.fixture(scope="module")
def log_a():
    return make_dataset("Y", "A", seed=7, duration_s=20.0)


def test_same_seed_same_log_other_seed_other_log(log_a):
    again = make_dataset("Y", "A", seed=7, duration_s=20.0)
    np.testing.assert_array_equal(again.current, log_a.current)
    np.testing.assert_array_equal(again.position, log_a.position)
    other = make_dataset("Y", "A", seed=8, duration_s=20.0)
    assert len(other) != len(log_a) or not np.array_equal(other.position, log_a.position)


def test_datasets_and_axes_derive_their_own_streams():
    c = make_dataset("Y", "C", seed=7, duration_s=20.0)
    a = make_dataset("Y", "A", seed=7, duration_s=20.0)
    assert len(c) != len(a) or not np.array_equal(c.position - c.position[0], a.position - a.position[0])
    x = make_dataset("X", "A", seed=7, duration_s=20.0)
    assert not np.array_equal(x.extras["truth_noise_A"][:100], a.extras["truth_noise_A"][:100])
    draws = [dataset_streams(7, "X", "A")[k].standard_normal(3) for k in (0, 1)]
    assert not np.array_equal(*draws)


def test_log_layout(log_a):
    assert log_a.axis == "Y" and log_a.dataset == "A" and log_a.effort_unit == "A"
    assert log_a.acceleration is None and log_a.velocity is not None
    np.testing.assert_allclose(np.diff(log_a.time), SAMPLE_TIME_S, atol=1e-12)
    assert log_a.time[0] == 0.0
    assert {"truth_current_A", "truth_friction_A", "truth_inertia_A", "truth_cogging_A",
            "truth_noise_A"} == set(log_a.extras)
    attrs = log_a.attrs
    assert attrs["seed"] == 7 and attrs["trajectory"]["dataset"] == "A"
    assert len(attrs["plant"]["breakaway_A"]) >= 16 and attrs["effect"] is None and attrs["cutting"] is None


def test_truth_channels_add_up(log_a):
    e = log_a.extras
    np.testing.assert_allclose(e["truth_current_A"],
                               e["truth_friction_A"] + e["truth_inertia_A"] + e["truth_cogging_A"], atol=1e-12)
    np.testing.assert_allclose(log_a.current, e["truth_current_A"] + e["truth_noise_A"], atol=1e-12)
    # cogging: a function of the position alone (encoder quantisation 0.05 um x slope 1.5 A/mm)
    plant = default_plant_parameters("Y")
    np.testing.assert_allclose(e["truth_cogging_A"], plant.cogging_current(log_a.position), atol=1e-4)
    assert 0.95 * plant.cogging_A < np.abs(e["truth_cogging_A"]).max() <= plant.cogging_A


def test_magnitudes_like_the_paper(log_a):
    e = log_a.extras
    moving = np.abs(log_a.velocity) > 100.0 / 60.0
    assert 0.7 < np.mean(np.abs(e["truth_friction_A"][moving])) < 1.5
    assert 0.1 < np.abs(e["truth_inertia_A"]).max() < 0.8
    assert 0.08 <= np.std(e["truth_noise_A"]) <= 0.10  # recalibrated noise std 0.09 A


def test_sensor_resolution(log_a):
    resolution = Sensors().position_resolution_mm
    np.testing.assert_allclose(log_a.position / resolution, np.round(log_a.position / resolution), atol=1e-6)
    np.testing.assert_allclose(log_a.current / 1e-3, np.round(log_a.current / 1e-3), atol=1e-6)
    # actual velocity: encoder difference over the previous sample interval
    np.testing.assert_allclose(log_a.velocity[1:], np.diff(log_a.position) / SAMPLE_TIME_S, atol=1e-9)
    assert np.abs(log_a.velocity).max() <= 2000.0 / 60.0 * 1.01


def test_noise_has_the_configured_std_and_autocorrelation():
    noise = CurrentNoise(std_A=0.07, lag1_correlation=0.8).sample(400_000, np.random.default_rng(0))
    assert np.std(noise) == pytest.approx(0.07, rel=0.03)
    lag1 = np.corrcoef(noise[1:], noise[:-1])[0, 1]
    lag3 = np.corrcoef(noise[3:], noise[:-3])[0, 1]
    assert lag1 == pytest.approx(0.8, abs=0.01)
    assert lag3 == pytest.approx(0.8**3, abs=0.01)  # AR(1): geometric decay
    first = [CurrentNoise(0.07, 0.8).sample(3, np.random.default_rng(s))[0] for s in range(4000)]
    assert np.std(first) == pytest.approx(0.07, rel=0.05)  # stationary from the first sample


def test_configured_noise_reaches_the_log():
    log = make_dataset("X", "D", seed=2, noise=CurrentNoise(std_A=0.05, lag1_correlation=0.5))
    noise = log.extras["truth_noise_A"]
    assert np.std(noise) == pytest.approx(np.sqrt(0.05**2 + 1e-6 / 12), rel=0.03)
    assert np.corrcoef(noise[1:], noise[:-1])[0, 1] == pytest.approx(0.5, abs=0.03)
    quiet = make_dataset("X", "D", seed=2, noise=CurrentNoise(std_A=0.0))
    assert np.abs(quiet.extras["truth_noise_A"]).max() <= 0.5e-3 + 1e-12  # quantisation only


def test_quantise_gives_short_decimals():
    values = quantise([0.123456, -254.12345678, -1e-9], 1e-4)
    assert [repr(v) for v in values.tolist()] == ["0.1235", "-254.1235", "0.0"]
    assert repr(quantise([0.0749], 0.025).tolist()[0]) == "0.075"


def test_bad_settings_are_clear_errors():
    with pytest.raises(GreyboxError, match="seed"):
        make_dataset("X", "A", seed=-1)
    with pytest.raises(GreyboxError, match="unknown dataset 'E'"):
        make_dataset("X", "E")
    with pytest.raises(GreyboxError, match="unknown axis"):
        make_dataset("W", "A")
    with pytest.raises(GreyboxError, match="lag-1"):
        CurrentNoise(lag1_correlation=1.0)
