"""Plant laws (greybox.base.PlantLaw): compiled friction/advance against plain Python, the models' own
element and bristle steps, steady sliding, stable steps, and the shared compiled formulas."""

from __future__ import annotations

import math

import numpy as np
import plant_reference as ref
import pytest
from friction_reference import lugre_step_reference, stribeck_reference
from friction_signals import STEP, velocity_profile

from greybox.base import PlantLaw
from greybox.models.friction import CoulombModel, GMSModel, LuGreModel
from greybox.models.friction.kernels import (
    direction_curves,
    gms_trajectory_kernel,
    lugre_decay_rate,
    lugre_exact_step,
    lugre_trajectory_kernel,
    stribeck_at,
)
from greybox.models.friction.plant_laws import MAX_STEP_RATIO, gms_plant_law, lugre_plant_law, stable_step
from greybox.twin.plant import (
    default_plant_parameters,
    lag_decay,
    lagged_stribeck_ratio,
    maxwell_slip_kernel,
    maxwell_slip_update,
    simulate_plant,
    stribeck_ratio,
    twin_plant_law,
)

FINE = 0.25e-3

GMS = {"alpha": np.array([0.1, 0.2, 0.3, 0.4]), "k": np.array([30.0, 60.0, 20.0, 10.0]), "sigma": 0.02,
       "s_0": 0.012, "s_inf": 0.008, "v_s": 3.0, "c": 3.0, "mu": 0.006}
LUGRE = {"sigma0": 150.0, "sigma1": 0.3, "sigma2": 0.006, "coulomb": 0.9, "static": 1.25, "v_s": 3.0}


def gms_law(inertia=2.8e-4, offset=0.0):
    return gms_plant_law(**GMS, inertia=inertia, offset=offset)


def lugre_law(inertia=2.8e-4, offset=0.0):
    return lugre_plant_law(**LUGRE, inertia=inertia, offset=offset)


def gms_python():
    p = GMS
    return ref.GMSPlant(p["alpha"], p["k"], p["sigma"], p["s_0"], p["s_inf"], p["v_s"], p["c"], p["mu"])


def lugre_python():
    p = LUGRE
    return ref.LuGrePlant(p["sigma0"], p["sigma1"], p["sigma2"], p["coulomb"], p["static"], p["v_s"])


def fine_velocity(duration=3.0, seed=0):
    """Plateaus, reversals, small oscillations and standstills at the fine step [mm/s]."""
    return velocity_profile(duration, seed=seed, step=FINE, v_max=40.0)


def drive(law, python, velocity, step, position=-250.0):
    """Step the compiled law and the plain-Python one along ``velocity``; return both friction sequences."""
    state = law.state.copy()
    compiled, expected = [], []
    x = position
    for v in velocity:
        compiled.append(law.friction(law.parameters, state, x, v))
        expected.append(python.friction(x, v))
        law.advance(law.parameters, state, v, step)
        python.advance(v, step)
        x += step * v
    return np.array(compiled), np.array(expected), state


# ------------------------------------------------------------------ compiled laws = plain Python
@pytest.mark.parametrize("which", ["gms", "lugre", "twin", "twin without friction"])
def test_compiled_laws_agree_with_plain_python(which):
    velocity = fine_velocity(seed=len(which))
    if which == "gms":
        law, python = gms_law(), gms_python()
    elif which == "lugre":
        law, python = lugre_law(), lugre_python()
    else:
        friction = which == "twin"
        law = twin_plant_law(default_plant_parameters("X"), friction=friction)
        python = ref.TwinPlant(default_plant_parameters("X"), friction=friction)
    compiled, expected, _ = drive(law, python, velocity, FINE)
    scale = max(np.max(np.abs(expected)), 1e-300)
    np.testing.assert_allclose(compiled, expected, rtol=0, atol=1e-11 * scale)
    if which == "twin without friction":
        assert np.all(compiled == 0.0)
    else:
        assert compiled.max() > 0.5 * scale and compiled.min() < -0.5 * scale  # slid both ways


