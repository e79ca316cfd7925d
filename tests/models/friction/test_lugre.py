"""LuGre model: exact zero-order-hold step, stiff bristles at 2 ms, identification."""

from __future__ import annotations

import numpy as np
import plant_reference as ref
import pytest
from friction_reference import lugre_reference
from friction_signals import STEP, motion_log, velocity_profile
from scipy.integrate import solve_ivp

from greybox.control.loop import controller_periods
from greybox.control.pid import ControllerSettings
from greybox.control.plants import ModelPlant, fine_stride
from greybox.control.references import filtered_random_reference
from greybox.control.tuning import default_bandwidth_hz, pole_placement_gains
from greybox.errors import LogError, ParameterError
from greybox.models.files import load_model, save_model
from greybox.models.friction import LuGreModel, stribeck_curve
from greybox.models.friction.lugre import check_lugre_parameters, simulate_lugre

PARAMS = {"sigma1": 0.02, "sigma2": 0.004, "coulomb": 0.6, "static": 0.9, "v_s": 3.0}


def fine_reference(velocity, sigma0):
    """Bristle deflection at the sample times from an implicit (Radau) solver, velocity held over each step."""
    g = stribeck_curve(velocity, PARAMS["static"], PARAMS["coulomb"], PARAMS["v_s"])
    z, out = 0.0, []
    for v, g_v in zip(velocity, g):
        out.append(z)
        lam = sigma0 * abs(v) / g_v
        sol = solve_ivp(lambda t, y, v=v, lam=lam: v - lam * y, (0.0, STEP), [z], method="Radau", rtol=1e-11,
                        atol=1e-15, jac=lambda t, y, lam=lam: [[-lam]])
        z = sol.y[0, -1]
    return np.array(out)


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_stiff_bristles_at_2ms_match_a_fine_implicit_reference():
    sigma0 = 1e3  # A/mm: sigma0 |v| T / g reaches ~300, far beyond forward Euler's limit of 2
    t = np.arange(150) * STEP
    velocity = 80.0 * np.sin(2 * np.pi * 5.0 * t) + 2.0  # two reversals
    _, z, _ = simulate_lugre(velocity, STEP, sigma0=sigma0, **PARAMS)
    reference = fine_reference(velocity, sigma0)
    np.testing.assert_allclose(z, reference, rtol=0, atol=1e-8 * np.max(np.abs(reference)))
    assert np.max(sigma0 * np.abs(velocity) / PARAMS["coulomb"] * STEP) > 100


def test_stiff_bristles_stay_bounded_where_forward_euler_diverges():
    sigma0 = 1e5
    velocity = velocity_profile(20.0, seed=5)
    friction, z, _ = simulate_lugre(velocity, STEP, sigma0=sigma0, **PARAMS)
    # the deflection never exceeds the static level over the stiffness (the bristle's steady state)
    assert np.max(np.abs(z)) <= PARAMS["static"] / sigma0 * (1 + 1e-9)
    assert np.all(np.isfinite(friction))
    # forward Euler with the same step: z <- z + T (v - lambda z) blows up
    g = stribeck_curve(velocity, PARAMS["static"], PARAMS["coulomb"], PARAMS["v_s"])
    z_euler = 0.0
    with np.errstate(over="ignore", invalid="ignore"):
        for v, g_v in zip(velocity[:2000], g[:2000]):
            z_euler = z_euler + STEP * (v - sigma0 * abs(v) / g_v * z_euler)
    assert not abs(z_euler) < 1e3 * PARAMS["static"] / sigma0


@pytest.mark.parametrize("speed", [-50.0, -2.0, 0.5, 10.0, 120.0])
def test_steady_sliding_is_the_stribeck_curve_plus_viscous(speed):
    velocity = np.concatenate((np.full(50, -speed), np.full(2000, speed)))
    friction, _, _ = simulate_lugre(velocity, STEP, sigma0=200.0, **PARAMS)
    expected = np.sign(speed) * stribeck_curve(speed, PARAMS["static"], PARAMS["coulomb"], PARAMS["v_s"]) \
        + PARAMS["sigma2"] * speed
    assert friction[-1] == pytest.approx(expected, rel=1e-10)


