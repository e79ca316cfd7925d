"""Training subsets that cover the (position, velocity) plane."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.models.kernel.subset import coverage_subset, grid_cells


def skewed_log(n=20000, seed=0):
    """Mostly slow motion near the middle, rare fast excursions: a realistic dwell pattern."""
    rng = np.random.default_rng(seed)
    position = np.concatenate([rng.normal(250.0, 20.0, n - 200), rng.uniform(0.0, 500.0, 200)])
    velocity = np.concatenate([rng.normal(0.0, 5.0, n - 200), rng.uniform(-200.0, 200.0, 200)])
    return np.column_stack((position, velocity))


def test_every_occupied_cell_is_represented():
    features = skewed_log()
    chosen = coverage_subset(features, 500, n_bins=15, random_state=1)
    assert chosen.size == 500
    assert np.unique(chosen).size == 500
    assert np.all(np.diff(chosen) > 0)
    cells = grid_cells(features, 15)
    assert set(np.unique(cells[chosen])) == set(np.unique(cells))


def test_quota_is_even_across_cells():
    features = skewed_log()
    chosen = coverage_subset(features, 2000, n_bins=10, random_state=0)
    cells = grid_cells(features, 10)
    available = np.bincount(cells, minlength=100)
    taken = np.bincount(cells[chosen], minlength=100)
    full = taken == available
    # Cells not taken whole all got the same share (within one sample),
    # and that share is at least as large as any cell taken whole.
    share = taken[~full & (available > 0)]
    assert share.max() - share.min() <= 1
    assert share.min() >= taken[full].max()


def test_bins_are_capped_so_a_small_subset_still_covers():
    features = skewed_log()
    chosen = coverage_subset(features, 30, n_bins=50, random_state=0)
    bins = int(np.floor(np.sqrt(30)))
    assert set(np.unique(grid_cells(features, bins)[chosen])) == set(np.unique(grid_cells(features, bins)))


def test_seeded():
    features = skewed_log()
    a = coverage_subset(features, 300, random_state=5)
    b = coverage_subset(features, 300, random_state=5)
    c = coverage_subset(features, 300, random_state=6)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


def test_small_input_returned_whole_and_bad_input_rejected():
    np.testing.assert_array_equal(coverage_subset(np.zeros((5, 2)), 10), np.arange(5))
    with pytest.raises(ValueError, match="n_subset"):
        coverage_subset(np.zeros((5, 2)), 0)
    with pytest.raises(ValueError, match="NaN"):
        coverage_subset(np.array([[0.0, np.nan], [1.0, 2.0], [3.0, 4.0]]), 2)


def test_accuracy_vs_subset_size_reports_each_size():
    from greybox.data.log import AxisLog
    from greybox.models.kernel.subset import accuracy_vs_subset_size
    from greybox.models.svr import SVRCurrentModel

    def run(seed, n=8000):
        rng = np.random.default_rng(seed)
        t = np.arange(n) * 0.002
        p = 200.0 + 150.0 * np.sin(2 * np.pi * 0.13 * t) + 30.0 * np.sin(2 * np.pi * 0.71 * t + seed)
        v = 150.0 * 2 * np.pi * 0.13 * np.cos(2 * np.pi * 0.13 * t) + 30.0 * 2 * np.pi * 0.71 * np.cos(
            2 * np.pi * 0.71 * t + seed)
        current = np.tanh(v / 40.0) + 0.4 * np.sin(2 * np.pi * p / 120.0) + 0.01 * rng.standard_normal(n)
        return AxisLog(time=t, position=p, effort=current, velocity=v, acceleration=np.zeros(n))

    model = SVRCurrentModel(C=3.0, epsilon=0.01, gamma=5.0, optimize=False)
    rows = accuracy_vs_subset_size(model, [run(1), run(2)], run(3), [30, 600])
    assert [r["n_subset"] for r in rows] == [30, 600]
    assert all(r["n"] == 8000 and r["fit_seconds"] >= 0 for r in rows)
    assert rows[1]["rmse"] < 0.5 * rows[0]["rmse"]
    assert model.get_params()["n_subset"] == 2000  # the given model is left untouched