def test_gms_law_takes_the_models_element_step():
    """At the model's sample time the law's element states are the run kernel's, bit for bit."""
    velocity = velocity_profile(6.0, seed=4)
    law = gms_law()
    n, N = velocity.size, GMS["alpha"].size
    z_out, mode_out = np.empty((n, N)), np.empty((n, N), dtype=np.int8)
    w_out, f_out = np.empty(n), np.empty(n)
    curves = direction_curves(np.full(2, GMS["s_0"]), np.full(2, GMS["s_inf"]), np.full(2, GMS["v_s"]))
    gms_trajectory_kernel(velocity, STEP, GMS["alpha"], GMS["k"], GMS["sigma"], curves, GMS["c"], np.full(2, GMS["mu"]),
                          np.zeros(N), np.zeros(N, dtype=np.int8), z_out, mode_out, w_out, f_out)
    state = law.state.copy()
    z, mode, rate = np.empty((n, N)), np.empty((n, N)), np.empty(n)
    for j, v in enumerate(velocity):
        z[j], mode[j] = state[1:1 + N], state[1 + N:]
        law.advance(law.parameters, state, v, STEP)
        rate[j] = state[0]
    np.testing.assert_array_equal(z, z_out)
    np.testing.assert_array_equal(mode, mode_out)
    np.testing.assert_allclose(rate, w_out, rtol=1e-12, atol=1e-12 * np.max(np.abs(w_out)))
    assert np.any(mode_out != 0) and np.any(mode_out == 0)


def test_lugre_law_takes_the_models_bristle_step():
    velocity = velocity_profile(6.0, seed=5)
    law = lugre_law()
    z_out, z_dot = np.empty(velocity.size), np.empty(velocity.size)
    curves = direction_curves(np.full(2, LUGRE["static"]), np.full(2, LUGRE["coulomb"]), np.full(2, LUGRE["v_s"]))
    lugre_trajectory_kernel(velocity, STEP, LUGRE["sigma0"], curves, 0.0, z_out, z_dot)
    state = law.state.copy()
    z = np.empty(velocity.size)
    for j, v in enumerate(velocity):
        z[j] = state[0]
        law.advance(law.parameters, state, v, STEP)
    np.testing.assert_array_equal(z, z_out)


def _dyadic_velocity(v, step, bits=40):
    """``v`` nudged so that every displacement ``step * v`` is a multiple of 2^-bits mm, exactly in floating point.

    Summed from a dyadic start (0, -250 mm) such displacements give positions whose differences are the
    displacements again, bit for bit: the prescribed-motion kernel (which steps by ``x[i] - x[i-1]``) and a
    law (which steps by ``h v``) then move their elements by the same amount.
    """
    target = np.round(step * v * 2.0**bits) / 2.0**bits
    out = target / step
    for i in range(out.size):
        while step * out[i] != target[i]:
            out[i] = np.nextafter(out[i], math.inf if step * out[i] < target[i] else -math.inf)
    return out


def test_twin_law_follows_the_twins_prescribed_motion_kernel():
    """Along a prescribed motion the twin's law gives the Maxwell-slip current of maxwell_slip_kernel.

    The kernel steps the elements by the position difference, the law by ``h v``; with a general velocity
    the two displacements differ by the rounding of the summed position (~1e-16 mm), which the stiff
    elements (sum k_i ~ 2600 A/mm) turn into ~1e-12 A. On displacements exact in floating point (dyadic,
    see _dyadic_velocity) both take the same steps, and the currents must agree bit for bit.
    """
    p = default_plant_parameters("X")
    t = np.arange(4001) * FINE
    v = _dyadic_velocity(6.0 * np.cos(2 * np.pi * 3.0 * t) + 2.0 * np.sin(2 * np.pi * 17.0 * t) + 1.0, FINE)
    x = np.concatenate(([0.0], np.cumsum(FINE * v[1:])))
    np.testing.assert_array_equal(np.diff(x), FINE * v[1:])  # the same displacements for kernel and law
    expected = maxwell_slip_kernel(x, v, FINE, 1, p.stiffness_A_mm, np.asarray(p.breakaway_deflection_mm),
                                   p.coulomb_ratio, p.stribeck_velocity_mm_s, p.stribeck_shape, p.lag_time_s)
    law = twin_plant_law(p)
    state = law.state.copy()
    state[0] = stribeck_ratio(v[0], p.coulomb_ratio, p.stribeck_velocity_mm_s, p.stribeck_shape)
    got = [0.0]
    for i in range(1, t.size):
        law.advance(law.parameters, state, v[i], FINE)
        got.append(state[1])
    np.testing.assert_array_equal(got, expected)
    assert np.ptp(expected) > 1.5  # slid both ways


