"""The time base of a stream: the nominal step from the first samples, drops, gaps."""

from __future__ import annotations

import numpy as np

from greybox.data.log import AxisLog
from greybox.live.timeline import SETTLE_SAMPLES, Dropped, Gap, Timeline


def samples(times) -> AxisLog:
    times = np.asarray(times, dtype=float)
    return AxisLog(time=times, position=np.zeros(times.size), effort=np.zeros(times.size))


def kept(events) -> np.ndarray:
    return np.concatenate([event.time for event in events if isinstance(event, AxisLog)])


def test_the_nominal_step_is_the_median_of_the_first_samples():
    timeline = Timeline()
    times = 0.002 * np.arange(SETTLE_SAMPLES)
    assert timeline.push(samples(times[:5])) == []  # held until enough steps are in
    events = timeline.push(samples(times[5:]))
    assert abs(timeline.nominal - 0.002) < 1e-12
    np.testing.assert_array_equal(kept(events), times)


def test_backwards_early_and_gap():
    timeline = Timeline(sample_time=0.002, tolerance=0.25)
    events = timeline.push(samples([0.0, 0.002, 0.004, 0.003, 0.004, 0.0045, 0.006, 0.020, 0.022]))
    kinds = [type(event).__name__ for event in events]
    assert kinds == ["AxisLog", "Dropped", "Dropped", "AxisLog", "Gap", "AxisLog"]
    assert events[1] == Dropped(2, 0.003, 0.004, "backwards")  # 3 ms and 4 ms again: both not after 4 ms
    assert events[2].reason == "early" and events[2].count == 1
    assert isinstance(events[4], Gap) and abs(events[4].step_s - 0.014) < 1e-12 and events[4].missing == 6
    np.testing.assert_array_equal(kept(events), [0.0, 0.002, 0.004, 0.006, 0.020, 0.022])


def test_jitter_within_the_tolerance_is_kept():
    timeline = Timeline(sample_time=0.002, tolerance=0.25)
    times = [0.0, 0.0021, 0.0039, 0.0062, 0.008]
    np.testing.assert_array_equal(kept(timeline.push(samples(times))), times)


def test_the_state_is_carried_across_messages():
    timeline = Timeline(sample_time=0.002)
    timeline.push(samples([0.0, 0.002]))
    events = timeline.push(samples([0.002, 0.004]))
    assert isinstance(events[0], Dropped) and events[0].after_s == 0.002


def test_a_short_stream_is_flushed_at_its_own_step():
    timeline = Timeline()
    assert timeline.push(samples([0.0, 0.01, 0.02])) == []
    events = timeline.flush()
    assert timeline.nominal == 0.01 and len(kept(events)) == 3


def test_a_message_within_the_tolerance_is_passed_on_whole_and_one_after_a_gap_is_split():
    timeline = Timeline(sample_time=0.002, tolerance=0.25)
    timeline.push(samples([0.0, 0.002]))
    message = samples([0.0041, 0.006, 0.0079])
    events = timeline.push(message)
    assert len(events) == 1 and events[0] is message
    events = timeline.push(samples([0.020, 0.022]))  # the gap before the message's first sample
    assert [type(event).__name__ for event in events] == ["Gap", "AxisLog"]
    events = timeline.push(samples([0.024, 0.0245, 0.026]))  # too soon inside the message
    assert [type(event).__name__ for event in events] == ["AxisLog", "Dropped", "AxisLog"]
    np.testing.assert_array_equal(kept(events), [0.024, 0.026])


def test_bridged_pieces_are_the_resampled_log_whatever_the_messages():
    from greybox.data.prepare import resample

    rng = np.random.default_rng(1)
    times = 0.002 * np.arange(200) + rng.uniform(-0.6e-3, 0.6e-3, 200)
    log = AxisLog(time=times, position=np.sin(times * 7.0), effort=np.cos(times * 3.0))
    whole = resample(log, 0.002)
    for sizes in ((1,), (10,), (3, 17, 1)):
        timeline, events, start, k = Timeline(sample_time=0.002, max_gap=5.0), [], 0, 0
        while start < len(log):
            stop = min(len(log), start + sizes[k % len(sizes)])
            events += timeline.push(log.select(slice(start, stop)))
            start, k = stop, k + 1
        assert all(isinstance(event, AxisLog) for event in events)
        np.testing.assert_array_equal(kept(events), whole.time)
        np.testing.assert_array_equal(np.concatenate([event.position for event in events]), whole.position)


def test_bridged_drops_backwards_and_splits_only_beyond_max_gap():
    timeline = Timeline(sample_time=0.002, max_gap=5.0)
    events = timeline.push(samples([0.0, 0.002, 0.0015, 0.004, 0.0139, 0.016, 0.0281, 0.030]))
    kinds = [type(event).__name__ for event in events]
    assert kinds == ["Dropped", "AxisLog", "Gap", "AxisLog"]
    assert events[0].count == 1 and events[0].reason == "backwards"
    np.testing.assert_allclose(events[1].time, 0.002 * np.arange(9))  # 9.9 ms bridged: within 5 steps
    assert events[2].time_s == 0.0281  # 12.1 ms: a gap
    np.testing.assert_allclose(events[3].time, [0.0281])  # the new run's grid starts at its first sample
