"""The independent Bouc-Wen axis family (studies.hysteresis_axis): physics, logs, hidden effects."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from greybox.data.prepare import prepare
from studies import hysteresis_axis as ha

#: A validation study's tests (runs of the study, its script, the real data sets): left out of the default
#: run (`pytest -m slow` runs them, as .ci/run does).
pytestmark = pytest.mark.slow

SHORT_S = 10.0


def rms(values):
    return float(np.sqrt(np.mean(np.square(values))))


def motion_along(position, time):
    """Motion with the given path [mm] over time [s], velocity by differences and no acceleration."""
    return ha.Motion(time, position, np.gradient(position, time), np.zeros_like(time))


def stribeck_A(speed, axis):
    """The Stribeck curve of the module notes, written out here."""
    return axis.coulomb_A + (axis.static_A - axis.coulomb_A) * np.exp(
        -(speed / axis.stribeck_velocity_mm_s) ** axis.stribeck_exponent)


@pytest.fixture(scope="module")
def null_case():
    return ha.family_logs(ha.FamilyCase(None, seed=4, duration_s=SHORT_S))


# ------------------------------------------------------------------------------------------- logs
def test_logs_are_deterministic_raw_and_on_a_2_ms_grid(null_case):
    train, test, info = null_case
    again_train, again_test, _ = ha.family_logs(ha.FamilyCase(None, seed=4, duration_s=SHORT_S))
    other_train, _, _ = ha.family_logs(ha.FamilyCase(None, seed=5, duration_s=SHORT_S))
    assert len(train) == len(test) == 2
    for log, other in zip(train, other_train):
        assert not np.allclose(log.effort, other.effort) and not np.allclose(log.position, other.position)
    for log, again in zip(train + test, again_train + again_test):
        np.testing.assert_array_equal(log.effort, again.effort)
        np.testing.assert_array_equal(log.position, again.position)
        assert log.velocity is None and log.acceleration is None and log.effort_unit == "A"
        assert np.all(np.isfinite(log.effort)) and np.all(np.isfinite(log.position))
        steps = np.diff(log.time)
        assert np.all(steps > 0)
        np.testing.assert_allclose(steps, ha.SAMPLE_TIME_S, rtol=1e-9)
        assert log.time[0] == 0.0 and log.duration == pytest.approx(SHORT_S)
        np.testing.assert_allclose(log.position / ha.ENCODER_RESOLUTION_MM,
                                   np.round(log.position / ha.ENCODER_RESOLUTION_MM), atol=1e-6)
    # four different trajectories
    positions = [log.position for log in train + test]
    assert all(not np.array_equal(positions[0], p) for p in positions[1:])
    assert info["axis"] == ha.draw_axis(4).__dict__


def test_currents_and_motion_have_the_documented_size(null_case):
    train, test, info = null_case
    axis = ha.draw_axis(4)
    low = axis.travel_centre_mm - ha.TRAVEL_MM / 2
    for log, velocity, acceleration in zip(train + test, info["velocity_mm_s"], info["acceleration_mm_s2"]):
        assert 0.2 < rms(log.effort) < 3.0
        assert low - 1e-9 <= log.position.min() and log.position.max() <= low + ha.TRAVEL_MM + 1e-9
        assert np.abs(velocity).max() <= ha.FEED_RANGE_MM_S[1] + 1e-9
        assert np.abs(acceleration).max() <= axis.acceleration_limit_mm_s2 * (1 + 1e-9)
        assert np.sum(np.diff(np.sign(velocity[np.abs(velocity) > 1e-6])) != 0) >= 5   # reversals


def test_noise_is_ar1_with_the_drawn_correlation():
    _, _, info = ha.family_logs(ha.FamilyCase(None, seed=8, duration_s=60.0))
    axis = ha.draw_axis(8)
    noise = np.concatenate(info["noise_A"])
    assert info["noise_rms_A"] == pytest.approx(rms(info["noise_A"][0]))
    assert rms(noise) == pytest.approx(axis.noise_std_A, rel=0.05)
    lag1 = np.corrcoef(noise[1:], noise[:-1])[0, 1]
    assert lag1 == pytest.approx(axis.noise_correlation, abs=0.03)


def test_axes_are_drawn_within_the_documented_ranges():
    for seed in range(20):
        axis = ha.draw_axis(seed)
        for name, (low, high) in ha.AXIS_RANGES.items():
            assert low <= getattr(axis, name) <= high
    assert ha.draw_axis(3) == ha.draw_axis(3) and ha.draw_axis(3) != ha.draw_axis(4)


# ------------------------------------------------------------------------------------ friction law
@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("speed", [0.3, 2.0, 7.0, 45.0])
@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_steady_sliding_follows_the_stribeck_curve(seed, speed, direction):
    axis = ha.draw_axis(seed)
    length = 200 * axis.presliding_mm
    time = np.linspace(0.0, length / speed, 2001)
    current = ha.axis_current(motion_along(direction * speed * time, time), axis)
    expected = direction * (stribeck_A(speed, axis) + axis.viscous_A_s_mm * speed)
    assert current[-1] == pytest.approx(expected, rel=0.01)
    assert current[-1] == pytest.approx(expected, rel=1e-6)   # saturated: |w| = 1 to the table's end


def test_hysteresis_state_matches_the_ode():
    axis = ha.draw_axis(6)
    xp, n, beta = axis.presliding_mm, axis.hysteresis_exponent, axis.hysteresis_beta

    def slope(x, w, direction):   # dw/dx, integrated along x in the direction of the leg
        return 1 / xp * (1 - np.abs(w) ** n * ((1 - beta) + beta * np.sign(direction * w)))

    corners = np.array([0.0, 3.0, -1.5, 0.4, -0.2, 4.0]) * xp
    path = np.concatenate([np.linspace(a, b, 400, endpoint=False) for a, b in zip(corners[:-1], corners[1:])]
                          + [corners[-1:]])
    w = ha.hysteresis_state(path, axis)
    state = 0.0
    for k, (a, b) in enumerate(zip(corners[:-1], corners[1:])):
        leg = np.linspace(a, b, 400, endpoint=False)
        solution = solve_ivp(slope, (a, b), [state], t_eval=leg, args=(np.sign(b - a),), rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(w[400 * k:400 * (k + 1)], solution.y[0], atol=1e-5)
        state = solve_ivp(slope, (a, b), [state], args=(np.sign(b - a),), rtol=1e-10, atol=1e-12).y[0, -1]
    assert np.abs(w).max() < 1


def loop(axis, amplitude_mm, frequency_hz=0.02):
    """Two cycles of a sine in position from w = 0: (position, hysteretic friction) over the second cycle."""
    time = np.linspace(0.0, 2 / frequency_hz, 8001)
    position = amplitude_mm * np.sin(2 * np.pi * frequency_hz * time)
    motion = motion_along(position, time)
    friction = ha.axis_current(motion, axis) - axis.viscous_A_s_mm * motion.velocity
    return position[4000:], friction[4000:], stribeck_A(np.abs(motion.velocity[4000:]), axis)


@pytest.mark.parametrize("seed", [0, 3])
def test_small_cycle_presliding_dissipates_below_the_stribeck_level(seed):
    axis = ha.draw_axis(seed)
    position, friction, level = loop(axis, 0.3 * axis.presliding_mm)
    area = np.sum(0.5 * (friction[1:] + friction[:-1]) * np.diff(position))
    assert area > 0
    assert 0.1 < np.max(np.abs(friction) / level) < 0.6


@pytest.mark.parametrize("seed", [0, 3])
def test_large_cycle_slides_and_dissipates_about_four_amplitudes_times_friction(seed):
    axis = ha.draw_axis(seed)
    amplitude = 20 * axis.presliding_mm
    position, friction, level = loop(axis, amplitude)
    area = np.sum(0.5 * (friction[1:] + friction[:-1]) * np.diff(position))
    assert 0.8 * 4 * amplitude * axis.coulomb_A < area < 4 * amplitude * axis.static_A
    assert np.max(np.abs(friction) / level) > 0.99


def test_direction_asymmetry_acts_through_the_hysteresis_without_a_jump_at_reversal():
    axis = ha.draw_axis(2)
    time = np.linspace(0.0, 4.0, 40001)
    motion = motion_along(20 * axis.presliding_mm * np.sin(np.pi * time), time)
    hidden = ha.axis_current(motion, axis, ha.Modifiers(negative_level=0.5)) - ha.axis_current(motion, axis)
    w = ha.hysteresis_state(motion.position, axis)
    assert np.all(hidden[w >= 0] == 0)
    assert hidden.max() > 0.45 * axis.coulomb_A   # half the (negative) friction is missing in negative sliding
    assert np.abs(np.diff(hidden)).max() < 0.02 * axis.coulomb_A   # continuous where the velocity reverses


# ---------------------------------------------------------------------------------- hidden effects
@pytest.mark.parametrize("effect", ha.HIDDEN_EFFECTS)
def test_hidden_effect_has_the_requested_ratio_and_leaves_the_rest_alone(effect, null_case):
    train, test, info = ha.family_logs(ha.FamilyCase(effect, ratio=2.0, seed=4, duration_s=SHORT_S))
    null_train, null_test, null_info = null_case
    achieved = rms(info["hidden_A"][0]) / rms(info["noise_A"][0])
    assert achieved == pytest.approx(2.0, rel=0.1)
    assert info["ratio_achieved"] == pytest.approx(achieved)
    assert info["effect"] == effect and info["effect_parameters"]["strength"] > 0
    for log, null, hidden, noise, null_noise in zip(train + test, null_train + null_test, info["hidden_A"],
                                                    info["noise_A"], null_info["noise_A"]):
        assert rms(hidden) > 0.2 * rms(info["hidden_A"][0])
        np.testing.assert_array_equal(log.position, null.position)
        np.testing.assert_array_equal(noise, null_noise)
        np.testing.assert_allclose(log.effort - hidden, null.effort, atol=1e-12)


def test_nothing_is_hidden_in_the_null_case(null_case):
    _, _, info = null_case
    assert info["effect_parameters"] == {} and info["ratio_achieved"] == 0.0
    assert all(not np.any(hidden) for hidden in info["hidden_A"])


def test_effect_shapes_come_from_their_own_stream():
    first = ha.family_logs(ha.FamilyCase("thermal_drift", seed=1, duration_s=2.0))[2]["effect_parameters"]
    again = ha.family_logs(ha.FamilyCase("thermal_drift", ratio=0.5, seed=1, duration_s=2.0))[2]["effect_parameters"]
    other = ha.family_logs(ha.FamilyCase("thermal_drift", seed=2, duration_s=2.0))[2]["effect_parameters"]
    assert first["time_constant_s"] == again["time_constant_s"] != other["time_constant_s"]
    assert first["sign"] == again["sign"] and first["strength"] == pytest.approx(2 * again["strength"])


def fit_share(values, columns):
    """Share of the variance of ``values`` explained by least squares on ``columns``."""
    design = np.column_stack(columns)
    coefficients = np.linalg.lstsq(design, values, rcond=None)[0]
    return 1 - np.var(values - design @ coefficients) / np.var(values), coefficients


def test_periodic_force_is_periodic_in_position_with_the_drawn_period():
    train, _, info = ha.family_logs(ha.FamilyCase("position_periodic_force", ratio=3.0, seed=7, duration_s=SHORT_S))
    parameters = info["effect_parameters"]
    x, hidden = train[0].position, info["hidden_A"][0]

    def waves(period):
        return np.sin(2 * np.pi * x / period), np.cos(2 * np.pi * x / period)

    share, coefficients = fit_share(hidden, waves(parameters["period_mm"]))
    assert share > 0.999
    assert np.hypot(*coefficients) == pytest.approx(parameters["strength"], rel=0.01)
    periods = parameters["period_mm"] * np.linspace(0.5, 2.0, 151)
    best = periods[np.argmax([fit_share(hidden, waves(period))[0] for period in periods])]
    assert best == pytest.approx(parameters["period_mm"], rel=0.02)


def test_periodic_friction_flips_with_the_direction():
    train, _, info = ha.family_logs(ha.FamilyCase("position_periodic_friction", ratio=3.0, seed=7,
                                                  duration_s=SHORT_S))
    parameters = info["effect_parameters"]
    wave = np.sin(2 * np.pi * train[0].position / parameters["period_mm"] + parameters["phase_rad"])
    velocity, hidden = info["velocity_mm_s"][0], info["hidden_A"][0]
    sliding = (np.abs(velocity) > 1.0) & (np.abs(wave) > 0.2)
    assert np.any(sliding & (velocity > 0)) and np.any(sliding & (velocity < 0))
    agree = np.sign(hidden[sliding]) == np.sign(velocity[sliding] * wave[sliding] * parameters["amplitude"])
    assert agree.mean() > 0.99


def test_too_strong_an_effect_is_refused():
    refused = 0
    for seed in range(6):   # a friction reduction in negative motion is refused, an increase is not
        try:
            info = ha.family_logs(ha.FamilyCase("direction_asymmetry", ratio=500.0, seed=seed, duration_s=5.0))[2]
        except ValueError as error:
            assert "smaller ratio" in str(error)
            refused += 1
        else:
            assert info["effect_parameters"]["amplitude"] < -1
    assert 0 < refused < 6
    with pytest.raises(ValueError, match="unknown hidden effect"):
        ha.FamilyCase("stribeck")


# -------------------------------------------------------------------------------------- preparation
def test_prepare_derives_the_true_velocity(null_case):
    train, test, info = null_case
    prepared = prepare(train + test)
    for log, velocity in zip(prepared, info["velocity_mm_s"]):
        assert log.is_prepared and len(log) == len(velocity)
        assert rms(log.velocity - velocity) < 0.02 * rms(velocity)


# -------------------------------------------------------------------------------------- independence
def test_module_imports_nothing_of_the_models_or_the_twin():
    forbidden = ("greybox.models.friction", "greybox.twin", "greybox.discover", "greybox.identify", "greybox.models")
    package = ha.__name__.split(".")[:-1]
    imported = []
    for node in ast.walk(ast.parse(Path(ha.__file__).read_text())):
        if isinstance(node, ast.Import):
            imported += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = package[:len(package) + 1 - node.level] if node.level else []
            module = ".".join(base + ([node.module] if node.module else []))
            imported += [module] + [f"{module}.{alias.name}" for alias in node.names]
    assert "greybox.data.log" in imported
    assert not [name for name in imported if name.startswith(forbidden)]
