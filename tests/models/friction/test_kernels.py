"""The compiled friction kernels agree with their plain-Python references."""

from __future__ import annotations

import numpy as np
import pytest
from friction_reference import gms_reference, lugre_reference, play_operator_reference
from friction_signals import STEP, velocity_profile

from greybox.models.friction.directions import direction_pair
from greybox.models.friction.gms import GMSState, gms_trajectory, simulate_gms
from greybox.models.friction.kernels import (
    direction_curves,
    gms_friction_kernel,
    gms_trajectory_kernel,
    lugre_trajectory_kernel,
    play_operator_kernel,
)
from greybox.models.friction.lugre import simulate_lugre


def gms_parameters(n_elements, seed=0):
    rng = np.random.default_rng(seed)
    alpha = rng.uniform(0.2, 1.0, n_elements)
    return {"alpha": alpha / alpha.sum(), "k": rng.uniform(10.0, 80.0, n_elements), "sigma": 0.003,
            "s_0": 0.02, "s_inf": 0.012, "v_s": 4.0, "C": 3.0, "mu": 0.004}


def run_kernel(velocity, p, state=None):
    state = GMSState.at_rest(p["alpha"].size) if state is None else state
    return gms_friction_kernel(velocity, STEP, p["alpha"], p["k"], p["sigma"], curves_of(p), p["C"],
                               direction_pair(p["mu"], "mu"), state.z, state.mode)


def curves_of(p):
    return direction_curves(direction_pair(p["s_0"], "s_0"), direction_pair(p["s_inf"], "s_inf"),
                            direction_pair(p["v_s"], "v_s"))


