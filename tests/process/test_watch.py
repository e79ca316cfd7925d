"""A part watched while it is cut finds, block by block, what the check of the whole part finds."""

from __future__ import annotations

import numpy as np
import pytest
from process_parts import good_parts, make_part

from greybox.process.check import check_part
from greybox.process.envelope import Envelope
from greybox.process.watch import PartWatch


@pytest.fixture(scope="module")
def envelope():
    return Envelope(false_alarm_rate=1e-3).fit(good_parts(15, seed=7))


def _watch(envelope, part, block=40, **options):
    watch, found = PartWatch(envelope, **options), []
    for start in range(0, len(part.time), block):
        piece = slice(start, start + block)
        for breach in watch.update(part.velocity[piece], part.signal[piece]):
            found.append((breach, part.time[min(start + block, len(part.time)) - 1]))  # reported with this block
    return found


def test_a_breakage_is_reported_within_its_smoothing_window(envelope):
    part = make_part(3, np.random.default_rng(1), wait_s=1.05, break_at_s=4.0)
    found = _watch(envelope, part)
    assert found, "the breakage was not seen"
    breach, seen_at = found[0]
    assert breach.kind in ("drop", "missing cut") and breach.start_s == pytest.approx(4.0, abs=0.2)
    assert seen_at <= 4.0 + 0.2  # reported while the part is cut: half a smoothing window and a block late
    whole = check_part(envelope, part)
    assert breach.start_s == pytest.approx(whole.stretches[0].start_s, abs=0.02)


def test_good_parts_raise_nothing_and_a_relevelled_watch_sees_what_the_whole_check_sees():
    teach = good_parts(10, seed=2)
    envelope = Envelope(relevel=True).fit(teach)
    assert not any(_watch(envelope, part) for part in good_parts(5, seed=11))
    rng = np.random.default_rng(4)
    warm = make_part(21, rng, friction=0.8)
    whole = check_part(envelope, warm)
    assert not whole.flagged
    watch = PartWatch(envelope, corrections=whole.offsets)
    for start in range(0, len(warm.time), 40):
        watch.update(warm.velocity[start:start + 40], warm.signal[start:start + 40])
    np.testing.assert_allclose(watch._grid, whole.signal, equal_nan=True)  # block by block = the whole part
    previous = check_part(envelope, make_part(20, rng, friction=0.8)).offsets
    without, with_previous = _watch(envelope, warm), _watch(envelope, warm, corrections=previous)
    assert without and len(with_previous) < len(without)  # the warmer machine leaves the band unless re-levelled


def test_positions_right_after_the_first_motion_are_skipped_when_asked(envelope):
    part = make_part(4, np.random.default_rng(6), wait_s=1.05)
    first = int(np.argmax(np.abs(part.velocity) > 0.5))
    spoiled = part.signal.copy()
    spoiled[first:first + 15] += 5.0  # 0.03 s off after the first motion, as a model started at rest reads
    part = type(part)(part.source, part.number, part.start_s, part.time, part.velocity, spoiled)
    assert _watch(envelope, part)
    assert _watch(envelope, part, skip_s=0.03 + envelope.width_ // 2 * envelope.sample_time_ + 0.01) == []
