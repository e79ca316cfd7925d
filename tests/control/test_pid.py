"""The discrete PID and its tuning rule."""

from __future__ import annotations

import math

import numpy as np
import pytest

from greybox.control.pid import ControllerSettings, PIDGains, measure, pid_step
from greybox.control.tuning import default_bandwidth_hz, pole_placement_gains
from greybox.errors import ParameterError


def _settings(kp=2.0, ki=30.0, kd=0.05, tf=1e-3, period=1e-3, limit=5.0, resolution=0.0):
    return ControllerSettings.from_gains(PIDGains(kp, ki, kd, tf), period, limit, resolution)


def python_pid(errors, feedforward, s):
    """The controller written out from its difference equations."""
    integral, derivative, previous, out = 0.0, 0.0, errors[0], []
    for e, ff in zip(errors, feedforward):
        derivative = s.derivative_decay * derivative + s.derivative_gain * (e - previous)
        demand = ff + s.kp * e + integral + derivative
        u = min(max(demand, -s.current_limit_A), s.current_limit_A)
        if not ((demand > s.current_limit_A and e > 0) or (demand < -s.current_limit_A and e < 0)):
            integral += s.ki_dt * e
        previous = e
        out.append(u)
    return np.array(out)


def compiled_pid(errors, feedforward, s):
    memory = np.array([0.0, 0.0, errors[0]])
    return np.array([pid_step(memory, s, e, ff) for e, ff in zip(errors, feedforward)])


def test_compiled_step_agrees_with_plain_python():
    rng = np.random.default_rng(0)
    errors = np.cumsum(rng.normal(0.0, 0.2, 3000))
    feedforward = rng.normal(0.0, 1.0, 3000)
    s = _settings()
    got = compiled_pid(errors, feedforward, s)
    np.testing.assert_allclose(got, python_pid(errors, feedforward, s), rtol=1e-12, atol=1e-12)
    assert np.any(np.abs(got) == s.current_limit_A)  # the saturation was exercised


def test_proportional_integral_and_filtered_derivative():
    period, tf, kd = 1e-3, 2e-3, 0.05
    s = _settings(kp=2.0, ki=0.0, kd=kd, tf=tf, period=period, limit=1e9)
    # a constant error: no derivative kick at the start, the P part only
    assert compiled_pid(np.full(5, 0.1), np.zeros(5), s) == pytest.approx(np.full(5, 0.2))
    # a ramp of slope c: the filtered derivative settles at kd * c
    slope = 3.0
    ramp = slope * period * np.arange(2000)
    u = compiled_pid(ramp, np.zeros(ramp.size), s) - 2.0 * ramp
    assert u[-1] == pytest.approx(kd * slope, rel=1e-9)
    assert u[1] == pytest.approx(kd * slope * period / (tf + period), rel=1e-9)  # first-order lag, backward Euler
    # integral: ki T per unit error and sample
    s = _settings(kp=0.0, ki=40.0, kd=0.0, period=period, limit=1e9)
    assert compiled_pid(np.full(11, 0.5), np.zeros(11), s)[-1] == pytest.approx(10 * 40.0 * period * 0.5)


def test_anti_windup_stops_integrating_into_the_limit():
    s = _settings(kp=1.0, ki=100.0, kd=0.0, limit=2.0)
    errors = np.concatenate((np.full(1000, 5.0), np.full(400, -0.5)))
    u = compiled_pid(errors, np.zeros(errors.size), s)
    assert np.all(u[:1000] == 2.0)
    # the integral froze at the limit instead of growing to 100 * 1e-3 * 5 * 1000 = 500 A,
    # so the output leaves the limit as soon as the error changes sign
    assert u[1000] < 2.0 and u[1010] < u[1000]
    ideal = python_pid(errors, np.zeros(errors.size), _settings(kp=1.0, ki=100.0, kd=0.0, limit=1e9))
    assert ideal[1000] > 400.0


def test_encoder_measurement_rounds_to_the_resolution():
    assert measure(1.23456789, 1e-4) == pytest.approx(1.2346)
    assert measure(-0.00004, 1e-4) == 0.0
    assert measure(1.23456789, 0.0) == 1.23456789


def test_invalid_gains_and_settings():
    with pytest.raises(ParameterError, match="kp"):
        PIDGains(-1.0, 0.0, 0.0, 0.0)
    with pytest.raises(ParameterError, match="current limit"):
        ControllerSettings.from_gains(PIDGains(1.0, 0.0, 0.0, 0.0), 1e-3, 0.0, 0.0)
    with pytest.raises(ParameterError, match="inertia"):
        pole_placement_gains(0.0, 10.0)


# ------------------------------------------------------------------ tuning
def test_pole_placement_puts_a_triple_pole_at_minus_omega():
    j, f = 3e-4, 20.0
    g = pole_placement_gains(j, f)
    roots = np.roots([j, g.kd, g.kp, g.ki])  # rigid axis J s^2 under the ideal PID
    np.testing.assert_allclose(roots.real, -2 * math.pi * f, rtol=1e-3)
    np.testing.assert_allclose(roots.imag, 0.0, atol=1e-3 * 2 * math.pi * f)
    assert g.derivative_filter_s == pytest.approx(1.0 / (10 * 2 * math.pi * f))


def _sampled_loop_poles(j, gains, period):
    """Closed-loop poles of the sampled rigid axis (exact zero-order hold) under the discrete PID."""
    s = ControllerSettings.from_gains(gains, period, 1e9, 0.0)
    # state: position, velocity, integral, derivative, previous error; reference 0, error = -position
    error = np.array([-1.0, 0, 0, 0, 0])
    derivative = s.derivative_decay * np.array([0, 0, 0, 1.0, 0]) + s.derivative_gain * (
        error - np.array([0, 0, 0, 0, 1.0]))
    current = s.kp * error + np.array([0, 0, 1.0, 0, 0]) + derivative
    a = np.zeros((5, 5))
    a[0] = np.array([1.0, period, 0, 0, 0]) + period**2 / (2 * j) * current
    a[1] = np.array([0, 1.0, 0, 0, 0]) + period / j * current
    a[2] = np.array([0, 0, 1.0, 0, 0]) + s.ki_dt * error
    a[3] = derivative
    a[4] = error
    return np.linalg.eigvals(a)


@pytest.mark.parametrize("period", [0.25e-3, 2e-3])
def test_default_bandwidth_gives_a_well_damped_sampled_loop(period):
    j = 2.8e-4
    poles = _sampled_loop_poles(j, pole_placement_gains(j, default_bandwidth_hz(period)), period)
    continuous = np.log(poles.astype(complex)) / period
    damping = -continuous.real / np.abs(continuous)
    assert np.max(np.abs(poles)) < 1.0
    assert np.min(damping) > 0.45
    # four times the rule's bandwidth is beyond what the sampled loop can take
    fast = _sampled_loop_poles(j, pole_placement_gains(j, 4 * default_bandwidth_hz(period)), period)
    assert np.max(np.abs(fast)) > 1.0
