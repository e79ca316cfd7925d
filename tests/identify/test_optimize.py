"""Bounded local searches, seeded multi-start and progress reports."""

from __future__ import annotations

import io

import numpy as np
import pytest

from greybox.identify.optimize import local_search, multistart
from greybox.identify.progress import ProgressEvent, ProgressPrinter, make_progress


def shifted(target):
    target = np.asarray(target, dtype=float)
    return lambda x: np.asarray(x) - target


def double_well(x):
    """Cost (x^2 - 1)^2 + 0.3 x as residuals: global minimum near -1, a local one near +1."""
    return np.array([x[0] ** 2 - 1.0, np.sqrt(0.3 * (x[0] + 3.0))])


@pytest.mark.parametrize("method", ["nelder-mead", "least-squares"])
def test_local_search_finds_an_interior_minimum(method):
    result = local_search(shifted([0.3, -1.2, 2.0]), [0.0, 0.0, 0.0], [-5, -5, -5], [5, 5, 5], scale=0.5,
                          method=method, max_iter=2000)
    np.testing.assert_allclose(result.x, [0.3, -1.2, 2.0], atol=1e-3)
    assert result.cost < 1e-6 and result.n_evaluations > 3


@pytest.mark.parametrize("method", ["nelder-mead", "least-squares"])
def test_bounds_are_respected(method):
    seen = []

    def residuals(x):
        seen.append(np.array(x))
        return np.asarray(x) - np.array([3.0, -3.0])

    result = local_search(residuals, [0.0, 0.0], [-1.0, -1.0], [1.0, 1.0], scale=0.5, method=method, max_iter=500)
    np.testing.assert_allclose(result.x, [1.0, -1.0], atol=1e-3)
    assert np.all(np.abs(np.array(seen)) <= 1.0 + 1e-12)


def test_multistart_is_reproducible_and_escapes_a_local_minimum():
    single = local_search(double_well, [1.2], [-3.0], [3.0], scale=0.2)
    assert single.x[0] > 0  # the local search alone stays in the well it started in
    first = multistart(double_well, [1.2], [-3.0], [3.0], scale=3.0, n_starts=10, random_state=3)
    second = multistart(double_well, [1.2], [-3.0], [3.0], scale=3.0, n_starts=10, random_state=3)
    assert first.x[0] < 0 and first.cost < single.cost
    assert first.x[0] == second.x[0] and first.cost == second.cost and first.start == second.start
    assert first.start > 0


def test_multistart_reports_every_evaluation():
    events = []
    result = multistart(shifted([0.5]), [0.0], [-1.0], [1.0], scale=0.3, n_starts=3, random_state=0,
                        stage="test", progress=events.append)
    assert len(events) == result.n_evaluations + 3  # one extra 'done' event per start
    assert [e.start for e in events if e.done] == [0, 1, 2]
    bests = [e.best for e in events]
    assert bests == sorted(bests, reverse=True) and bests[-1] == result.cost
    assert all(e.stage == "test" and e.n_starts == 3 for e in events)


def test_invalid_arguments():
    with pytest.raises(ValueError, match="unknown method"):
        local_search(shifted([0.0]), [0.0], [-1.0], [1.0], scale=0.1, method="bfgs")
    with pytest.raises(ValueError, match="lower < upper"):
        local_search(shifted([0.0]), [0.0], [1.0], [-1.0], scale=0.1)
    with pytest.raises(ValueError, match="n_starts"):
        multistart(shifted([0.0]), [0.0], [-1.0], [1.0], scale=0.1, n_starts=0)


def test_progress_printer_writes_throttled_lines():
    stream = io.StringIO()
    printer = ProgressPrinter(stream, interval=3600.0)
    for evaluation in range(1, 50):
        printer(ProgressEvent("GMS joint", 0, 1, evaluation, 1.0 / evaluation, 1.0 / evaluation))
    printer(ProgressEvent("GMS joint", 0, 1, 50, 0.02, 0.02, done=True))
    lines = stream.getvalue().splitlines()
    assert len(lines) == 2  # the first event, then the final one
    assert lines[-1].startswith("GMS joint: start 1/1 eval    50 cost 0.02 best 0.02 (done)")


def test_make_progress():
    assert make_progress(None) is None and make_progress(False) is None
    assert isinstance(make_progress(True), ProgressPrinter)
    callback = [].append
    assert make_progress(callback) is callback
    with pytest.raises(TypeError):
        make_progress("yes")


def test_fixed_design_fills_the_cube_evenly_and_replaces_the_seeded_draws():
    from scipy.special import ndtr

    from greybox.identify.optimize import fixed_design, multistart_results

    design = fixed_design(64, 3)
    np.testing.assert_array_equal(design, fixed_design(64, 3))
    u = ndtr(design)
    for j in range(3):  # every eighth of each axis holds 8 of the 64 points, give or take three
        counts = np.histogram(u[:, j], bins=8, range=(0.0, 1.0))[0]
        assert counts.min() >= 5 and counts.max() <= 11

    def residuals(theta):
        return np.array([theta[0] - 1.0, 3.0 * (theta[1] + 0.5)])

    starts = {}
    for seed in (0, 1):
        results = multistart_results(residuals, [0.0, 0.0], [-2.0, -2.0], [2.0, 2.0], scale=0.5, n_starts=3,
                                     random_state=seed, deviates=fixed_design(2, 2), max_iter=5)
        starts[seed] = [result.x for result in results]
    np.testing.assert_array_equal(starts[0], starts[1])


def test_a_stall_rule_ends_a_search_on_a_flat_cost_and_leaves_one_that_progresses():
    from greybox.identify.optimize import Stall

    stall = Stall(tolerance=1e-4, window=10)
    flat = local_search(lambda x: np.array([1.0]), [0.0, 0.0], [-1.0, -1.0], [1.0, 1.0], scale=0.1, max_iter=400,
                        stall=stall)
    # the best cost never falls: the search ends after one window of 10 (p + 1) evaluations, not at max_iter
    assert flat.n_evaluations == stall.evaluations(2) + 1
    target = [0.3, -0.2]
    free = local_search(shifted(target), [0.0, 0.0], [-1.0, -1.0], [1.0, 1.0], scale=0.5, max_iter=2000)
    stopped = local_search(shifted(target), [0.0, 0.0], [-1.0, -1.0], [1.0, 1.0], scale=0.5, max_iter=2000,
                           stall=stall)
    # a search that still makes progress reaches the minimum; it stops once the cost no longer falls by 1e-4
    np.testing.assert_allclose(stopped.x, target, atol=1e-3)
    assert stopped.n_evaluations <= free.n_evaluations
    # least squares has its own rules: the stall rule does not apply to it
    squares = local_search(lambda x: np.array([1.0]), [0.0], [-1.0], [1.0], scale=0.1, method="least-squares",
                           max_iter=400, stall=Stall(tolerance=1e-4, window=1))
    assert squares.cost == 1.0
