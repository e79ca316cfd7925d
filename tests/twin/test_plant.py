"""Truth plant of the synthetic axis: Maxwell-slip kernel, steady sliding, pre-sliding, position profile."""

from __future__ import annotations

import math

import numpy as np
import pytest

from greybox.errors import GreyboxError
from greybox.twin.plant import default_plant_parameters, maxwell_slip_kernel, simulate_plant


class FunctionMotion:
    """Motion given by a function of time returning (x, v, a)."""

    def __init__(self, function):
        self.function = function

    def evaluate(self, time_s):
        return self.function(np.asarray(time_s, dtype=float))


def constant_velocity(start_mm, velocity_mm_s):
    return FunctionMotion(lambda t: (start_mm + velocity_mm_s * t, np.full_like(t, velocity_mm_s), np.zeros_like(t)))


def sine_motion(centre_mm, amplitude_mm, frequency_hz):
    w = 2.0 * np.pi * frequency_hz
    return FunctionMotion(lambda t: (centre_mm + amplitude_mm * np.sin(w * t), amplitude_mm * w * np.cos(w * t),
                                     -amplitude_mm * w * w * np.sin(w * t)))


def reference_maxwell_slip(position, velocity, step, stride, stiffness, deflection, coulomb_ratio,
                           stribeck_velocity, stribeck_shape, lag_time):
    """Plain-Python elasto-plastic Maxwell-slip elements with a lagged Stribeck ratio."""

    def ratio(v):
        return coulomb_ratio + (1.0 - coulomb_ratio) * math.exp(-((abs(v) / stribeck_velocity) ** stribeck_shape))

    states = [0.0] * len(stiffness)
    level = ratio(velocity[0])
    keep = math.exp(-step / lag_time) if lag_time > 0 else 0.0
    out = []
    for i in range(len(position)):
        dx = 0.0
        if i > 0:
            target = ratio(velocity[i])
            level = target + (level - target) * keep
            dx = position[i] - position[i - 1]
        total = 0.0
        for j in range(len(stiffness)):
            limit = deflection[j] * level
            states[j] = min(max(states[j] + dx, -limit), limit)
            total += stiffness[j] * states[j]
        if i % stride == 0:
            out.append(total)
    return np.array(out)


@pytest.fixture
def plant():
    return default_plant_parameters("X")


@pytest.fixture
def flat_plant(plant):
    """The X plant without position dependence."""
    return plant.replace(preload_gain=0.0, lead_gain=0.0, tilt_gain=0.0)


def test_kernel_agrees_with_plain_python_reference(plant):
    rng = np.random.default_rng(3)
    t = np.arange(4001) * plant.internal_step_s
    velocity = 2.0 * np.sin(2 * np.pi * 1.3 * t) + 0.5 * np.sin(2 * np.pi * 7.0 * t + 1.0)
    position = -250.0 + np.cumsum(velocity) * plant.internal_step_s + 1e-4 * rng.standard_normal(t.size)
    args = (position, velocity, plant.internal_step_s, 8, plant.stiffness_A_mm,
            np.asarray(plant.breakaway_deflection_mm), plant.coulomb_ratio, plant.stribeck_velocity_mm_s,
            plant.stribeck_shape, plant.lag_time_s)
    compiled = maxwell_slip_kernel(*args)
    reference = reference_maxwell_slip(*args)
    assert compiled.shape == (501,)
    np.testing.assert_allclose(compiled, reference, rtol=0, atol=1e-12)
    no_lag = args[:-1] + (0.0,)
    np.testing.assert_allclose(maxwell_slip_kernel(*no_lag), reference_maxwell_slip(*no_lag), rtol=0, atol=1e-12)


@pytest.mark.parametrize("speed_mm_min", [100.0, 250.0, 600.0, 1200.0, 2000.0])
@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_steady_sliding_follows_the_stribeck_curve(flat_plant, speed_mm_min, direction):
    v = direction * speed_mm_min / 60.0
    response = simulate_plant(flat_plant, constant_velocity(-250.0, v), 1001)
    friction = response.friction_A[-1]
    coulomb = flat_plant.static_friction_A * flat_plant.stribeck_ratio(v)
    assert friction == pytest.approx(direction * coulomb + flat_plant.viscous_A_s_mm * v, abs=1e-9)
    assert np.sign(friction) == direction
    # about 1.1-1.3 A like the recalibrated paper axes: Coulomb level 0.9 x 1.25 A, up to 0.2 A viscous
    assert 1.0 < abs(friction) < 1.4


