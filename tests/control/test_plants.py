"""Closed-loop plants: the one compiled loop kernel against a plain-Python loop, and steady-sliding physics."""

from __future__ import annotations

import numba
import numpy as np
import plant_reference as ref
import pytest

from greybox.control.loop import controller_periods, simulate_loop
from greybox.control.pid import ControllerSettings
from greybox.control.plants import ModelPlant, TwinPlant, compiled_position_loop, fine_stride
from greybox.control.references import Reference, filtered_random_reference
from greybox.control.tuning import default_bandwidth_hz, pole_placement_gains
from greybox.errors import GreyboxError
from greybox.models.friction import CoulombModel, GMSModel, LuGreModel, StribeckModel


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


def _fixed_model(which, offset=0.0, inertia=2.8e-4):
    """A GMS or LuGre model with given parameters (as if fitted)."""
    if which == "gms":
        model = GMSModel()
        model.alpha_, model.k_ = np.array([0.1, 0.2, 0.3, 0.4]), np.array([30.0, 60.0, 20.0, 10.0])
        model.slip_rate_, model.sigma_, model.s_0_ = 0.8, 0.02, 0.012
        model.s_inf_, model.v_s_, model.viscous_ = 0.008, 3.0, 0.006
        model.n_evaluations_ = 0
    else:
        model = LuGreModel()
        model.sigma0_, model.sigma1_, model.viscous_ = 150.0, 0.3, 0.006
        model.coulomb_, model.static_, model.v_s_ = 0.9, 1.25, 3.0
    model.J_, model.offset_, model.effort_unit_, model.cost_ = inertia, offset, "A", 0.0
    return model


@pytest.fixture(scope="module")
def fitted_dynamic_models(tiny_twin_runs):
    return (GMSModel(n_starts=1, max_iter=60).fit(tiny_twin_runs),
            LuGreModel(n_starts=1, max_iter=60).fit(tiny_twin_runs))


@pytest.fixture(scope="module")
def tiny_twin_runs():
    from greybox.data.prepare import prepare
    from greybox.twin import make_dataset

    return prepare([make_dataset("X", "A", seed=3, duration_s=6.0), make_dataset("X", "P", seed=3, duration_s=6.0)])


# ------------------------------------------------------------------ compiled loop = plain Python
def test_twin_loop_agrees_with_plain_python():
    plant = TwinPlant.for_axis("X")
    reference = _reference()
    settings, periods = _settings(plant.inertia_A_s2_mm, reference)
    feedforward, disturbance = _inputs(reference)
    trace = plant.run(reference, feedforward, disturbance, settings, periods)
    stride = fine_stride(settings.period_s, min(plant.params.internal_step_s, settings.period_s / 4))
    expected = ref.python_loop(_motion(reference), feedforward, disturbance, settings, periods, stride,
                               settings.period_s / stride, ref.TwinPlant(plant.params), plant.inertia_A_s2_mm)
    for got, want in zip(trace, expected):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    assert np.ptp(trace.friction_A) > 0.5  # the run went through stick and slip


@pytest.mark.parametrize("which", ["gms", "lugre"])
def test_model_loops_agree_with_plain_python(fitted_dynamic_models, which):
    model = fitted_dynamic_models[0 if which == "gms" else 1]
    plant = ModelPlant(model)
    reference = _reference()
    settings, periods = _settings(plant.inertia_A_s2_mm, reference)
    feedforward, disturbance = _inputs(reference)
    trace = plant.run(reference, feedforward, disturbance, settings, periods)
    stride = fine_stride(settings.period_s, min(plant.max_step_s, plant.law.stable_step_s, settings.period_s / 4))
    python_plant = (ref.GMSPlant if which == "gms" else ref.LuGrePlant).of(model)
    expected = ref.python_loop(_motion(reference), feedforward, disturbance, settings, periods, stride,
                               settings.period_s / stride, python_plant, model.J_, model.offset_)
    for got, want in zip(trace, expected):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    assert np.ptp(trace.friction_A) > 0.5  # the run went through stick and slip