def test_odd_symmetry():
    velocity = velocity_profile(5.0, seed=2)
    friction, _, _ = simulate_lugre(velocity, STEP, sigma0=500.0, **PARAMS)
    mirrored, _, _ = simulate_lugre(-velocity, STEP, sigma0=500.0, **PARAMS)
    np.testing.assert_array_equal(mirrored, -friction)


def test_parameter_validation():
    with pytest.raises(ParameterError, match="sigma0"):
        check_lugre_parameters(0.0, 0.0, 0.6, 0.9, 3.0)
    with pytest.raises(ParameterError, match="sigma1"):
        check_lugre_parameters(100.0, -1.0, 0.6, 0.9, 3.0)
    with pytest.raises(ParameterError, match="Coulomb"):
        check_lugre_parameters(100.0, 0.0, -0.6, 0.9, 3.0)


def test_identification_recovers_the_parameters_from_noise_free_data():
    velocity = velocity_profile(20.0, seed=9)
    log = motion_log(velocity)
    friction, _, _ = simulate_lugre(velocity, STEP, sigma0=60.0, **PARAMS)
    log = log.replace(effort=0.001 * log.acceleration + friction)
    model = LuGreModel(n_starts=2).fit(log)
    assert model.coulomb_ == pytest.approx(PARAMS["coulomb"], rel=1e-3)
    assert model.static_ == pytest.approx(PARAMS["static"], rel=1e-3)
    assert model.v_s_ == pytest.approx(PARAMS["v_s"], rel=1e-2)
    assert model.viscous_ == pytest.approx(PARAMS["sigma2"], rel=1e-3)
    assert model.J_ == pytest.approx(0.001, rel=1e-3)
    assert model.sigma0_ == pytest.approx(60.0, rel=0.05)
    residual = model.predict(log) - log.effort
    assert np.sqrt(np.mean(residual ** 2)) < 1e-3 * np.std(log.effort)
    assert model.n_params == 7


# ------------------------------------------------------------------ direction-dependent Stribeck curve and viscous term
#: Asymmetric law: ``(positive motion, negative motion)`` for the viscous coefficient and the Stribeck curve.
ASYM = {"sigma1": 0.02, "sigma2": (0.004, 0.007), "coulomb": (0.6, 0.42), "static": (0.9, 0.75), "v_s": (3.0, 6.0)}


def asym_level(v):
    """Steady sliding friction ``sgn(v) g(v) + sigma2(v) v`` of ASYM at a velocity [mm/s] (non-zero) [A]."""
    d = 0 if v > 0 else 1
    g = stribeck_curve(v, ASYM["static"][d], ASYM["coulomb"][d], ASYM["v_s"][d])
    return np.sign(v) * g + ASYM["sigma2"][d] * v


def swapped(params):
    """The law with the roles of positive and negative motion exchanged."""
    return {key: value[::-1] if isinstance(value, tuple) else value for key, value in params.items()}


def asym_log(duration=20.0, seed=9, sigma0=60.0, inertia=0.001):
    velocity = velocity_profile(duration, seed=seed)
    log = motion_log(velocity)
    friction, _, _ = simulate_lugre(velocity, STEP, sigma0=sigma0, **ASYM)
    return log.replace(effort=inertia * log.acceleration + friction)