def test_stribeck_decrease_then_viscous_rise(flat_plant):
    speeds = np.array([100.0, 150.0, 300.0, 2000.0]) / 60.0
    friction = [simulate_plant(flat_plant, constant_velocity(-250.0, v), 501).friction_A[-1] for v in speeds]
    assert friction[0] > friction[1] > friction[2]
    assert friction[3] > friction[2]


def test_frictional_lag_is_first_order(flat_plant):
    """After a speed step the breakaway level reaches 1 - 1/e of its change after one lag time."""
    v1, v2, t_step = 1.5, 30.0, 0.5
    motion = FunctionMotion(lambda t: (np.where(t < t_step, v1 * t, v1 * t_step + v2 * (t - t_step)),
                                       np.where(t < t_step, v1, v2), np.zeros_like(t)))
    plant = flat_plant.replace(viscous_A_s_mm=0.0, lag_time_s=0.02)
    response = simulate_plant(plant, motion, 501)
    before = plant.static_friction_A * plant.stribeck_ratio(v1)
    after = plant.static_friction_A * plant.stribeck_ratio(v2)
    k = int(round((t_step + plant.lag_time_s) / 0.002))
    fraction = (before - response.friction_A[k]) / (before - after)
    assert fraction == pytest.approx(1.0 - math.exp(-1.0), abs=0.01)
    assert response.friction_A[-1] == pytest.approx(after, rel=1e-9)


def test_presliding_hysteresis_loop(flat_plant):
    """A small oscillation gives a closed loop with dissipation, below breakaway."""
    # 0.5 um: below the typical breakaway deflection (0.7 um) of elements spread over 0.1-5 um
    response = simulate_plant(flat_plant.replace(viscous_A_s_mm=0.0), sine_motion(-250.0, 0.0005, 1.0), 1501)
    x, friction = response.position_mm, response.friction_A
    second, third = slice(500, 1001), slice(1000, 1501)
    np.testing.assert_allclose(friction[second], friction[third], atol=1e-9)  # closed loop
    dissipated = np.trapezoid(friction[third], x[third])  # energy per cycle [A mm]
    assert dissipated > 0.0
    assert np.max(np.abs(friction)) < 0.9 * flat_plant.static_friction_A
    # not a spring: passing the centre, the friction points along the motion (Masing branches)
    assert response.velocity_mm_s[1000] > 0 > response.velocity_mm_s[1250]
    assert friction[1000] > 0.0 > friction[1250]


def test_virgin_curve_is_stiffer_for_smaller_displacements(flat_plant):
    """The slope of the initial loading curve falls as elements break away (Maxwell-slip)."""
    # 0.01 um per 2 ms sample, below the smallest breakaway deflection (0.1 um); 5 um in 1 s, the largest
    response = simulate_plant(flat_plant.replace(viscous_A_s_mm=0.0), constant_velocity(-250.0, 0.005), 501)
    x = response.position_mm - response.position_mm[0]
    slope = np.diff(response.friction_A) / np.diff(x)
    assert slope[0] == pytest.approx(flat_plant.stiffness_A_mm.sum(), rel=1e-6)
    assert np.all(np.diff(slope) <= 1e-9)
    assert slope[-1] < 0.05 * slope[0]


def test_friction_rises_towards_the_travel_ends(plant):
    """The preload profile c_pre u^4 raises the friction at both ends of the travel."""
    plant = plant.replace(tilt_gain=0.0)  # isolate the preload; the trend along the travel has its own test
    low, high = plant.travel_mm
    v = 20.0
    duration = (high - low) / v
    n = int(duration / 0.002)
    response = simulate_plant(plant, constant_velocity(low, v), n)
    x, friction = response.position_mm, response.friction_A
    middle = np.abs(x - 0.5 * (low + high)) < 20.0
    near_low, near_high = x < low + 20.0, x > high - 20.0
    steady = np.arange(n) > 50
    # u^4 averages 0.85 over the outer 20 mm; the viscous part (10 %) of the friction does not rise
    rise = 1.0 + 0.6 * plant.preload_gain
    assert friction[near_low & steady].mean() > friction[middle].mean() * rise
    assert friction[near_high].mean() > friction[middle].mean() * rise


