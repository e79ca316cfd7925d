"""Least-squares projections and the position scan of the discovery workflow."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse

from greybox.identify.projection import Nuisance, PositionScan, _reduction, _reduction_pairs, added_squares


def rss(matrix, target):
    coefficients, *_ = np.linalg.lstsq(matrix, target, rcond=None)
    residual = target - matrix @ coefficients
    return float(residual @ residual)


@pytest.fixture
def problem():
    rng = np.random.default_rng(3)
    n = 500
    nuisance = np.column_stack((np.ones(n), rng.normal(size=n), rng.normal(size=n)))
    candidate = np.column_stack((rng.normal(size=n), rng.normal(size=n)))
    targets = rng.normal(size=(n, 4)) + candidate @ rng.normal(size=(2, 4))
    return nuisance, candidate, targets


def test_added_squares_is_the_drop_of_the_residual_sum_of_squares(problem):
    nuisance, candidate, targets = problem
    basis = Nuisance(nuisance)
    reduction = added_squares(candidate, basis.project(targets), basis)
    for j in range(targets.shape[1]):
        expected = rss(nuisance, targets[:, j]) - rss(np.hstack((nuisance, candidate)), targets[:, j])
        assert reduction[j] == pytest.approx(expected, rel=1e-9)


def test_sparse_columns_give_the_same_reduction(problem):
    nuisance, _, targets = problem
    rng = np.random.default_rng(4)
    codes = rng.integers(0, 6, size=targets.shape[0])
    indicators = scipy.sparse.csr_matrix((np.ones(codes.size), (np.arange(codes.size), codes)))
    basis = Nuisance(nuisance)
    sparse = added_squares(indicators, basis.project(targets), basis)
    dense = added_squares(indicators.toarray(), basis.project(targets), basis)
    np.testing.assert_allclose(sparse, dense, rtol=1e-8)
    # the indicators sum to the constant column already in the nuisance: one direction fewer, still exact
    expected = rss(nuisance, targets[:, 0]) - rss(np.hstack((nuisance, indicators.toarray())), targets[:, 0])
    assert sparse[0] == pytest.approx(expected, rel=1e-8)


def test_columns_inside_the_nuisance_add_nothing(problem):
    nuisance, _, targets = problem
    basis = Nuisance(nuisance)
    inside = nuisance @ np.array([[1.0], [2.0], [-0.5]])
    assert np.all(added_squares(inside, basis.project(targets), basis) < 1e-20)


def test_dependent_nuisance_columns_are_dropped(problem):
    nuisance, _, _ = problem
    assert Nuisance(np.hstack((nuisance, nuisance[:, :1] * 3.0))).rank == 3


def test_two_column_closed_form_agrees_with_the_eigen_decomposition():
    rng = np.random.default_rng(5)
    for case in range(20):
        columns = rng.normal(size=(40, 2))
        if case % 4 == 1:
            columns[:, 1] = 2.0 * columns[:, 0]  # rank one
        if case % 4 == 2:
            columns[:, 0] = 0.0  # a zero column
        gram = columns.T @ columns
        cross = columns.T @ rng.normal(size=(40, 3))
        norms = np.diag(gram).copy()
        pairs = _reduction_pairs(gram[0, 0:1], gram[0, 1:2], gram[1, 1:2], norms[0:1], norms[1:2],
                                 cross[0:1], cross[1:2])[0]
        np.testing.assert_allclose(pairs, _reduction(gram, norms, cross), rtol=1e-9, atol=1e-12)


def _sine_columns(position, weight, period):
    phase = 2 * np.pi * position / period
    return np.column_stack((np.sin(phase), np.cos(phase))) * weight[:, None]


def test_position_scan_is_exact_for_positions_on_the_bin_grid():
    rng = np.random.default_rng(6)
    step, top = 1.0 / 160.0, 1.0 / 2.0  # frequency grid [1/mm]: periods 160/j mm
    # positions on multiples of the bin width the scan will choose
    probe = PositionScan(np.array([0.0, 1.0]), np.ones(2), Nuisance(np.ones((2, 1))), np.zeros((2, 1)), step, top)
    width = 1.0 / (probe.length * step)
    position = width * rng.integers(0, int(40.0 / width), size=3000)
    weight = np.sign(rng.normal(size=position.size))
    nuisance = Nuisance(np.column_stack((np.ones(position.size), weight)))
    targets = nuisance.project(rng.normal(size=(position.size, 3)))
    scan = PositionScan(position, weight, nuisance, targets, step, top)
    periods = 1.0 / (step * np.array([4, 7, 19, 50, 80]))
    got = scan.reductions(periods)
    for row, period in enumerate(periods):
        exact = added_squares(_sine_columns(position, weight, period), targets, nuisance)
        np.testing.assert_allclose(got[row], exact, rtol=1e-7)


def test_position_scan_finds_a_hidden_period_and_loses_little_off_the_bin_edges():
    rng = np.random.default_rng(7)
    position = rng.uniform(-20.0, 20.0, size=4000)
    weight = np.ones(position.size)
    nuisance = Nuisance(np.ones((position.size, 1)))
    signal = 0.5 * np.sin(2 * np.pi * position / 4.0 + 0.3)
    targets = nuisance.project((signal + 0.2 * rng.normal(size=position.size))[:, None])
    step = 1.0 / 160.0
    periods = 1.0 / (step * np.arange(4, 161))
    scan = PositionScan(position, weight, nuisance, targets, step, 1.0 / periods.min())
    reductions = scan.reductions(periods)[:, 0]
    assert periods[np.argmax(reductions)] == pytest.approx(4.0)
    exact = added_squares(_sine_columns(position, weight, 4.0), targets, nuisance)[0]
    assert reductions.max() == pytest.approx(exact, rel=0.015)


def test_position_scan_refuses_periods_off_its_grid():
    position = np.linspace(0.0, 10.0, 200)
    scan = PositionScan(position, np.ones(200), Nuisance(np.ones((200, 1))), np.zeros((200, 1)), 0.025, 1.0)
    with pytest.raises(ValueError, match="integer multiples"):
        scan.reductions(np.array([3.3]))