def asymmetric_model(**overrides):
    """An asymmetric LuGreModel holding ASYM (as if fitted)."""
    model = LuGreModel(asymmetric=True)
    model.sigma0_, model.sigma1_ = 150.0, ASYM["sigma1"]
    model.viscous_, model.viscous_neg_ = ASYM["sigma2"]
    model.coulomb_, model.coulomb_neg_ = ASYM["coulomb"]
    model.static_, model.static_neg_ = ASYM["static"]
    model.v_s_, model.v_s_neg_ = ASYM["v_s"]
    model.J_, model.offset_, model.effort_unit_, model.cost_, model.sample_time_ = 2.8e-4, 0.0, "A", 0.0, STEP
    for name, value in overrides.items():
        setattr(model, name, value)
    return model


def test_asymmetric_kernel_matches_python_reference():
    velocity = velocity_profile(12.0, seed=4)
    assert velocity.max() > 10.0 and velocity.min() < -10.0 and np.any(velocity == 0.0)
    friction, z, z_end = simulate_lugre(velocity, STEP, sigma0=300.0, **ASYM)
    ref, ref_z, ref_z_end = lugre_reference(velocity, STEP, 300.0, ASYM["sigma1"], ASYM["sigma2"], ASYM["coulomb"],
                                            ASYM["static"], ASYM["v_s"])
    np.testing.assert_allclose(friction, ref, rtol=0, atol=1e-10 * np.max(np.abs(ref)))
    np.testing.assert_allclose(z, ref_z, rtol=0, atol=1e-12 * np.max(np.abs(ref_z)))
    assert z_end == pytest.approx(ref_z_end, abs=1e-12 * np.max(np.abs(ref_z)))
    # the reference itself distinguishes the directions: with the positive curve for both it differs
    positive_only = {key: value[0] if isinstance(value, tuple) else value for key, value in ASYM.items()}
    symmetric, _, _ = simulate_lugre(velocity, STEP, sigma0=300.0, **positive_only)
    assert np.max(np.abs(symmetric - friction)) > 0.1


def test_equal_directions_give_the_symmetric_result_exactly():
    velocity = velocity_profile(8.0, seed=4)
    pairs = {key: (value, value) for key, value in PARAMS.items() if key != "sigma1"}
    got = simulate_lugre(velocity, STEP, sigma0=400.0, sigma1=PARAMS["sigma1"], **pairs, z0=1e-4)
    want = simulate_lugre(velocity, STEP, sigma0=400.0, **PARAMS, z0=1e-4)
    for a, b in zip(got, want):
        np.testing.assert_array_equal(a, b)
    # a model whose negative-motion parameters equal the positive ones predicts as the symmetric model
    symmetric = asymmetric_model(asymmetric=False)
    for name in ("coulomb_neg_", "static_neg_", "v_s_neg_", "viscous_neg_"):
        delattr(symmetric, name)
    equal = asymmetric_model(coulomb_neg_=0.6, static_neg_=0.9, v_s_neg_=3.0, viscous_neg_=0.004)
    log = motion_log(velocity)
    np.testing.assert_array_equal(equal.predict(log), symmetric.predict(log))
    np.testing.assert_array_equal(equal.plant_law().parameters, symmetric.plant_law().parameters)


def test_mirrored_motion_with_exchanged_directions_gives_the_opposite_friction():
    """F(-v history) with the directions' parameters exchanged is exactly -F(v history)."""
    velocity = velocity_profile(5.0, seed=2)
    friction, z, z_end = simulate_lugre(velocity, STEP, sigma0=500.0, **ASYM)
    mirrored, z_mirrored, z_end_mirrored = simulate_lugre(-velocity, STEP, sigma0=500.0, **swapped(ASYM))
    np.testing.assert_array_equal(mirrored, -friction)
    np.testing.assert_array_equal(z_mirrored, -z)
    assert z_end_mirrored == -z_end
    # without the exchange the mirrored motion does not mirror the friction: the law is asymmetric
    unswapped, _, _ = simulate_lugre(-velocity, STEP, sigma0=500.0, **ASYM)
    assert np.max(np.abs(unswapped + friction)) > 0.1


