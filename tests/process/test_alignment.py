"""Finding the parts of a long log, and the shift of one part against another."""

from __future__ import annotations

import numpy as np
import pytest
from process_parts import DT, program_velocity

from greybox.errors import GreyboxError
from greybox.process.alignment import best_shift, part_slices, shifted


def test_a_part_counter_splits_a_log_where_its_value_changes():
    counter = np.repeat([3.0, 4.0, 5.0], [10, 20, 5])
    slices = part_slices(np.ones(35), counter=counter, sample_time=DT)
    assert [(s.start, s.stop) for s in slices] == [(0, 10), (10, 30), (30, 35)]


def test_without_a_counter_a_log_is_split_at_rests_longer_than_the_minimum():
    one = program_velocity(wait_s=3.0)
    log = np.concatenate([one, one, one])
    slices = part_slices(log, sample_time=DT, min_rest_s=2.0)
    assert len(slices) == 3  # the 0.5 s rests inside a part do not split it
    starts = [s.start for s in slices]
    assert starts[1] - starts[0] == one.size and starts[2] - starts[1] == one.size
    assert all(np.abs(log[s]).max() > 0 for s in slices)
    assert part_slices(np.zeros(100), sample_time=DT) == []


def test_best_shift_finds_the_timing_difference_within_its_bound():
    reference = program_velocity(wait_s=1.0)
    later = program_velocity(wait_s=1.07)  # 35 samples later
    assert best_shift(reference, later, 100) == 35
    assert best_shift(later, reference, 100) == -35
    assert abs(best_shift(reference, later, 10)) <= 10  # bounded
    with pytest.raises(GreyboxError):
        best_shift([], later, 10)


def test_shifted_lays_a_part_on_the_reference_grid_with_nan_outside():
    values = np.arange(10.0)
    np.testing.assert_array_equal(shifted(values, 3, 5), [3, 4, 5, 6, 7])
    out = shifted(values, -2, 4)
    assert np.isnan(out[:2]).all() and list(out[2:]) == [0.0, 1.0]
    assert np.isnan(shifted(values, 8, 4)[2:]).all()


def test_block_positions_stretch_each_block_of_the_part_onto_the_reference():
    from greybox.process.alignment import block_positions, warped

    reference = np.array([1, 1, 2, 2, 2, 2, 1, 1.0])  # block 1 runs twice: matched run by run
    part = np.array([1, 2, 2, 2, 2, 2, 2, 2, 2, 1, 1, 1.0])
    positions = block_positions(reference, part)
    np.testing.assert_allclose(positions[:2], [-0.25, 0.25])  # one sample for two
    np.testing.assert_allclose(positions[2:6], [1.5, 3.5, 5.5, 7.5])  # eight samples for four
    np.testing.assert_allclose(positions[6:], [9.25, 10.75])
    np.testing.assert_allclose(warped(np.arange(12.0), positions), np.clip(positions, 0, 11))
    lacking = block_positions(reference, np.array([1, 1, 1.0]))
    assert np.isnan(lacking[2:]).all() and np.isfinite(lacking[:2]).all()