def test_friction_trend_along_the_travel():
    """The tilt c_tilt u changes the sliding friction linearly along the travel; strongest on Y."""
    y = default_plant_parameters("Y")
    plant = y.replace(preload_gain=0.0, lead_gain=0.0)  # isolate the trend
    low, high = plant.travel_mm
    v = 40.0
    n = int((high - low) / v / 0.002)
    response = simulate_plant(plant, constant_velocity(low, v), n)
    steady = slice(100, None)
    u = (2.0 * response.position_mm[steady] - low - high) / (high - low)
    slope, intercept = np.polyfit(u, response.friction_A[steady], 1)
    coulomb = plant.static_friction_A * plant.stribeck_ratio(v)
    assert slope == pytest.approx(plant.tilt_gain * coulomb, rel=1e-6)
    assert intercept == pytest.approx(coulomb + plant.viscous_A_s_mm * v, rel=1e-6)
    # the paper's Y axis has the larger position effect
    x_axis = default_plant_parameters("X")
    spread = [np.ptp(p.position_factor(np.linspace(*p.travel_mm, 2001))) for p in (y, x_axis)]
    assert spread[0] > spread[1]


def test_cogging_current_is_periodic_in_position(plant):
    """The cogging current depends on the position alone, with the motor's cogging period, in either direction."""
    v, n = 20.0, 5000  # 200 mm in the middle of the travel
    forward = simulate_plant(plant, constant_velocity(-355.0, v), n)
    backward = simulate_plant(plant, constant_velocity(-355.0 + v * 0.002 * (n - 1), -v), n)
    np.testing.assert_allclose(forward.current_A, forward.friction_A + forward.inertia_A + forward.cogging_A,
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(forward.cogging_A, plant.cogging_current(forward.position_mm), rtol=0, atol=1e-12)
    # same positions, opposite motion: friction reverses, cogging does not
    np.testing.assert_allclose(backward.cogging_A[::-1], forward.cogging_A, rtol=0, atol=1e-9)
    assert np.all(np.sign(backward.friction_A[100:]) == -1.0) and np.all(np.sign(forward.friction_A[100:]) == 1.0)
    spacing = v * 0.002
    spectrum = np.abs(np.fft.rfft(forward.cogging_A * np.hanning(n)))
    frequencies = np.fft.rfftfreq(n, d=spacing)  # cycles per mm
    peak = frequencies[np.argmax(spectrum[1:]) + 1]
    assert peak == pytest.approx(1.0 / plant.cogging_period_mm, rel=0.01)
    assert 0.5 * np.ptp(forward.cogging_A) == pytest.approx(plant.cogging_A, rel=0.01)
    assert plant.cogging_A == pytest.approx(0.1)  # the calibrated amplitude


def test_periodic_friction_component_at_the_screw_lead(plant):
    v, n = 20.0, 5000  # 200 mm in the middle of the travel
    response = simulate_plant(plant, constant_velocity(-355.0, v), n)
    friction = response.friction_A[100:] - np.polyval(np.polyfit(response.position_mm[100:],
                                                                  response.friction_A[100:], 4),
                                                       response.position_mm[100:])
    spacing = v * 0.002
    spectrum = np.abs(np.fft.rfft(friction * np.hanning(friction.size)))
    frequencies = np.fft.rfftfreq(friction.size, d=spacing)  # cycles per mm
    peak = frequencies[np.argmax(spectrum[1:]) + 1]
    assert peak == pytest.approx(1.0 / plant.lead_mm, rel=0.05)
    amplitude = 0.5 * (friction.max() - friction.min())
    sliding = plant.static_friction_A * plant.stribeck_ratio(v)
    assert amplitude == pytest.approx(plant.lead_gain * sliding, rel=0.1)


def test_internal_step_must_divide_the_sample_time(plant):
    with pytest.raises(GreyboxError, match="divide"):
        simulate_plant(plant.replace(internal_step_s=0.3e-3), constant_velocity(0.0, 1.0), 10)


def test_invalid_parameters_are_refused(plant):
    with pytest.raises(GreyboxError, match="coulomb_ratio"):
        plant.replace(coulomb_ratio=1.5)
    with pytest.raises(GreyboxError, match="same"):
        plant.replace(breakaway_A=plant.breakaway_A[:3])


def test_y_axis_is_heavier_and_longer(plant):
    y = default_plant_parameters("Y")
    assert y.inertia_A_s2_mm > plant.inertia_A_s2_mm
    assert y.travel_mm[1] - y.travel_mm[0] > plant.travel_mm[1] - plant.travel_mm[0]
    assert len(y.breakaway_A) >= 16 and len(plant.breakaway_A) >= 16
