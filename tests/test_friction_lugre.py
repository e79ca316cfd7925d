"""LuGre model: exact zero-order-hold step, stiff bristles at 2 ms, identification."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from greybox.errors import ParameterError
from greybox.friction import LuGreModel, stribeck_curve
from greybox.friction.lugre import check_lugre_parameters, simulate_lugre
from greybox.friction.signals import STEP, motion_log, velocity_profile

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