@pytest.mark.parametrize("n_elements", [1, 4, 10])
def test_gms_kernel_matches_python_reference(n_elements):
    velocity = velocity_profile(12.0, seed=n_elements)
    p = gms_parameters(n_elements)
    friction, z_end, mode_end = run_kernel(velocity, p)
    ref, ref_z, ref_mode, ref_z_end, ref_mode_end = gms_reference(
        velocity, STEP, p["alpha"], p["k"], p["sigma"], p["s_0"], p["s_inf"], p["v_s"], p["C"], p["mu"])
    scale = np.max(np.abs(ref))
    np.testing.assert_allclose(friction, ref, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(z_end, ref_z_end, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(mode_end, ref_mode_end)
    # the trajectory kernel reproduces the element states and, through them, the friction
    z, stick, w, trajectory_friction, end = gms_trajectory(velocity, STEP, **p)
    np.testing.assert_allclose(z, ref_z, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(trajectory_friction, friction)  # one pass gives the same sums in the same order
    np.testing.assert_array_equal(stick, np.asarray(ref_mode) == 0)
    np.testing.assert_allclose(z @ p["k"] + p["sigma"] * w + p["mu"] * velocity, ref, rtol=0, atol=1e-12 * scale)
    np.testing.assert_array_equal(end.z, z_end)


def test_gms_kernel_exercises_stick_and_slip():
    velocity = velocity_profile(12.0, seed=4)
    p = gms_parameters(4)
    _, stick, _, _, _ = gms_trajectory(velocity, STEP, alpha=p["alpha"], C=p["C"], s_0=p["s_0"],
                                       s_inf=p["s_inf"], v_s=p["v_s"])
    # every element both sticks and slips, and there are samples where only some elements stick
    assert stick.any(axis=0).all() and (~stick).any(axis=0).all()
    partial = stick.any(axis=1) & ~stick.all(axis=1)
    assert partial.sum() > 100


def test_gms_chunks_carry_the_state():
    velocity = velocity_profile(8.0, seed=7)
    p = gms_parameters(4)
    whole, _ = simulate_gms(velocity, STEP, **p)
    parts, state = [], None
    for chunk in np.array_split(velocity, [1, 777, 778, 2500]):
        friction, state = simulate_gms(chunk, STEP, **p, state=state)
        parts.append(friction)
    np.testing.assert_array_equal(np.concatenate(parts), whole)


def test_lugre_kernel_matches_python_reference():
    velocity = velocity_profile(12.0, seed=3)
    params = {"sigma0": 300.0, "sigma1": 0.05, "sigma2": 0.004, "coulomb": 0.6, "static": 0.9, "v_s": 3.0}
    friction, z, z_end = simulate_lugre(velocity, STEP, **params)
    ref, ref_z, ref_z_end = lugre_reference(velocity, STEP, params["sigma0"], params["sigma1"], params["sigma2"],
                                            params["coulomb"], params["static"], params["v_s"])
    np.testing.assert_allclose(friction, ref, rtol=0, atol=1e-10 * np.max(np.abs(ref)))
    np.testing.assert_allclose(z, ref_z, rtol=0, atol=1e-12 * np.max(np.abs(ref_z)))
    assert z_end == pytest.approx(ref_z_end, abs=1e-12 * np.max(np.abs(ref_z)))


def test_kernels_write_into_column_views():
    """The identification passes column views of its regressor matrix as outputs."""
    velocity = velocity_profile(2.0, seed=1)
    p = gms_parameters(4)
    matrix = np.zeros((velocity.size, 7))
    modes = np.empty((velocity.size, 4), dtype=np.int8)
    rest = GMSState.at_rest(4)
    gms_trajectory_kernel(velocity, STEP, p["alpha"], p["k"], p["sigma"], curves_of(p), p["C"],
                          direction_pair(p["mu"], "mu"), rest.z, rest.mode, matrix[:, :4], modes, matrix[:, 4],
                          matrix[:, 5])
    z, stick, w, friction, _ = gms_trajectory(velocity, STEP, **p)
    np.testing.assert_array_equal(matrix[:, :4], z)
    np.testing.assert_array_equal(matrix[:, 4], w)
    np.testing.assert_array_equal(matrix[:, 5], friction)
    assert np.all(matrix[:, 6] == 0.0)
    z_col = np.zeros((velocity.size, 2))
    end = lugre_trajectory_kernel(velocity, STEP, 300.0, direction_curves([0.9, 0.9], [0.6, 0.6], [3.0, 3.0]), 0.0,
                                  z_col[:, 0], z_col[:, 1])
    _, z_ref, end_ref = simulate_lugre(velocity, STEP, sigma0=300.0, sigma1=0.0, sigma2=0.0, coulomb=0.6,
                                       static=0.9, v_s=3.0)
    np.testing.assert_array_equal(z_col[:, 0], z_ref)
    assert end == end_ref


def test_play_operator_kernel_matches_python_reference():
    rng = np.random.default_rng(4)
    position = np.cumsum(rng.normal(0.0, 0.004, 3000))
    widths = np.array([0.001, 0.003, 0.01, 0.03])
    start = rng.uniform(-1.0, 1.0, widths.size)
    states, after = np.empty((position.size, widths.size)), start.copy()
    play_operator_kernel(position, widths, after, -0.01, states)
    rows, expected_after = play_operator_reference(position, widths, start, -0.01)
    np.testing.assert_array_equal(states, np.array(rows))
    np.testing.assert_array_equal(after, expected_after)


def test_play_operator_is_rate_independent_and_saturates_after_its_width():
    widths = np.array([0.002, 0.02])
    coarse = np.array([0.0, 0.01, 0.03, 0.025, 0.0])
    fine = np.interp(np.linspace(0.0, 4.0, 401), np.arange(5.0), coarse)   # the same path, 100 times the samples
    states = [np.empty((path.size, 2)) for path in (coarse, fine)]
    for path, out in zip((coarse, fine), states):
        play_operator_kernel(path, widths, np.zeros(2), path[0], out)
    np.testing.assert_allclose(states[1][::100], states[0], atol=1e-12)
    np.testing.assert_allclose(states[0][:, 0], [0.0, 1.0, 1.0, -1.0, -1.0], atol=1e-12)   # 2 um: saturated
    np.testing.assert_allclose(states[0][:, 1], [0.0, 0.5, 1.0, 0.75, -0.5], atol=1e-12)   # 20 um: follows
    # in two chunks, the second starting from the first's end state and last position: the same states
    state, chunks = np.zeros(2), [np.empty((150, 2)), np.empty((fine.size - 150, 2))]
    play_operator_kernel(fine[:150], widths, state, fine[0], chunks[0])
    play_operator_kernel(fine[150:], widths, state, fine[149], chunks[1])
    np.testing.assert_array_equal(np.vstack(chunks), states[1])
