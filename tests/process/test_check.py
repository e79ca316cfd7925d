"""A part against its envelope: the kinds of stretch, where they lie, the whole part's deviation."""

from __future__ import annotations

import numpy as np
import pytest
from process_parts import good_parts, make_part

from greybox.process.check import check_part
from greybox.process.envelope import Envelope


@pytest.fixture(scope="module")
def envelope():
    return Envelope(false_alarm_rate=1e-3).fit(good_parts(15, seed=7))


def test_good_parts_pass(envelope):
    assert not any(check_part(envelope, part).flagged for part in good_parts(20, seed=8))


def test_a_breakage_is_a_missing_cut_from_the_moment_it_breaks(envelope):
    part = make_part(3, np.random.default_rng(1), wait_s=1.05, break_at_s=4.0)
    done = check_part(envelope, part)
    assert done.flagged and "missing cut" in done.kinds
    first = next(s for s in done.stretches if s.kind == "missing cut")
    assert first.start_s == pytest.approx(4.0, abs=0.2)
    assert done.mean_kind == "drop"


def test_a_load_in_air_is_an_extra_cut_and_a_heavier_cut_a_rise(envelope):
    bumped = check_part(envelope, make_part(4, np.random.default_rng(2), wait_s=1.0, bump_at_s=8.0))
    over = [s for s in bumped.stretches if s.end_s > 7.9 and s.start_s < 8.4]  # the stretches over the bump
    assert [s.kind for s in over] == ["extra cut"] and over[0].start_s == pytest.approx(8.0, abs=0.2)
    heavy = check_part(envelope, make_part(5, np.random.default_rng(3), cut=1.5))
    assert heavy.mean_kind == "rise" and set(heavy.kinds) <= {"rise"}
    light = check_part(envelope, make_part(6, np.random.default_rng(4), cut=0.0))
    assert light.mean_kind == "drop" and "missing cut" in light.kinds
    slight = check_part(envelope, make_part(7, np.random.default_rng(5), cut=1.02))  # the part mean sees 2 %
    assert slight.mean_kind == "rise" and slight.deviation == pytest.approx(0.02, abs=0.005)


def test_nc_block_numbers_align_a_part_whose_dwell_is_longer_which_the_shift_cannot():
    rng = np.random.default_rng(12)
    teach = [make_part(k, rng, wait_s=float(rng.uniform(1.0, 1.1)), blocks=True) for k in range(1, 11)]
    slow = make_part(11, rng, wait_s=1.05, dwell_s=0.9, blocks=True)  # the return stroke 0.4 s later
    by_blocks = Envelope().fit(teach)
    assert by_blocks.blocks_ and not check_part(by_blocks, slow).flagged
    plain = [make_part(p.number, rng, wait_s=1.05) for p in teach]  # no block column: aligned by the shift
    by_shift = Envelope().fit(plain)
    assert not by_shift.blocks_ and check_part(by_shift, make_part(11, rng, wait_s=1.05, dwell_s=0.9)).flagged
    broken = make_part(12, rng, wait_s=1.05, dwell_s=0.9, break_at_s=4.0, blocks=True)
    found = check_part(by_blocks, broken)
    assert "missing cut" in found.kinds and found.stretches[0].start_s == pytest.approx(4.0, abs=0.06)
