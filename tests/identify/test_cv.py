"""Time-blocked cross-validation: whole blocks, never across runs."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.identify.cv import blocked_folds, time_blocks


def test_blocks_tile_each_run_and_never_span_two():
    lengths = [1000, 37, 2500]
    blocks = time_blocks(lengths, 10)
    assert len(blocks) == 10
    for run, n in enumerate(lengths):
        own = [b for b in blocks if b.run == run]
        assert own, "every run gets a block"
        assert own[0].start == 0 and own[-1].stop == n
        assert all(a.stop == b.start for a, b in zip(own[:-1], own[1:]))
        sizes = [len(b) for b in own]
        assert max(sizes) - min(sizes) <= 1
    offsets = np.concatenate(([0], np.cumsum(lengths)[:-1]))
    for b in blocks:
        assert b.offset == offsets[b.run]
        idx = b.indices
        assert offsets[b.run] <= idx.min() and idx.max() < offsets[b.run] + lengths[b.run]


def test_more_runs_than_blocks_gives_one_block_per_run():
    assert len(time_blocks([10, 10, 10, 10], 2)) == 4


@pytest.mark.parametrize("gap", [0, 5])
def test_folds_hold_whole_blocks_and_partition_the_samples(gap):
    lengths = [600, 150, 900]
    n_folds, n_blocks = 3, 9
    folds = blocked_folds(lengths, n_folds=n_folds, n_blocks=n_blocks, gap=gap)
    blocks = time_blocks(lengths, n_blocks)
    total = sum(lengths)
    run_of = np.repeat(np.arange(len(lengths)), lengths)
    all_tests = np.concatenate([test for _, test in folds])
    np.testing.assert_array_equal(np.sort(all_tests), np.arange(total))
    for train, test in folds:
        assert np.intersect1d(train, test).size == 0
        in_test = np.zeros(total, bool)
        in_test[test] = True
        for b in blocks:
            # A block is in the test set entirely or not at all.
            assert in_test[b.indices].all() or not in_test[b.indices].any()
        # No training sample lies within `gap` samples of a test sample of the same run.
        for i in train:
            lo, hi = max(0, i - gap), min(total, i + gap + 1)
            neighbours = np.arange(lo, hi)
            neighbours = neighbours[run_of[neighbours] == run_of[i]]
            assert not in_test[neighbours].any()


def test_neighbouring_samples_stay_together():
    # With one run and no gap, the only train/test neighbours are at block edges.
    folds = blocked_folds([1200], n_folds=4, n_blocks=8)
    blocks = time_blocks([1200], 8)
    edges = {b.start for b in blocks} | {b.stop for b in blocks}
    for _, test in folds:
        label = np.zeros(1200, bool)
        label[test] = True
        changes = np.flatnonzero(label[1:] != label[:-1]) + 1
        assert set(changes.tolist()) <= edges


def test_rejects_impossible_settings():
    with pytest.raises(ValueError, match="n_folds"):
        blocked_folds([100], n_folds=1)
    with pytest.raises(ValueError, match="n_blocks"):
        blocked_folds([100], n_folds=3, n_blocks=2)
    with pytest.raises(ValueError, match="too few"):
        time_blocks([3], 5)