@pytest.mark.parametrize("speed", [-120.0, -10.0, -2.0, -0.5, 0.5, 2.0, 10.0, 120.0])
def test_asymmetric_steady_sliding_is_each_directions_curve_plus_viscous(speed):
    velocity = np.concatenate((np.full(50, -speed), np.full(2000, speed)))
    friction, _, _ = simulate_lugre(velocity, STEP, sigma0=200.0, **ASYM)
    assert friction[-1] == pytest.approx(asym_level(speed), rel=1e-10)
    d = 0 if speed > 0 else 1
    assert abs(friction[-1]) > ASYM["coulomb"][d] and abs(friction[-1]) < ASYM["static"][d] + ASYM["sigma2"][d] * 120


def test_bristle_deflection_stays_bounded_over_200_reversals():
    """|z| <= max g / sigma0 over 100 periods (200 reversals) of a biased sine, and the cycle repeats (no drift)."""
    sigma0 = 1e4  # stiff: sigma0 |v| T / g up to ~2000
    period = 100  # samples
    t = np.arange(100 * period) * STEP
    velocity = 40.0 * np.sin(2 * np.pi * t / (period * STEP)) + 5.0
    friction, z, z_end = simulate_lugre(velocity, STEP, sigma0=sigma0, **ASYM)
    assert np.count_nonzero(np.diff(np.sign(velocity)) != 0) == 200
    bound = max(ASYM["static"] + ASYM["coulomb"]) / sigma0
    assert np.max(np.abs(np.append(z, z_end))) <= bound * (1 + 1e-12)
    assert np.max(z) > 0.6 / sigma0 * 0.99 and np.min(z) < -0.42 / sigma0 * 0.99  # each direction's level reached
    np.testing.assert_allclose(z[-period:], z[-2 * period:-period], rtol=0, atol=1e-9 * bound)
    np.testing.assert_allclose(friction[-period:], friction[10 * period:11 * period], rtol=0, atol=1e-9)


def cycle_work(velocity, z, z_end):
    """Work [A mm] of the friction of ASYM over each step, exact for the velocity held over the step.

    With ``dz/dt = v - lambda z`` the integral of ``z`` over a step is ``(v T - dz) / lambda``, so the
    work ``v T sigma2 v + v (sigma0 int z + sigma1 dz)`` needs only the deflections at the sample times.
    """
    dz = np.diff(np.append(z, z_end))
    d = (velocity < 0).astype(int)
    g = np.array([stribeck_curve(v, ASYM["static"][k], ASYM["coulomb"][k], ASYM["v_s"][k])
                  for v, k in zip(velocity, d)])
    sigma2 = np.array(ASYM["sigma2"])[d]
    # sigma0 v / lambda = sgn(v) g(v); nothing moves (and no work is done) at rest
    elastic = np.sign(velocity) * g * (velocity * STEP - dz)
    return elastic + ASYM["sigma1"] * velocity * dz + sigma2 * velocity ** 2 * STEP


@pytest.mark.parametrize("amplitude", [0.0005, 0.003, 0.02, 0.5])
def test_energy_dissipated_over_closed_position_cycles_is_non_negative(amplitude):
    """From steady state, the friction does no net work on the axis over a closed cycle: it only dissipates.

    sigma1 |v| <= 4 g(v) holds (|v| < 13 mm/s here), the condition under which the LuGre law is dissipative.
    """
    sigma0 = 200.0
    period = 250  # samples: 0.5 s
    k = np.arange(20 * period)
    velocity = amplitude * 2 * np.pi / (period * STEP) * np.sin(2 * np.pi * k / period)  # x = A (1 - cos)
    _, z, z_end = simulate_lugre(velocity, STEP, sigma0=sigma0, **ASYM)
    work = cycle_work(velocity, z, z_end)
    per_cycle = work.reshape(-1, period).sum(axis=1)[5:]
    assert np.all(per_cycle >= 0.0)
    assert per_cycle[-1] == pytest.approx(per_cycle[-2], rel=1e-3)  # steady state (slowest in pre-sliding)
    # the exact work is the integral of the model's friction over the travel: the sum of F v h over the last
    # cycle at a 20 times finer step (the same held velocities; the exact step composes exactly)
    fine, _, _ = simulate_lugre(np.repeat(velocity, 20), STEP / 20, sigma0=sigma0, **ASYM)
    sampled = np.sum((fine * np.repeat(velocity, 20))[-20 * period:]) * STEP / 20
    assert per_cycle[-1] == pytest.approx(sampled, rel=0.05)
    if amplitude >= 0.02:  # sliding: about (F_c+ + F_c-) per unit travel, twice the amplitude each way
        assert per_cycle[-1] > 2 * amplitude * sum(ASYM["coulomb"])