@pytest.mark.parametrize("which", ["gms", "lugre"])
def test_the_offset_is_a_constant_load(which):
    """A model's offset pushes the axis like a constant current: the loop with offset I_0 and
    disturbance d equals the loop without offset and disturbance d - I_0."""
    model = _fixed_model(which, offset=0.15)
    reference = _reference()
    plant = ModelPlant(model)
    settings, periods = _settings(plant.inertia_A_s2_mm, reference)
    feedforward, disturbance = _inputs(reference)
    loaded = plant.run(reference, feedforward, disturbance, settings, periods)
    unloaded = ModelPlant(_fixed_model(which, offset=0.0)).run(reference, feedforward, disturbance - 0.15, settings,
                                                               periods)
    for got, want in zip(loaded, unloaded):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    stride = fine_stride(settings.period_s, min(plant.max_step_s, plant.law.stable_step_s, settings.period_s / 4))
    python_plant = (ref.GMSPlant if which == "gms" else ref.LuGrePlant).of(model)
    expected = ref.python_loop(_motion(reference), feedforward, disturbance, settings, periods, stride,
                               settings.period_s / stride, python_plant, model.J_, model.offset_)
    for got, want in zip(loaded, expected):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    free = ModelPlant(_fixed_model(which)).run(reference, feedforward, disturbance, settings, periods)
    late = slice(len(reference) // 2, None)  # the integrator has taken up the load
    assert np.mean(loaded.current_A[late] - free.current_A[late]) == pytest.approx(0.15, abs=0.02)


def test_one_compiled_loop_serves_every_law(fitted_dynamic_models):
    """The loop is compiled once for all plant laws (first-class function arguments), not once per law."""
    reference = _reference(duration=0.05)
    for plant in (TwinPlant.for_axis("X"), TwinPlant.for_axis("Y", friction=False),
                  ModelPlant(fitted_dynamic_models[0]), ModelPlant(fitted_dynamic_models[1])):
        simulate_loop(plant, reference)
    loop = compiled_position_loop()
    if numba.config.DISABLE_JIT:  # the no-JIT run (tests/test_without_jit.py): plain Python, nothing compiled
        assert not hasattr(loop, "signatures")
    else:
        assert len(loop.signatures) == 1


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
    """In steady sliding the twin's load is its steady friction plus the cogging current of the position.

    The cogging current (period 10/24 mm: 19-48 Hz at these speeds) makes the velocity ripple a little,
    so the loop's current equals friction plus cogging only on average (J a averages out); without
    cogging the axis slides at constant velocity and its current is the friction sample by sample.
    """
    plant = TwinPlant.for_axis("X")
    result = simulate_loop(plant, _ramp(speed), resolution_mm=0.0)
    late = result.reference.time > 0.6
    position = result.position_mm[late]
    cogging = plant.params.cogging_current(position)
    assert np.ptp(cogging) > 1.5 * plant.params.cogging_A  # the run went over whole cogging periods
    expected = plant.params.steady_friction(speed, position) + cogging
    np.testing.assert_allclose(result.plant_friction_A[late], expected, rtol=2e-3)
    assert np.mean(result.current_A[late]) == pytest.approx(np.mean(expected), rel=1e-3)

    flat = TwinPlant(plant.params.replace(cogging_A=0.0))
    result = simulate_loop(flat, _ramp(speed), resolution_mm=0.0)
    expected = flat.params.steady_friction(speed, result.position_mm[late])
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
        s = model.s_inf_ + (model.s_0_ - model.s_inf_) * np.exp(-abs(speed) / model.v_s_)
        expected = -np.sum(model.k_ * model.alpha_) * s + model.viscous_ * speed
    else:
        g = model.coulomb_ + (model.static_ - model.coulomb_) * np.exp(-abs(speed) / model.v_s_)
        expected = -g + model.viscous_ * speed
    np.testing.assert_allclose(result.plant_friction_A[late], expected, rtol=5e-3)


@pytest.mark.parametrize("model", [CoulombModel, StribeckModel])
def test_model_plant_refuses_models_without_a_plant_law(tiny_twin_runs, model):
    with pytest.raises(GreyboxError, match=r"^a \w+ model cannot serve as the plant: .*use twin-X, twin-Y or a gms"):
        ModelPlant(model().fit(tiny_twin_runs))


def test_model_plant_refuses_a_non_positive_inertia():
    with pytest.raises(GreyboxError, match="a plant needs J > 0"):
        ModelPlant(_fixed_model("gms", inertia=0.0))


def test_fine_stride_is_the_fewest_steps_below_the_limit():
    assert fine_stride(0.002, 0.25e-3) == 8
    assert fine_stride(0.002, 0.3e-3) == 7
    assert fine_stride(0.25e-3, 1.0) == 1
