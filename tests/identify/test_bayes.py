"""Smoke tests of the scikit-optimize interface."""

from __future__ import annotations

import math

import numpy as np
import pytest

from greybox.identify.bayes import minimize_log_uniform


def bowl(params):
    """Minimum 0 at a = 10, b = 0.01 in log coordinates."""
    return (math.log10(params["a"]) - 1.0) ** 2 + (math.log10(params["b"]) + 2.0) ** 2


def test_finds_the_minimum_region_of_a_known_function():
    bounds = {"a": (1e-3, 1e3), "b": (1e-5, 1e1)}
    best, history = minimize_log_uniform(bowl, bounds, n_calls=16, random_state=0)
    assert abs(math.log10(best["a"]) - 1.0) < 0.3
    assert abs(math.log10(best["b"]) + 2.0) < 0.3
    assert len(history) == 16
    assert all(bounds[k][0] <= h[k] <= bounds[k][1] for h in history for k in bounds)
    assert best["a"] == min(history, key=lambda h: h["objective"])["a"]
    # The surrogate beats the random start: the best of the guided points is
    # better than the best of the 8 random ones.
    random_best = min(h["objective"] for h in history[:8])
    assert min(h["objective"] for h in history[8:]) < random_best


def test_seeded_and_reports_progress():
    seen = []
    _, first = minimize_log_uniform(bowl, {"a": (1e-2, 1e2), "b": (1e-3, 1e-1)}, n_calls=6, random_state=3)
    _, second = minimize_log_uniform(
        bowl, {"a": (1e-2, 1e2), "b": (1e-3, 1e-1)}, n_calls=6, random_state=3,
        progress=lambda i, p, v: seen.append((i, v)),
    )
    assert first == second
    assert [i for i, _ in seen] == list(range(6))


def test_non_finite_values_are_survived_and_never_chosen():
    def objective(params):
        return math.nan if params["a"] > 1.0 else (math.log10(params["a"]) + 1.0) ** 2

    best, history = minimize_log_uniform(objective, {"a": (1e-3, 1e3)}, n_calls=10, random_state=0)
    assert any(not np.isfinite(h["objective"]) for h in history)
    assert best["a"] <= 1.0


def test_rejects_bad_bounds():
    with pytest.raises(ValueError, match="0 < low < high"):
        minimize_log_uniform(bowl, {"a": (0.0, 1.0)}, n_calls=3)
    with pytest.raises(ValueError, match="empty"):
        minimize_log_uniform(bowl, {}, n_calls=3)


@pytest.mark.slow  # a long search, > 5 s
def test_a_minimum_in_a_corner_is_found_without_skopt_repeat_warnings():
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        best, history = minimize_log_uniform(lambda p: p["a"], {"a": (1e-2, 1e2)}, n_calls=12,
                                             n_initial_points=3, random_state=0)
    assert not [w for w in caught if "evaluated at point" in str(w.message)]
    assert best["a"] < 1.1e-2
    assert len(history) == 12