def test_identification_recovers_asymmetric_levels_from_noise_free_data():
    log = asym_log()
    model = LuGreModel(asymmetric=True, n_starts=2).fit(log)
    for speed in (-80.0, -20.0, -5.0, -1.0, 1.0, 5.0, 20.0, 80.0):
        sliding = model.predict(motion_log(np.full(1500, speed)))  # constant speed: no inertial current
        assert sliding[-1] == pytest.approx(asym_level(speed), rel=0.02)
    assert (model.coulomb_, model.coulomb_neg_) == pytest.approx(ASYM["coulomb"], rel=0.02)
    assert (model.static_, model.static_neg_) == pytest.approx(ASYM["static"], rel=0.02)
    assert (model.viscous_, model.viscous_neg_) == pytest.approx(ASYM["sigma2"], rel=0.02)
    assert model.J_ == pytest.approx(0.001, rel=0.02)
    assert model.n_params == 11
    residual = model.predict(log) - log.effort
    assert np.sqrt(np.mean(residual ** 2)) < 1e-3 * np.std(log.effort)
    # the symmetric model cannot: one level for both directions
    symmetric = LuGreModel(n_starts=2).fit(log)
    assert np.sqrt(np.mean((symmetric.predict(log) - log.effort) ** 2)) > 10 * np.sqrt(np.mean(residual ** 2))


def test_asymmetric_model_file_round_trip_predicts_identically(tmp_path):
    log = asym_log(duration=6.0, seed=5)
    model = LuGreModel(asymmetric=True, n_starts=1, max_iter=60).fit(log)
    loaded = load_model(save_model(model, tmp_path / "lugre.gbm"))
    assert loaded.asymmetric is True
    assert {name: getattr(loaded, name) for name in vars(model) if name.endswith("_")} == \
        {name: value for name, value in vars(model).items() if name.endswith("_")}
    other = motion_log(velocity_profile(3.0, seed=11))
    np.testing.assert_array_equal(loaded.predict(other), model.predict(other))
    # a symmetric model learns no negative-motion attributes: its files are those written before the asymmetric model
    symmetric = LuGreModel(n_starts=1, max_iter=20).fit(log)
    assert not [name for name in vars(symmetric) if name.endswith("_neg_")]
    np.testing.assert_array_equal(load_model(save_model(symmetric, tmp_path / "s.gbm")).predict(other),
                                  symmetric.predict(other))