@pytest.mark.parametrize("axis", ["X", "Y"])
def test_twin_law_load_is_simulate_plants_friction_plus_cogging(axis):
    """The law's friction (position factor with preload, tilt and lead, plus cogging) is simulate_plant's
    friction plus cogging current along the same prescribed motion, up to the rounding of the two formulas."""
    p = default_plant_parameters(axis)
    t = np.arange(4001) * FINE
    v = _dyadic_velocity(6.0 * np.cos(2 * np.pi * 3.0 * t) + 2.0 * np.sin(2 * np.pi * 17.0 * t) + 1.0, FINE)
    x = np.concatenate(([-250.0], -250.0 + np.cumsum(FINE * v[1:])))

    class Prescribed:
        @staticmethod
        def evaluate(time):
            assert time.size == t.size
            return x, v, np.zeros_like(x)

    response = simulate_plant(p, Prescribed(), 501, 8 * FINE)
    law = twin_plant_law(p)
    state = law.state.copy()
    state[0] = stribeck_ratio(v[0], p.coulomb_ratio, p.stribeck_velocity_mm_s, p.stribeck_shape)
    got = [law.friction(law.parameters, state, x[0], v[0])]
    for i in range(1, t.size):
        law.advance(law.parameters, state, v[i], FINE)
        if i % 8 == 0:
            got.append(law.friction(law.parameters, state, x[i], v[i]))
    expected = response.friction_A + response.cogging_A
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12 * np.max(np.abs(expected)))
    assert np.ptp(response.cogging_A) > 1.5 * p.cogging_A and np.ptp(expected) > 1.5


# ------------------------------------------------------------------ analytic facts
@pytest.mark.parametrize("speed", [-25.0, -0.8, 2.0, 40.0])
def test_laws_slide_with_their_steady_friction(speed):
    """At constant velocity every law settles on its Stribeck curve plus the viscous term.

    The twin's law also carries the cogging current of its position (its friction is the plant's whole
    position-dependent load); the position factor is flat here.
    """
    n = int(0.5 / FINE)  # 0.5 s: the twin's lag (15 ms) and every slip transient have died out
    gms, lugre = gms_law(), lugre_law()
    p = default_plant_parameters("X").replace(preload_gain=0.0, lead_gain=0.0, tilt_gain=0.0)
    twin = twin_plant_law(p)
    friction = {}
    for name, law in (("gms", gms), ("lugre", lugre), ("twin", twin)):
        state = law.state.copy()
        for _ in range(n):
            law.advance(law.parameters, state, speed, FINE)
        friction[name] = law.friction(law.parameters, state, 17.0, speed)
    s = GMS["s_inf"] + (GMS["s_0"] - GMS["s_inf"]) * math.exp(-abs(speed) / GMS["v_s"])
    K = float(GMS["k"] @ GMS["alpha"])
    assert friction["gms"] == pytest.approx(math.copysign(K * s, speed) + GMS["mu"] * speed, rel=1e-9)
    g = LUGRE["coulomb"] + (LUGRE["static"] - LUGRE["coulomb"]) * math.exp(-abs(speed) / LUGRE["v_s"])
    assert friction["lugre"] == pytest.approx(math.copysign(g, speed) + LUGRE["sigma2"] * speed, rel=1e-6)
    cogging = float(p.cogging_current(17.0))
    assert abs(cogging) > 0.5 * p.cogging_A  # x = 17 mm is not a zero of the cogging current
    assert friction["twin"] == pytest.approx(p.steady_friction(speed, 17.0) + cogging, rel=1e-9)


def test_stable_step_of_stiffness_and_damping_on_the_inertia():
    assert stable_step(4e-4, 100.0, 0.0) == pytest.approx(MAX_STEP_RATIO * math.sqrt(4e-4 / 100.0))
    assert stable_step(4e-4, 0.0, 0.5) == pytest.approx(MAX_STEP_RATIO * 4e-4 / 0.5)
    assert stable_step(4e-4, 100.0, 0.5) == pytest.approx(MAX_STEP_RATIO * 4e-4 / 0.5)  # the smaller one
    assert stable_step(4e-4, 0.0, 0.0) == math.inf
    stiff = gms_plant_law(**{**GMS, "k": GMS["k"] * 1e4}, inertia=2.8e-4, offset=0.0)
    assert stiff.stable_step_s == pytest.approx(MAX_STEP_RATIO * math.sqrt(2.8e-4 / (1e4 * GMS["k"].sum())))
    fast_slip = gms_plant_law(**{**GMS, "c": 1e3}, inertia=2.8e-4, offset=0.0)
    assert fast_slip.stable_step_s == pytest.approx(min(GMS["s_0"], GMS["s_inf"]) / 1e3)
    damping = LUGRE["sigma1"] + LUGRE["sigma2"]  # limits the LuGre step here, not the bristle stiffness
    assert lugre_law().stable_step_s == pytest.approx(MAX_STEP_RATIO * 2.8e-4 / damping)
    assert lugre_law().stable_step_s < MAX_STEP_RATIO * math.sqrt(2.8e-4 / LUGRE["sigma0"])


