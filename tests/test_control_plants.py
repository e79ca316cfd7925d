"""Closed-loop plants: compiled loop kernels against plain-Python references, and steady-sliding physics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from greybox.control.loop import controller_periods, simulate_loop
from greybox.control.pid import ControllerSettings
from greybox.control.plants import ModelPlant, TwinPlant, fine_stride, maxwell_slip_update, stribeck_ratio
from greybox.control.references import Reference, filtered_random_reference
from greybox.control.tuning import default_bandwidth_hz, pole_placement_gains
from greybox.errors import GreyboxError
from greybox.friction import CoulombModel, GMSModel, LuGreModel
from greybox.twin.plant import default_plant_parameters, maxwell_slip_kernel


# ------------------------------------------------------------------ plain-Python references
def python_pid(memory, s, error, feedforward):
    derivative = s.derivative_decay * memory[1] + s.derivative_gain * (error - memory[2])
    demand = feedforward + s.kp * error + memory[0] + derivative
    current = min(max(demand, -s.current_limit_A), s.current_limit_A)
    if not ((demand > s.current_limit_A and error > 0) or (demand < -s.current_limit_A and error < 0)):
        memory[0] += s.ki_dt * error
    memory[1], memory[2] = derivative, error
    return current


def python_measure(x, resolution):
    return float(np.round(x / resolution) * resolution) if resolution > 0 else x


def python_loop(reference, feedforward, disturbance, s, periods, stride, step, friction_of, advance):
    """Generic plain-Python closed loop; ``friction_of(x, v)`` and ``advance(x, v, dx)`` hold the plant state."""
    n = reference.shape[0]
    out = np.empty((4, n))
    x, v = reference[0, 0], 0.0
    memory = [0.0, 0.0, reference[0, 0] - python_measure(x, s.resolution_mm)]
    for k in range(n):
        out[0, k], out[2, k] = x, friction_of(x, v)
        total, saturated = 0.0, 0
        for j in range(periods):
            t = j * s.period_s
            target = reference[k, 0] + t * (reference[k, 1] + 0.5 * t * reference[k, 2])
            current = python_pid(memory, s, target - python_measure(x, s.resolution_mm), feedforward[k])
            total += current
            saturated += abs(current) >= s.current_limit_A
            for _ in range(stride):
                v += step * (current + disturbance[k] - friction_of(x, v)) / advance.inertia
                x += step * v
                advance(v, step * v)
        out[1, k], out[3, k] = total / periods, saturated / periods
    return out


class PythonTwin:
    def __init__(self, p, step):
        self.p, self.inertia = p, p.inertia_A_s2_mm
        self.k = list(p.stiffness_A_mm)
        self.D = list(p.breakaway_deflection_mm)
        self.d = [0.0] * len(self.k)
        self.level, self.elastic = 1.0, 0.0
        self.decay = math.exp(-step / p.lag_time_s)

    def friction(self, x, v):
        p = self.p
        u = (2 * x - p.travel_mm[0] - p.travel_mm[1]) / (p.travel_mm[1] - p.travel_mm[0])
        g = 1 + p.preload_gain * u**4 + p.lead_gain * math.sin(2 * math.pi * x / p.lead_mm + p.lead_phase_rad)
        return g * self.elastic + p.viscous_A_s_mm * v

    def __call__(self, v, dx):
        p = self.p
        target = p.coulomb_ratio + (1 - p.coulomb_ratio) * math.exp(-((abs(v) / p.stribeck_velocity_mm_s)
                                                                         ** p.stribeck_shape))
        self.level = target + (self.level - target) * self.decay
        self.elastic = 0.0
        for j in range(len(self.d)):
            self.d[j] = min(max(self.d[j] + dx, -self.D[j] * self.level), self.D[j] * self.level)
            self.elastic += self.k[j] * self.d[j]


class PythonGMS:
    """GMS element law written out from docs/friction-models.md (stick until |z| = alpha s(v), then slip)."""

    def __init__(self, m, step):
        self.m, self.inertia, self.step = m, m.J_, step
        self.z = [0.0] * len(m.alpha_)
        self.slipping = [0] * len(m.alpha_)
        self.rate = 0.0

    def friction(self, x, v):
        m = self.m
        return m.mu_ * v + m.sigma_ * self.rate + sum(k * z for k, z in zip(m.k_, self.z))

    def __call__(self, v, dx):
        m, h = self.m, self.step
        s = m.s_inf_ + (m.s0_ - m.s_inf_) * math.exp(-abs(v) / m.v_s_)
        d = int(v > 0) - int(v < 0)
        self.rate = 0.0
        for i, a in enumerate(m.alpha_):
            z = self.z[i]
            if self.slipping[i] != d:
                self.slipping[i] = 0
            if self.slipping[i] == 0:
                new = z + v * h
                if d != 0 and d * new >= a * s:
                    self.slipping[i] = d
                    new = d * a * s if d * z < a * s else z + m.C_ * h * (a * d - z / s)
            else:
                new = z + m.C_ * h * (a * d - z / s)
            self.rate += a * (new - z) / h
            self.z[i] = new


class PythonLuGre:
    def __init__(self, m, step):
        self.m, self.inertia, self.step = m, m.J_, step
        self.z, self.rate = 0.0, 0.0

    def friction(self, x, v):
        m = self.m
        return m.sigma0_ * self.z + m.sigma1_ * self.rate + m.viscous_ * v

    def __call__(self, v, dx):
        m, h = self.m, self.step
        g = m.coulomb_ + (m.static_ - m.coulomb_) * math.exp(-abs(v) / m.v_s_)
        lam = m.sigma0_ * abs(v) / g
        new = self.z * math.exp(-lam * h) + v * (1 - math.exp(-lam * h)) / lam if lam > 0 else self.z + v * h
        self.rate = (new - self.z) / h
        self.z = new


# ------------------------------------------------------------------ fixtures
def _reference(stroke=0.05, duration=0.3, start=-250.0):
    return filtered_random_reference(stroke, duration, 4, cutoff_hz=5.0, start_mm=start, name="test")


def _settings(inertia, reference, limit=10.0, resolution=1e-4):
    periods = controller_periods(reference.sample_time)
    period = reference.sample_time / periods
    gains = pole_placement_gains(inertia, default_bandwidth_hz(period))
    return ControllerSettings.from_gains(gains, period, limit, resolution), periods


def _motion(reference):
    return np.column_stack((reference.position, reference.velocity, reference.acceleration))


def _inputs(reference, seed=0):
    rng = np.random.default_rng(seed)
    return rng.normal(0.0, 0.3, len(reference)), rng.normal(0.0, 0.05, len(reference))


@pytest.fixture(scope="module")
def fitted_dynamic_models(tiny_twin_runs):
    return (GMSModel(n_starts=1, max_iter=60).fit(tiny_twin_runs),
            LuGreModel(n_starts=1, max_iter=60).fit(tiny_twin_runs))


@pytest.fixture(scope="module")
def tiny_twin_runs():
    from greybox.data.prepare import prepare
    from greybox.twin import make_dataset

    return prepare([make_dataset("X", "A", seed=3, duration_s=6.0), make_dataset("X", "P", seed=3, duration_s=6.0)])


# ------------------------------------------------------------------ element update = the twin's kernel
def test_maxwell_slip_update_reproduces_the_twin_kernel():
    p = default_plant_parameters("X")
    step = p.internal_step_s
    t = np.arange(4001) * step
    x = 0.03 * np.sin(2 * np.pi * 3.0 * t) + 0.01 * np.sin(2 * np.pi * 17.0 * t) + 2.0 * t
    v = np.gradient(x, step)
    args = (p.stiffness_A_mm, np.asarray(p.breakaway_deflection_mm), p.coulomb_ratio, p.stribeck_velocity_mm_s,
            p.stribeck_shape, p.lag_time_s)
    expected = maxwell_slip_kernel(x, v, step, 1, *args)
    state = np.zeros(len(p.breakaway_A))
    level = stribeck_ratio(v[0], p.coulomb_ratio, p.stribeck_velocity_mm_s, p.stribeck_shape)
    decay = math.exp(-step / p.lag_time_s)
    got = [0.0]
    for i in range(1, x.size):
        target = stribeck_ratio(v[i], p.coulomb_ratio, p.stribeck_velocity_mm_s, p.stribeck_shape)
        level = target + (level - target) * decay
        got.append(maxwell_slip_update(state, x[i] - x[i - 1], level, p.stiffness_A_mm,
                                       np.asarray(p.breakaway_deflection_mm)))
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)


# ------------------------------------------------------------------ compiled loops = plain Python
def test_twin_loop_kernel_agrees_with_plain_python():
    plant = TwinPlant.for_axis("X")
    reference = _reference()
    settings, periods = _settings(plant.inertia_A_s2_mm, reference)
    feedforward, disturbance = _inputs(reference)
    trace = plant.run(reference, feedforward, disturbance, settings, periods)
    stride = fine_stride(settings.period_s, min(plant.params.internal_step_s, settings.period_s / 4))
    twin = PythonTwin(plant.params, settings.period_s / stride)
    expected = python_loop(_motion(reference), feedforward, disturbance, settings, periods, stride,
                           settings.period_s / stride, twin.friction, twin)
    for got, want in zip(trace, expected):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    assert np.ptp(trace.friction_A) > 0.5  # the run went through stick and slip


@pytest.mark.parametrize("which", ["gms", "lugre"])
def test_model_loop_kernels_agree_with_plain_python(fitted_dynamic_models, which):
    model = fitted_dynamic_models[0 if which == "gms" else 1]
    plant = ModelPlant(model)
    reference = _reference()
    settings, periods = _settings(plant.inertia_A_s2_mm, reference)
    feedforward, disturbance = _inputs(reference)
    trace = plant.run(reference, feedforward, disturbance, settings, periods)
    _, _, stable = plant._arguments()
    stride = fine_stride(settings.period_s, min(plant.max_step_s, stable, settings.period_s / 4))
    python_plant = (PythonGMS if which == "gms" else PythonLuGre)(model, settings.period_s / stride)
    assert model.offset_ == 0.0  # the plain-Python loop has no constant load
    expected = python_loop(_motion(reference), feedforward, disturbance, settings, periods, stride,
                           settings.period_s / stride, python_plant.friction, python_plant)
    for got, want in zip(trace, expected):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    assert np.ptp(trace.friction_A) > 0.5  # the run went through stick and slip


# ------------------------------------------------------------------ physics in closed loop
def _ramp(speed, duration=1.0, start=-250.0, step=0.002):
    t = np.arange(int(round(duration / step)) + 1) * step
    # the speed rises from 0 along a quintic smoothstep over 0.1 s, then stays constant
    tau = np.clip(t / 0.1, 0.0, 1.0)
    shape = np.where(t < 0.1, 0.1 * (2.5 * tau**4 - 3.0 * tau**5 + tau**6), t - 0.05)
    position = start + speed * shape
    velocity = np.gradient(position, step, edge_order=2)
    return Reference("ramp", t, position, velocity, np.gradient(velocity, step, edge_order=2))


@pytest.mark.parametrize("speed", [-20.0, 8.0])
def test_twin_plant_slides_with_its_steady_friction(speed):
    plant = TwinPlant.for_axis("X")
    result = simulate_loop(plant, _ramp(speed), resolution_mm=0.0)
    late = result.reference.time > 0.6
    expected = plant.params.steady_friction(speed, result.position_mm[late])
    np.testing.assert_allclose(result.plant_friction_A[late], expected, rtol=2e-3)
    # the loop's current carries the friction in steady sliding (its acceleration is zero)
    np.testing.assert_allclose(result.current_A[late], expected, rtol=5e-3)


@pytest.mark.parametrize("which", ["gms", "lugre"])
def test_model_plants_slide_with_their_steady_friction(fitted_dynamic_models, which):
    model = fitted_dynamic_models[0 if which == "gms" else 1]
    speed = -12.0
    result = simulate_loop(ModelPlant(model), _ramp(speed), resolution_mm=0.0)
    late = result.reference.time > 0.6
    if which == "gms":
        s = model.s_inf_ + (model.s0_ - model.s_inf_) * np.exp(-abs(speed) / model.v_s_)
        expected = -np.sum(model.k_ * model.alpha_) * s + model.mu_ * speed
    else:
        g = model.coulomb_ + (model.static_ - model.coulomb_) * np.exp(-abs(speed) / model.v_s_)
        expected = -g + model.viscous_ * speed
    np.testing.assert_allclose(result.plant_friction_A[late], expected, rtol=5e-3)


def test_model_plant_refuses_static_models(tiny_twin_runs):
    with pytest.raises(GreyboxError, match="cannot serve as the plant"):
        ModelPlant(CoulombModel().fit(tiny_twin_runs))


def test_fine_stride_is_the_fewest_steps_below_the_limit():
    assert fine_stride(0.002, 0.25e-3) == 8
    assert fine_stride(0.002, 0.3e-3) == 7
    assert fine_stride(0.25e-3, 1.0) == 1
