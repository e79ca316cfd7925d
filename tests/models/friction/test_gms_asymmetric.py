"""Physics and identification of the direction-dependent (asymmetric) GMS model."""

from __future__ import annotations

import numpy as np
import pytest
from friction_reference import gms_reference
from friction_signals import STEP, motion_log, velocity_profile

from greybox.errors import ParameterError
from greybox.models.friction import GMSModel, stribeck_curve
from greybox.models.friction.gms import gms_trajectory, simulate_gms
from greybox.models.friction.plant_laws import gms_plant_law

#: Shared elements, and a break-away curve and viscous coefficient per direction (positive, negative motion).
ASYMMETRIC = {"alpha": np.array([0.15, 0.25, 0.6]), "k": np.array([40.0, 60.0, 30.0]), "sigma": 0.002, "C": 2.0,
              "s_0": (0.02, 0.034), "s_inf": (0.015, 0.026), "v_s": (5.0, 2.0), "mu": (0.005, 0.009)}
INERTIA = 0.001  # A s^2/mm


def swapped(params):
    """The same elements with the two directions' curves exchanged."""
    return {name: value[::-1] if isinstance(value, tuple) else value for name, value in params.items()}


def cycles(amplitude_mm, period_s, n_cycles):
    """Velocity [mm/s] of a sinusoidal position of the given amplitude, whole cycles at STEP."""
    t = np.arange(int(round(n_cycles * period_s / STEP))) * STEP
    return amplitude_mm * 2.0 * np.pi / period_s * np.cos(2.0 * np.pi * t / period_s)


