"""Initial guesses from the data, static fits and bounded linear least squares."""

from __future__ import annotations

import numpy as np
import pytest
from friction_signals import STEP, motion_log, velocity_profile
from scipy.optimize import lsq_linear

from greybox.identify.initial import (
    distance_since_reversal,
    motion_direction,
    presliding_deflection,
    sliding_mask,
    static_initial_guess,
)
from greybox.identify.linear import bounded_lstsq
from greybox.models.friction import stribeck_curve
from greybox.models.friction.gms import simulate_gms


def test_motion_direction_carries_the_last_direction_over_standstill():
    direction = motion_direction(np.array([0.0, 0.0, 1.0, 0.0, -2.0, 0.0, 0.0, 3.0]))
    np.testing.assert_array_equal(direction, [0, 0, 1, 1, -1, -1, -1, 1])


def test_distance_since_reversal():
    time = np.arange(7) * 0.5
    velocity = np.array([1.0, 1.0, 1.0, -1.0, 0.0, -1.0, 2.0])
    np.testing.assert_allclose(distance_since_reversal(time, velocity), [0.0, 0.5, 1.0, 0.0, 0.5, 0.5, 0.0])


def test_sliding_mask_leaves_out_the_first_travel_after_each_reversal():
    velocity = np.concatenate((np.full(100, 5.0), np.full(100, -5.0)))  # 0.01 mm per sample
    mask = sliding_mask(motion_log(velocity), min_distance=0.095)
    np.testing.assert_array_equal(np.flatnonzero(~mask), np.r_[0:10, 100:110])


def test_static_guess_uses_only_sliding_samples():
    log = motion_log(velocity_profile(20.0, seed=2))
    sliding = sliding_mask(log)
    assert 0.3 < sliding.mean() < 0.99
    static = np.sign(log.velocity) * stribeck_curve(log.velocity, 0.9, 0.6, 3.0) + 0.004 * log.velocity
    current = np.where(sliding, 0.001 * log.acceleration + static, 5.0)  # garbage near reversals
    guess = static_initial_guess([log.replace(effort=current)])
    assert guess["static"] == pytest.approx(0.9, rel=1e-6)
    assert guess["coulomb"] == pytest.approx(0.6, rel=1e-6)
    assert guess["v_s"] == pytest.approx(3.0, rel=1e-5)
    assert guess["viscous"] == pytest.approx(0.004, rel=1e-6)
    assert guess["J"] == pytest.approx(0.001, rel=1e-6)


def test_presliding_deflection_of_a_single_spring():
    delta, stiffness, speed = 0.01, 60.0, 0.5  # mm, A/mm, mm/s: 0.001 mm per sample
    stroke = int(0.5 / (speed * STEP))
    velocity = np.tile(np.concatenate((np.full(stroke, speed), np.full(stroke, -speed))), 3)
    friction, _ = simulate_gms(velocity, STEP, alpha=np.array([1.0]), k=np.array([stiffness]), C=0.1,
                               sigma=0.0, s_0=delta, s_inf=delta, v_s=10.0, mu=0.0)
    level = stiffness * delta
    static = {"J": 0.0, "offset": 0.0, "viscous": 0.0, "coulomb": level, "static": level, "v_s": 10.0}
    estimate = presliding_deflection([motion_log(velocity, friction)], static)
    assert estimate == pytest.approx(delta, abs=speed * STEP / 1.8)
    assert presliding_deflection([motion_log(np.full(500, speed), np.full(500, level))], static) is None


def test_bounded_lstsq_matches_scipy():
    rng = np.random.default_rng(0)
    a = rng.standard_normal((400, 5)) * np.array([1e-3, 1.0, 1e3, 5.0, 1.0])
    b = a @ np.array([2e3, -1.0, 1e-3, 0.5, -3.0]) + 0.1 * rng.standard_normal(400)
    x, residual = bounded_lstsq(a, b)
    np.testing.assert_allclose(x, np.linalg.lstsq(a, b, rcond=None)[0], rtol=1e-8)
    np.testing.assert_allclose(residual, a @ x - b)
    lower, upper = np.array([0.0, 0.0, 0.0, 0.0, -1.0]), np.full(5, np.inf)
    x, _ = bounded_lstsq(a, b, lower, upper)
    reference = lsq_linear(a, b, bounds=(lower, upper), method="bvls", tol=1e-12).x
    assert x[1] == 0.0 and x[4] == -1.0
    np.testing.assert_allclose(x, reference, rtol=1e-6, atol=1e-9)


def test_bounded_lstsq_gives_a_zero_column_the_coefficient_nearest_zero():
    a = np.column_stack((np.arange(10.0), np.zeros(10)))
    x, _ = bounded_lstsq(a, 2.0 * np.arange(10.0), np.array([-np.inf, 1.0]), np.array([np.inf, 3.0]))
    np.testing.assert_allclose(x, [2.0, 1.0])
