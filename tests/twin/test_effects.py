"""Hidden effects and the cutting load of the synthetic axis."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.errors import GreyboxError
from greybox.twin import EFFECTS, CuttingSpec, make_dataset
from greybox.twin.axes import AXES
from greybox.twin.cutting import cut_segments, cutting_current
from greybox.twin.datasets import dataset_streams
from greybox.twin.effects import EffectInputs, effect_current, effect_parameters
from greybox.twin.trajectories import dataset_trajectory


@pytest.fixture(scope="module")
def baseline():
    return make_dataset("X", "A", seed=4, duration_s=12.0)


def test_registry_has_the_named_effects():
    assert {"direction_asymmetry", "constant_offset", "position_periodic_force", "position_periodic_friction",
            "thermal_drift", "position_trend", "inertia_mismatch", "viscous_friction"} <= set(EFFECTS)
    for name, function in EFFECTS.items():
        assert function.__doc__, name
        assert all(isinstance(key, str) for key in effect_parameters(name))


@pytest.mark.parametrize("name", sorted(EFFECTS))
def test_effect_changes_the_current_by_its_truth_channel(baseline, name):
    log = make_dataset("X", "A", seed=4, duration_s=12.0, effect=name, effect_strength=0.3)
    effect = log.extras["truth_effect_A"]
    assert np.abs(effect).max() > 0.01
    np.testing.assert_array_equal(log.position, baseline.position)  # same motion
    np.testing.assert_allclose(log.extras["truth_current_A"] - baseline.extras["truth_current_A"], effect,
                               rtol=0, atol=1e-12)
    np.testing.assert_array_equal(log.extras["truth_friction_A"], baseline.extras["truth_friction_A"])
    # same noise draw: the logged currents differ by the effect up to the current resolution
    resolution = log.attrs["sensors"]["current_resolution_A"]
    assert np.abs(log.current - baseline.current - effect).max() <= resolution * (1 + 1e-9)
    assert log.attrs["effect"]["name"] == name and log.attrs["effect"]["strength_A"] == 0.3


def effect_inputs(x, v, a=None, t=None):
    x, v = np.asarray(x, float), np.asarray(v, float)
    a = np.zeros_like(x) if a is None else np.asarray(a, float)
    t = np.zeros_like(x) if t is None else np.asarray(t, float)
    return EffectInputs(t, x, v, a, (-510.0, 0.0))


def test_direction_dependence_of_the_effects():
    x = np.array([-100.0, -100.0, -97.3, -97.3])
    v = np.array([10.0, -10.0, 10.0, -10.0])
    force = effect_current("position_periodic_force", effect_inputs(x, v), 0.2, period_mm=7.0, phase_rad=0.3)
    friction = effect_current("position_periodic_friction", effect_inputs(x, v), 0.2, period_mm=7.0, phase_rad=0.3)
    assert force[0] == force[1] and force[2] == force[3]
    assert friction[0] == pytest.approx(-friction[1]) and friction[2] == pytest.approx(-friction[3])
    np.testing.assert_allclose(np.abs(friction), np.abs(force), rtol=1e-6)
    asymmetry = effect_current("direction_asymmetry", effect_inputs(x, v), 0.2)
    np.testing.assert_allclose(asymmetry, [0.2, 0.0, 0.2, 0.0], atol=1e-6)


def test_periodic_force_has_its_period():
    x = np.linspace(-300.0, -200.0, 10001)
    current = effect_current("position_periodic_force", effect_inputs(x, np.ones_like(x)), 0.1, period_mm=4.0)
    np.testing.assert_allclose(current[400:], current[:-400], atol=1e-12)  # 400 steps = 4 mm
    assert current.max() == pytest.approx(0.1, rel=1e-6)


def test_trend_drift_inertia_viscous_reference_conditions():
    x = np.array([-510.0, -255.0, 0.0])
    v = np.array([2000.0 / 60.0] * 3)
    a = np.array([1000.0, 0.0, -500.0])
    t = np.array([0.0, 60.0, 1e6])
    inputs = effect_inputs(x, v, a, t)
    np.testing.assert_allclose(effect_current("position_trend", inputs, 0.3), [-0.3, 0.0, 0.3], atol=1e-9)
    np.testing.assert_allclose(effect_current("position_trend", effect_inputs(x, -v), 0.3, same_sign=True),
                               [-0.3, 0.0, 0.3], atol=1e-12)
    np.testing.assert_allclose(effect_current("thermal_drift", inputs, -0.2),
                               [0.0, -0.2 * (1 - np.exp(-1.0)), -0.2], atol=1e-9)
    np.testing.assert_allclose(effect_current("inertia_mismatch", inputs, 0.1), [0.1, 0.0, -0.05])
    np.testing.assert_allclose(effect_current("viscous_friction", inputs, 0.15), 0.15)
    np.testing.assert_allclose(effect_current("constant_offset", inputs, -0.05), -0.05)


def test_unknown_effect_or_parameter_is_a_clear_error():
    inputs = effect_inputs([0.0], [1.0])
    with pytest.raises(GreyboxError, match="unknown hidden effect 'friction_wave'.*thermal_drift"):
        effect_current("friction_wave", inputs, 0.1)
    with pytest.raises(GreyboxError, match="no parameter tau.*time_constant_s"):
        effect_current("thermal_drift", inputs, 0.1, tau=3.0)
    with pytest.raises(GreyboxError, match="unknown hidden effect"):
        make_dataset("X", "D", effect="nope")


def test_cutting_current_opposes_the_feed_and_vanishes_outside_cuts():
    log = make_dataset("X", "A", seed=1, duration_s=30.0, cutting=True)
    process = log.extras["truth_process_A"]
    truth = make_dataset("X", "A", seed=1, duration_s=30.0)
    trajectory = dataset_trajectory(AXES["X"], "A", dataset_streams(1, "X", "A")[0], duration_s=30.0)
    velocity = trajectory.motion.evaluate(log.time)[1]
    spec = CuttingSpec()
    low, high = log.attrs["cutting"]["workpiece_mm"]
    cutting = process != 0.0
    assert cutting.any() and log.attrs["cutting"]["cut_segments"] == len(cut_segments(process)) > 1
    # the load opposes the feed, so the drive current it needs points along the motion (cutting direction -x)
    assert np.all(np.sign(process[cutting]) == -1.0)
    assert np.all(velocity[cutting] < 0.0)
    # nothing outside the workpiece or on the return strokes
    x = log.position
    assert np.all(process[(x < low - 1e-3) | (x > high + 1e-3)] == 0.0)
    assert np.all(process[velocity >= 0.0] == 0.0)
    np.testing.assert_allclose(log.extras["truth_current_A"] - truth.extras["truth_current_A"], process, atol=1e-12)
    assert np.abs(process).max() <= spec.strength_A * (2000.0 / 1000.0) ** spec.feed_exponent * (
        1 + spec.ripple * (np.pi / 2 - 1)) + 1e-9


def test_cutting_entry_ramp_ripple_and_feed_scaling():
    spec = CuttingSpec(workpiece_mm=(-40.0, 0.0), spindle_rpm=1500.0, teeth=4, ripple=0.5, entry_length_mm=5.0)
    t = np.arange(0, 2.0, 1e-4)
    v = np.full_like(t, -10.0)
    x = 10.0 + v * t  # from +10 to -10 mm: enters the workpiece at 0 mm
    current = cutting_current(spec, t, x, v)
    assert np.all(current[x > 0.0] == 0.0)
    entering = (x < 0.0) & (x > -5.0)
    full = x < -5.0
    envelope = np.abs(current) / (1 + spec.ripple * (0.5 * np.pi * np.abs(np.sin(np.pi * 100.0 * t)) - 1))
    assert np.all(np.diff(envelope[entering]) >= -1e-12)  # engagement ramps up over the entry length
    np.testing.assert_allclose(envelope[full], spec.strength_A * 0.6 ** 0.75, rtol=1e-9)
    spectrum = np.abs(np.fft.rfft(current[full] - current[full].mean()))
    frequency = np.fft.rfftfreq(int(full.sum()), 1e-4)
    assert frequency[np.argmax(spectrum)] == pytest.approx(100.0, abs=1.0)  # n z / 60 = 100 Hz
    assert np.all(cutting_current(spec, t, x, -v) == 0.0)  # return stroke: air cut