def test_asymmetric_model_parameters_and_linear_part():
    model = asymmetric_model()
    log = motion_log(velocity_profile(4.0, seed=6), effort=np.zeros(2000))
    part = model.linear_part(log)
    assert part.names == ("sigma1", "viscous_pos", "viscous_neg", "J")
    np.testing.assert_array_equal(part.lower, np.zeros(4))
    coefficients = model.linear_coefficients()
    np.testing.assert_array_equal(coefficients, [ASYM["sigma1"], *ASYM["sigma2"], 2.8e-4])
    np.testing.assert_allclose(part.columns @ coefficients + part.fixed, model.predict(log), rtol=0, atol=1e-12)
    model.set_linear_coefficients([0.03, 0.005, 0.009, 3e-4])
    assert (model.sigma1_, model.viscous_, model.viscous_neg_, model.J_) == (0.03, 0.005, 0.009, 3e-4)
    np.testing.assert_allclose(part.columns @ model.linear_coefficients() + part.fixed, model.predict(log),
                               rtol=0, atol=1e-12)
    rows = {row.name: row for row in model.parameter_table()}
    # every learned attribute has its row (the positive direction's under the symmetric model's names)
    assert set(rows) == {"sigma0", "sigma1", "viscous", "viscous_neg", "coulomb", "coulomb_neg", "static",
                         "static_neg", "v_s", "v_s_neg", "J", "offset"}
    assert (rows["coulomb"].value, rows["coulomb_neg"].value) == (0.6, 0.42) and rows["coulomb_neg"].unit == "A"
    assert "negative motion" in rows["coulomb_neg"].description and "positive motion" in rows["v_s"].description
    assert rows["v_s_neg"].unit == "mm/s" and rows["viscous"].unit == "A s/mm"


def test_asymmetric_plant_law_runs_and_follows_the_model():
    model = asymmetric_model()
    law = model.plant_law()
    # at the model's sample time the law's bristle and friction are the model's, in both directions
    velocity = velocity_profile(4.0, seed=8, v_max=40.0)
    state = law.state.copy()
    friction = np.empty(velocity.size)
    for j, v in enumerate(velocity):
        law.advance(law.parameters, state, v, STEP)
        friction[j] = law.friction(law.parameters, state, 0.0, v)
    _, z_end = model.predict_chunk(motion_log(velocity))
    assert state[0] == z_end
    sliding = np.abs(velocity) > 5.0
    np.testing.assert_allclose(friction[sliding], [asym_level(v) for v in velocity[sliding]], rtol=0.05)
    # in a position loop, the compiled law agrees with plain Python
    reference = filtered_random_reference(2.0, 0.6, 4, cutoff_hz=5.0, start_mm=-250.0, name="test")
    plant = ModelPlant(model)
    periods = controller_periods(reference.sample_time)
    period = reference.sample_time / periods
    settings = ControllerSettings.from_gains(pole_placement_gains(plant.inertia_A_s2_mm, default_bandwidth_hz(period)),
                                             period, 10.0, 1e-4)
    rng = np.random.default_rng(0)
    feedforward, disturbance = rng.normal(0.0, 0.3, len(reference)), rng.normal(0.0, 0.05, len(reference))
    trace = plant.run(reference, feedforward, disturbance, settings, periods)
    stride = fine_stride(settings.period_s, min(plant.max_step_s, plant.law.stable_step_s, settings.period_s / 4))
    motion = np.column_stack((reference.position, reference.velocity, reference.acceleration))
    expected = ref.python_loop(motion, feedforward, disturbance, settings, periods, stride,
                               settings.period_s / stride, ref.LuGrePlant.of(model), model.J_, model.offset_)
    for got, want in zip(trace, expected):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    assert trace.friction_A.max() > 0.6 and trace.friction_A.min() < -0.42  # slid both ways


def test_asymmetric_settings_are_checked():
    log = asym_log(duration=2.0)
    with pytest.raises(ParameterError, match="not separately identifiable"):
        LuGreModel(asymmetric=True, fit_offset=True).fit(log)
    with pytest.raises(ParameterError, match="asymmetric must be True or False"):
        LuGreModel(asymmetric="yes").fit(log)
    with pytest.raises(LogError, match="no negative motion"):
        LuGreModel(asymmetric=True).fit(motion_log(np.abs(velocity_profile(2.0, seed=1)) + 0.1))
    with pytest.raises(ParameterError, match="static level"):
        simulate_lugre(np.ones(3), STEP, sigma0=1.0, sigma1=0.0, sigma2=0.0, coulomb=0.5, static=(0.9, -0.9), v_s=1.0)
