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