@pytest.mark.parametrize("seed", [1, 4])
def test_compiled_kernel_matches_the_python_reference(seed):
    velocity = velocity_profile(6.0, seed=seed)
    friction, state = simulate_gms(velocity, STEP, **ASYMMETRIC)
    ref, _, _, z_end, mode_end = gms_reference(velocity, STEP, ASYMMETRIC["alpha"], ASYMMETRIC["k"],
                                               ASYMMETRIC["sigma"], ASYMMETRIC["s_0"], ASYMMETRIC["s_inf"],
                                               ASYMMETRIC["v_s"], ASYMMETRIC["C"], ASYMMETRIC["mu"])
    np.testing.assert_allclose(friction, ref, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(state.z, z_end, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(state.mode, mode_end)


def test_equal_directions_are_the_symmetric_model_bit_for_bit():
    velocity = velocity_profile(8.0, seed=3)
    symmetric = {**ASYMMETRIC, "s_0": 0.02, "s_inf": 0.015, "v_s": 5.0, "mu": 0.005}
    as_pairs = {**ASYMMETRIC, "s_0": (0.02, 0.02), "s_inf": (0.015, 0.015), "v_s": (5.0, 5.0), "mu": (0.005, 0.005)}
    np.testing.assert_array_equal(simulate_gms(velocity, STEP, **as_pairs)[0], simulate_gms(velocity, STEP,
                                                                                             **symmetric)[0])
    friction = simulate_gms(velocity, STEP, **as_pairs)[0]
    np.testing.assert_array_equal(simulate_gms(-velocity, STEP, **as_pairs)[0], -friction)  # odd symmetry


def test_mirrored_motion_with_exchanged_directions_is_the_negative_friction():
    """F(-v; curves swapped) = -F(v; curves): the model treats the two directions alike."""
    velocity = velocity_profile(8.0, seed=5)
    friction, _ = simulate_gms(velocity, STEP, **ASYMMETRIC)
    np.testing.assert_array_equal(simulate_gms(-velocity, STEP, **swapped(ASYMMETRIC))[0], -friction)
    assert not np.allclose(simulate_gms(-velocity, STEP, **ASYMMETRIC)[0], -friction, atol=1e-3)


@pytest.mark.parametrize("speed", [-60.0, -4.0, -0.5, 0.5, 4.0, 60.0])
def test_steady_sliding_follows_each_directions_curve(speed):
    velocity = np.concatenate((np.full(200, -speed), np.full(4000, speed)))
    friction, state = simulate_gms(velocity, STEP, **ASYMMETRIC)
    r = 0 if speed > 0 else 1
    stiffness = np.sum(ASYMMETRIC["k"] * ASYMMETRIC["alpha"])
    curve = stribeck_curve(speed, ASYMMETRIC["s_0"][r], ASYMMETRIC["s_inf"][r], ASYMMETRIC["v_s"][r])
    assert friction[-1] == pytest.approx(np.sign(speed) * stiffness * curve + ASYMMETRIC["mu"][r] * speed, rel=1e-9)
    assert np.all(state.mode == np.sign(speed))


def test_no_drift_of_the_deflections_over_many_reversals():
    """Large and small reversals, stops and stick-slip switching: deflections bounded and periodic."""
    rng = np.random.default_rng(7)
    one_period = np.concatenate([cycles(a, p, 1) for a, p in ((2.0, 0.4), (0.01, 0.2), (0.03, 0.1), (1.0, 0.25))]
                                + [np.zeros(25)])
    one_period = one_period + 0.2 * rng.standard_normal(one_period.size) * (np.abs(one_period) > 0)
    one_period -= one_period.mean()  # closed in position
    velocity = np.tile(one_period, 200)  # 800 reversals and more
    z, _, _, friction, _ = gms_trajectory(velocity, STEP, **ASYMMETRIC)
    limit = ASYMMETRIC["alpha"] * max(max(ASYMMETRIC["s_0"]), max(ASYMMETRIC["s_inf"]))
    assert np.all(np.abs(z) <= limit * (1 + 1e-12))
    n = one_period.size
    np.testing.assert_allclose(z[-n:], z[-2 * n:-n], atol=1e-12)  # a periodic orbit, no creep
    assert np.max(np.abs(np.diff(z[::n], axis=0)[-100:])) < 1e-12


@pytest.mark.parametrize("amplitude_mm", [0.05, 0.5, 5.0])
def test_energy_dissipated_over_closed_cycles_is_positive(amplitude_mm):
    """The friction takes work from the motion over every closed cycle, in either direction of travel."""
    velocity = cycles(amplitude_mm, 0.5, 6)
    for direction in (1.0, -1.0):
        friction, _ = simulate_gms(direction * velocity, STEP, **ASYMMETRIC)
        per_cycle = (friction * direction * velocity * STEP).reshape(6, -1).sum(axis=1)
        assert np.all(per_cycle[1:] > 0.0)
        # the stored spring energy returns: steady cycles dissipate the same work
        assert per_cycle[-1] == pytest.approx(per_cycle[-2], rel=1e-9)


def test_sliding_cycles_dissipate_each_directions_own_level():
    """A slow 10 mm cycle dissipates the work of each direction's sliding friction over its own travel."""
    velocity = cycles(5.0, 8.0, 2)
    friction, _ = simulate_gms(velocity, STEP, **ASYMMETRIC)
    second = slice(velocity.size // 2, None)
    work = np.sum((friction * velocity * STEP)[second])
    stiffness = np.sum(ASYMMETRIC["k"] * ASYMMETRIC["alpha"])
    v = velocity[second]
    r = (v < 0).astype(int)
    curve = stribeck_curve(v, np.take(ASYMMETRIC["s_0"], r), np.take(ASYMMETRIC["s_inf"], r),
                           np.take(ASYMMETRIC["v_s"], r))
    sliding = np.sum((stiffness * curve * np.abs(v) + np.take(ASYMMETRIC["mu"], r) * v ** 2) * STEP)
    assert work == pytest.approx(sliding, rel=0.01)  # the pre-sliding travel (0.06 mm of 20 mm) aside
    positive_share = np.sum((friction * velocity * STEP)[second][v > 0]) / work
    assert positive_share < 0.45  # the weaker positive direction takes less than half


def test_plant_law_takes_the_asymmetric_element_step():
    velocity = velocity_profile(4.0, seed=6)
    law = gms_plant_law(alpha=ASYMMETRIC["alpha"], k=ASYMMETRIC["k"], sigma=ASYMMETRIC["sigma"],
                        s_0=ASYMMETRIC["s_0"], s_inf=ASYMMETRIC["s_inf"], v_s=ASYMMETRIC["v_s"], c=ASYMMETRIC["C"],
                        mu=ASYMMETRIC["mu"], inertia=INERTIA, offset=0.0)
    _, _, _, friction, _ = gms_trajectory(velocity, STEP, **ASYMMETRIC)
    state = law.state.copy()
    plant = np.empty(velocity.size)
    for j, v in enumerate(velocity):
        law.advance(law.parameters, state, v, STEP)
        plant[j] = law.friction(law.parameters, state, 0.0, v)
    # the law's friction is explicit: it reads the deflections after the step and that step's rate
    z_after, _, w, _, _ = gms_trajectory(velocity, STEP, **ASYMMETRIC)
    expected = np.where(velocity < 0, ASYMMETRIC["mu"][1], ASYMMETRIC["mu"][0]) * velocity \
        + ASYMMETRIC["sigma"] * w + np.vstack((z_after[1:], np.zeros((1, 3)))) @ ASYMMETRIC["k"]
    np.testing.assert_allclose(plant[:-1], expected[:-1], rtol=1e-10, atol=1e-10)
    assert law.stable_step_s <= min(min(ASYMMETRIC["s_0"]), min(ASYMMETRIC["s_inf"])) / ASYMMETRIC["C"]


@pytest.mark.slow  # an identification, > 5 s
def test_identification_recovers_the_two_directions_levels():
    velocity = velocity_profile(30.0, seed=8)
    log = motion_log(velocity)
    friction, _ = simulate_gms(velocity, STEP, **ASYMMETRIC)
    log = log.replace(effort=INERTIA * log.acceleration + friction
                      + 0.002 * np.random.default_rng(8).standard_normal(velocity.size))
    model = GMSModel(asymmetric=True, n_elements=3).fit(log)
    symmetric = GMSModel(n_elements=3).fit(log)
    stiffness = np.sum(ASYMMETRIC["k"] * ASYMMETRIC["alpha"])
    fitted_stiffness = np.sum(model.k_ * model.alpha_)
    for speed in (1.0, 10.0, 50.0):
        for r, (s_0, s_inf, v_s) in enumerate(((model.s_0_, model.s_inf_, model.v_s_),
                                               (model.s_0_neg_, model.s_inf_neg_, model.v_s_neg_))):
            truth = stiffness * stribeck_curve(speed, ASYMMETRIC["s_0"][r], ASYMMETRIC["s_inf"][r],
                                               ASYMMETRIC["v_s"][r])
            assert fitted_stiffness * stribeck_curve(speed, s_0, s_inf, v_s) == pytest.approx(truth, rel=0.03)
    rmse = np.sqrt(np.mean((model.predict(log) - log.effort) ** 2))
    assert rmse < 0.004  # at the noise (0.002 A), where the symmetric model cannot get
    assert np.sqrt(np.mean((symmetric.predict(log) - log.effort) ** 2)) > 3 * rmse
    assert model.n_params == symmetric.n_params + 4


def test_asymmetric_model_refuses_an_offset():
    log = motion_log(velocity_profile(2.0, seed=1))
    with pytest.raises(ParameterError, match="not separately identifiable"):
        GMSModel(asymmetric=True, fit_offset=True).fit(log.replace(effort=np.sign(log.velocity)))


def test_parameter_table_names_each_direction():
    model = GMSModel(asymmetric=True, n_elements=3)
    model.alpha_, model.k_, model.slip_rate_, model.sigma_ = ASYMMETRIC["alpha"], ASYMMETRIC["k"], 2.0, 0.002
    model.s_0_, model.s_0_neg_ = ASYMMETRIC["s_0"]
    model.s_inf_, model.s_inf_neg_ = ASYMMETRIC["s_inf"]
    model.v_s_, model.v_s_neg_ = ASYMMETRIC["v_s"]
    model.viscous_, model.viscous_neg_ = ASYMMETRIC["mu"]
    model.J_, model.offset_, model.effort_unit_ = INERTIA, 0.0, "A"
    rows = {row.name: row for row in model.parameter_table()}
    assert rows["s_0_neg"].value == 0.034 and "negative" in rows["s_0_neg"].description
    assert rows["s_0"].value == 0.02 and "positive" in rows["s_0"].description
    assert rows["viscous_neg"].unit.endswith("s/mm")