def test_models_offer_their_law_and_static_models_none():
    gms = GMSModel()
    gms.alpha_, gms.k_ = GMS["alpha"], GMS["k"]
    gms.slip_rate_, gms.sigma_, gms.s_0_, gms.s_inf_, gms.v_s_, gms.viscous_ = (GMS[key] for key in
                                                                    ("c", "sigma", "s_0", "s_inf", "v_s", "mu"))
    gms.J_, gms.offset_ = 3e-4, 0.07
    law = gms.plant_law()
    assert isinstance(law, PlantLaw) and (law.inertia, law.offset) == (3e-4, 0.07)
    np.testing.assert_array_equal(law.parameters, gms_law().parameters)
    lugre = LuGreModel()
    lugre.sigma0_, lugre.sigma1_, lugre.viscous_ = LUGRE["sigma0"], LUGRE["sigma1"], LUGRE["sigma2"]
    lugre.coulomb_, lugre.static_, lugre.v_s_, lugre.J_, lugre.offset_ = 0.9, 1.25, 3.0, 3e-4, -0.02
    law = lugre.plant_law()
    assert (law.inertia, law.offset) == (3e-4, -0.02)
    np.testing.assert_array_equal(law.parameters, lugre_law().parameters)
    assert CoulombModel().plant_law() is None


# ------------------------------------------------------------------ the shared compiled formulas
def test_stribeck_curve_is_the_models_curve():
    for speed in (0.0, 0.3, 3.0, 30.0, 300.0):
        got = stribeck_at(speed, 0.008, 0.004, 1.0 / 3.0)
        assert got == pytest.approx(stribeck_reference(speed, 0.008, 0.012, 3.0), rel=1e-15)
    assert stribeck_at(0.0, 0.008, 0.004, 1.0 / 3.0) == 0.012  # s_0 at rest
    assert stribeck_at(1e4, 0.008, 0.004, 1.0 / 3.0) == 0.008  # s_inf at high speed


@pytest.mark.parametrize("v", [-12.0, -0.2, 0.0, 0.05, 7.0])
def test_lugre_exact_step_solves_the_bristle_equation(v):
    p = LUGRE
    z0, h = 2e-3, 2e-3
    curves = direction_curves(np.full(2, p["static"]), np.full(2, p["coulomb"]), np.full(2, p["v_s"]))
    lam = lugre_decay_rate(v, p["sigma0"], curves)
    got = lugre_exact_step(z0, v, lam, h)
    assert got == pytest.approx(lugre_step_reference(z0, v, p["sigma0"], p["coulomb"], p["static"], p["v_s"], h),
                                rel=1e-13, abs=1e-18)
    z = z0  # a fine forward-Euler integration of dz/dt = v - lam z converges to the exact step
    for _ in range(20000):
        z += h / 20000 * (v - lam * z)
    assert got == pytest.approx(z, rel=1e-4, abs=1e-12)


def test_twin_stribeck_ratio_lag_and_element_update():
    p = default_plant_parameters("X")
    args = (p.coulomb_ratio, p.stribeck_velocity_mm_s, p.stribeck_shape)
    assert stribeck_ratio(0.0, *args) == 1.0
    assert stribeck_ratio(-1e3, *args) == pytest.approx(p.coulomb_ratio)
    np.testing.assert_allclose(p.stribeck_ratio([-3.0, 3.0]), p.coulomb_ratio + (1 - p.coulomb_ratio) / math.e,
                               rtol=1e-15)
    assert np.ndim(p.stribeck_ratio(2.0)) == 0 and p.stribeck_ratio(np.zeros((2, 3))).shape == (2, 3)
    assert lag_decay(0.25e-3, 0.015) == pytest.approx(math.exp(-0.25e-3 / 0.015), rel=1e-15)
    assert lag_decay(0.25e-3, 0.0) == 0.0
    target = stribeck_ratio(5.0, *args)
    assert lagged_stribeck_ratio(1.0, 5.0, *args, 0.0) == target  # no lag: the steady ratio at once
    assert lagged_stribeck_ratio(1.0, 5.0, *args, 1.0) == 1.0  # infinite lag: unchanged
    deflection = np.array([0.0, 0.5e-3, -1e-3])
    stiffness, limits = np.array([10.0, 20.0, 30.0]), np.array([1e-3, 2e-3, 4e-3])
    force = maxwell_slip_update(deflection, 1e-3, 0.5, stiffness, limits)
    np.testing.assert_allclose(deflection, [0.5e-3, 1e-3, 0.0], atol=1e-18)  # clamped at D_i r
    assert force == pytest.approx(10.0 * 0.5e-3 + 20.0 * 1e-3)
