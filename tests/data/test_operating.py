"""The operating region of training runs: local span, grid, flags chunk by chunk, record check."""

import copy
import functools
from collections import Counter

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from greybox.data.log import AxisLog
from greybox.data.operating import (
    OperatingRegion,
    _reversal_kernel,
    _span_kernel,
    _window_count_kernel,
    check_operating_record,
    local_span,
    operating_record,
    reversal_marks,
    trailing_reversals,
)


def _run(amplitude: float, frequency: float, seconds: float = 20.0, step: float = 0.002) -> AxisLog:
    time = np.arange(int(seconds / step)) * step
    position = amplitude * np.sin(2 * np.pi * frequency * time)
    velocity = 2 * np.pi * frequency * amplitude * np.cos(2 * np.pi * frequency * time)
    acceleration = np.gradient(velocity, step)
    return AxisLog(time=time, position=position, effort=np.sign(velocity), velocity=velocity,
                   acceleration=acceleration)


def _reference_span(position, samples):
    return np.array([np.ptp(position[max(k - samples + 1, 0):k + 1]) for k in range(len(position))])


def _reference_kernel(position, history, window):
    """The plain-Python reference of the compiled running span: ``max - min`` over each trailing window of
    ``history`` then ``position``, scanned sample by sample (O(window) a sample)."""
    values = list(history) + list(position)
    out = []
    for t in range(len(history), len(values)):
        seen = values[max(t - window + 1, 0):t + 1]
        out.append(max(seen) - min(seen))
    return np.array(out)


@settings(max_examples=60, deadline=None)
@given(values=st.lists(st.floats(-1e6, 1e6, allow_nan=False), min_size=1, max_size=80),
       repeats=st.integers(1, 3), window=st.integers(1, 40), cut=st.integers(0, 120))
def test_the_running_span_equals_the_plain_windows_on_random_data(values, repeats, window, cut):
    """Exactly equal (the same subtraction of the same two samples), also with the compiler off (``py_func``,
    what NUMBA_DISABLE_JIT=1 runs), with ties (repeated values) and with a history shorter or longer than the
    window."""
    sequence = np.repeat(np.asarray(values), repeats)
    history, position = sequence[:min(cut, sequence.size - 1)], sequence[min(cut, sequence.size - 1):]
    expected = _reference_kernel(position, history, window)
    for kernel in (_span_kernel, getattr(_span_kernel, "py_func", _span_kernel)):
        ring, queues, counters = np.zeros(window), np.zeros((2, window), dtype=np.int64), np.zeros(5, np.int64)
        kernel(history, ring, queues, counters, np.empty(history.size))
        out = np.empty(position.size)
        kernel(position, ring, queues, counters, out)
        np.testing.assert_array_equal(out, expected)
    state = local_span(history, window)[1] if history.size else None
    span, _ = local_span(position, window, state)
    np.testing.assert_array_equal(span, expected)


def _reference_reversals(position, deadband):
    """The plain-Python reference of the compiled reversal detector: a reversal is confirmed where the
    position lies ``deadband`` behind the furthest point of the current stroke; the first move by
    ``deadband`` from the range seen so far sets the direction without a reversal."""
    marks, direction, extreme, high, low = [], 0, None, None, None
    for x in position:
        mark = False
        if extreme is None:
            extreme = high = low = x
        if direction == 0:
            high, low = max(high, x), min(low, x)
            if x - low >= deadband:
                direction, extreme = 1, x
            elif high - x >= deadband:
                direction, extreme = -1, x
        elif direction * (x - extreme) > 0:
            extreme = x
        elif direction * (extreme - x) >= deadband:
            mark, direction, extreme = True, -direction, x
        marks.append(mark)
    return np.array(marks, dtype=bool)


@settings(max_examples=60, deadline=None)
@given(steps=st.lists(st.floats(-3.0, 3.0, allow_nan=False), min_size=1, max_size=200),
       deadband=st.floats(0.05, 4.0), cuts=st.lists(st.integers(0, 200), max_size=3), window=st.integers(1, 30))
def test_the_reversals_equal_the_plain_detector_and_carry_across_chunks(steps, deadband, cuts, window):
    """The compiled detector (and with the compiler off, ``py_func``) marks the reversals the plain one does;
    chunk by chunk (its state carried) the same marks and window counts as the whole run at once."""
    position = np.cumsum(np.round(steps, 1))  # ties: equal positions and turns of exactly the deadband
    expected = _reference_reversals(position, deadband)
    whole, _ = reversal_marks(position, deadband)
    np.testing.assert_array_equal(whole, expected)
    plain = np.zeros(position.size, dtype=bool)
    getattr(_reversal_kernel, "py_func", _reversal_kernel)(position, deadband, np.full(4, np.nan), plain)
    np.testing.assert_array_equal(plain, expected)
    count, _ = trailing_reversals(whole, window)
    np.testing.assert_array_equal(count, [expected[max(k - window + 1, 0):k + 1].sum() for k in range(position.size)])
    plain_count = np.empty(position.size, dtype=np.int64)
    getattr(_window_count_kernel, "py_func", _window_count_kernel)(whole, np.zeros(window, dtype=bool),
                                                                   np.zeros(2, dtype=np.int64), plain_count)
    np.testing.assert_array_equal(plain_count, count)
    marks, counts, detector, history = [], [], None, None
    for piece in np.array_split(position, sorted(set(cuts))):
        part, detector = reversal_marks(piece, deadband, detector)
        part_count, history = trailing_reversals(part, window, history)
        marks.append(part)
        counts.append(part_count)
    np.testing.assert_array_equal(np.concatenate(marks), expected)
    np.testing.assert_array_equal(np.concatenate(counts), count)


def test_local_span_matches_the_plain_trailing_window_and_carries_across_chunks():
    rng = np.random.default_rng(0)
    position = np.cumsum(rng.normal(size=500))
    whole, _ = local_span(position, 37)
    np.testing.assert_allclose(whole, _reference_span(position, 37))
    parts, history = [], None
    for piece in np.array_split(position, [5, 6, 100, 333]):
        span, history = local_span(piece, 37, history)
        parts.append(span)
    np.testing.assert_allclose(np.concatenate(parts), whole)


def _region(runs):
    ranges = {channel: [float(min(getattr(r, channel).min() for r in runs)),
                        float(max(getattr(r, channel).max() for r in runs))]
              for channel in ("position", "velocity", "acceleration")}
    return OperatingRegion(ranges, check_operating_record(operating_record(runs)))


def test_small_oscillations_never_trained_on_lie_outside_and_a_run_of_the_same_kind_inside():
    region = _region([_run(20.0, 0.25), _run(40.0, 0.25)])
    same_kind, _ = region.flags(_run(30.0, 0.25), region.start(), sample_time=0.002)
    assert np.mean(np.logical_or.reduce(list(same_kind.values()))) < 0.05
    tiny, _ = region.flags(_run(0.3, 2.0), region.start(), sample_time=0.002)
    assert np.mean(tiny["motion"][500:]) > 0.9  # once the window holds only the oscillation


def _tapered(amplitude: float, frequency: float, step: float = 1 / 1024) -> AxisLog:
    """Seven periods under the envelope of the ARTS harmonic tests (two rising, three full, two falling)."""
    time = np.arange(int(7 / frequency / step)) * step
    envelope = np.clip(np.minimum(time, time[-1] - time) * frequency / 2, 0.0, 1.0)
    position = amplitude * envelope * np.sin(2 * np.pi * frequency * time)
    velocity = np.gradient(position, step)
    return AxisLog(time=time, position=position, effort=np.sign(velocity), velocity=velocity,
                   acceleration=np.zeros(time.size))


def test_small_fast_oscillations_lie_outside_slow_tapered_ones_of_the_same_span_by_their_reversals():
    """The regime of issue 40 point 4: the tapered starts of slow harmonic tests pass through every small
    amplitude, so the (speed, span) grid holds small spans; four reversals a second at 0.4 mm are not what
    they showed, one every two seconds. Without the rule (a format-4 record) most of them pass as inside."""
    training = [_tapered(20.0, 0.25), _tapered(40.0, 0.25)]
    region = _region(training)
    fast = _run(0.2, 2.0, step=1 / 1024)
    flags, _ = region.flags(fast, region.start(), sample_time=fast.sample_time)
    assert np.mean(flags["motion"][1024:]) > 0.95
    record = copy.deepcopy(region.operating)
    record.pop("reversals")
    grid_only = OperatingRegion(region.ranges, check_operating_record(record))
    before, _ = grid_only.flags(fast, grid_only.start(), sample_time=fast.sample_time)
    assert np.mean(before["motion"][1024:]) < 0.5
    slow, _ = region.flags(_tapered(30.0, 0.25), region.start(), sample_time=1 / 1024)
    assert np.mean(slow["motion"]) < 0.01


def test_flags_chunk_by_chunk_equal_the_whole_run():
    region = _region([_run(20.0, 0.25)])
    run = _run(0.5, 1.0, seconds=4.0)
    whole, _ = region.flags(run, region.start(), sample_time=0.002)
    state, parts = region.start(), []
    for samples in (slice(0, 3), slice(3, 700), slice(700, None)):
        flags, state = region.flags(run.select(samples), state, sample_time=0.002)
        parts.append(flags)
    for name, values in whole.items():
        np.testing.assert_array_equal(np.concatenate([part[name] for part in parts]), values)


@pytest.mark.parametrize("change, word", [
    (lambda r: r.pop("cells"), "exactly"),
    (lambda r: r.update(window_s=0.0), "window_s"),
    (lambda r: r.update(window_s=True), "window_s"),
    (lambda r: r["speed_edges"].reverse(), "increasing"),
    (lambda r: r["span_edges"].__setitem__(0, float("nan")), "finite"),
    (lambda r: r["cells"].append([99, 0]), "within the grid"),
    (lambda r: r["cells"].append([0, True]), "within the grid"),
    (lambda r: r.update(cells="all"), "cells"),
    (lambda r: r.update(reversals=r["reversals"][:-1]), "reversals"),
    (lambda r: r["reversals"].__setitem__(0, -2), "reversals"),
    (lambda r: r["reversals"].__setitem__(0, True), "reversals"),
    (lambda r: r["reversals"].__setitem__(0, 1.0), "reversals"),
    (lambda r: r.update(reversals={}), "reversals"),
    (lambda r: r.update(turns=[]), "exactly"),
])
def test_a_malformed_record_is_refused_naming_the_key(change, word):
    record = copy.deepcopy(operating_record([_run(20.0, 0.25)]))
    change(record)
    with pytest.raises(ValueError, match=word):
        check_operating_record(record)


def test_the_compiled_motion_flags_equal_the_plain_grid_lookup():
    training = [_run(20.0, 0.25), _run(5.0, 1.0)]
    region = _region(training)
    run = _run(3.0, 2.0, seconds=6.0)
    flags, _ = region.flags(run, region.start(), sample_time=0.002)
    speed_edges, span_edges = region.operating["speed_edges"], region.operating["span_edges"]

    def plain_cells(log):
        span = _reference_span(log.position, 250)  # 0.5 s at 2 ms
        turns = _reference_reversals(log.position, span_edges[0])
        count = [turns[max(k - 249, 0):k + 1].sum() for k in range(turns.size)]
        return [(int(np.searchsorted(speed_edges[1:-1], abs(v), side="right")),
                 int(np.searchsorted(span_edges[1:-1], s, side="right")), c)
                for v, s, c in zip(log.velocity, span, count)]

    samples = [cell for log in training for cell in plain_cells(log)]
    seen = {tuple(cell) for cell in region.operating["cells"]}
    occupied = Counter((i, j) for i, j, _ in samples)
    assert seen == {cell for cell, n in occupied.items() if n >= 5}
    most = [sorted((c for _, b, c in samples if b == j), reverse=True) for j in range(len(span_edges) - 1)]
    assert region.operating["reversals"] == [cs[4] if len(cs) >= 5 else -1 for cs in most]
    plain = [(i, j) not in seen or c > region.operating["reversals"][j] for i, j, c in plain_cells(run)]
    np.testing.assert_array_equal(flags["motion"], plain)
    assert flags["motion"].any() and not flags["motion"].all()


@functools.cache
def _trained_region(reversals: bool) -> OperatingRegion:
    """The region of two sine runs; without ``reversals``, as a model file of format version 4 holds it."""
    training = [_run(20.0, 0.25), _run(5.0, 1.0)]
    region = _region(training)
    operating = {key: value for key, value in region.operating.items() if reversals or key != "reversals"}
    return OperatingRegion(region.ranges, check_operating_record(operating))


def _plain_motion(region: OperatingRegion, log: AxisLog, window: int) -> np.ndarray:
    """The plain-Python reference of the motion flags: a window's span and reversals sample by sample."""
    speed_edges, span_edges = region.operating["speed_edges"], region.operating["span_edges"]
    seen = {tuple(cell) for cell in region.operating["cells"]}
    span = _reference_kernel(log.position, [], window)
    turns = _reference_reversals(log.position, span_edges[0])
    most = region.operating.get("reversals")
    out = []
    for k, (v, s) in enumerate(zip(log.velocity, span)):
        i = int(np.searchsorted(speed_edges[1:-1], abs(v), side="right"))
        j = int(np.searchsorted(span_edges[1:-1], s, side="right"))
        count = int(turns[max(k - window + 1, 0):k + 1].sum())
        out.append((i, j) not in seen or (most is not None and count > most[j]))
    return np.array(out, dtype=bool)


@settings(max_examples=40, deadline=None)
@given(amplitudes=st.lists(st.floats(0.05, 25.0), min_size=1, max_size=3),
       frequencies=st.lists(st.floats(0.05, 6.0), min_size=3, max_size=3),
       samples=st.integers(1, 400), cuts=st.lists(st.integers(0, 400), max_size=8), reversals=st.booleans())
def test_flags_are_the_plain_ones_whatever_the_chunks(amplitudes, frequencies, samples, cuts, reversals):
    """Any split of a run into chunks (single samples, empty chunks, chunks longer than the window) gives the
    flags of the whole run and of the plain reference, for records with the reversal rule and without it
    (format 4); run with NUMBA_DISABLE_JIT=1 too."""
    region = _trained_region(reversals)
    step = 0.01  # a window of 50 samples: runs of a few hundred cross it many times
    time = np.arange(samples) * step
    position = sum(a * np.sin(2 * np.pi * f * time) for a, f in zip(amplitudes, frequencies))
    velocity = sum(2 * np.pi * f * a * np.cos(2 * np.pi * f * time) for a, f in zip(amplitudes, frequencies))
    run = AxisLog(time=time, position=position, effort=np.sign(velocity), velocity=velocity,
                  acceleration=np.zeros(samples))
    whole, _ = region.flags(run, region.start(), sample_time=step)
    np.testing.assert_array_equal(whole["motion"], _plain_motion(region, run, 50))
    state, parts, bounds = region.start(), [], [0, *sorted(min(cut, samples) for cut in cuts), samples]
    for first, last in zip(bounds, bounds[1:]):
        flags, state = region.flags(run.select(slice(first, last)), state, sample_time=step)
        parts.append(flags)
    for name, values in whole.items():
        np.testing.assert_array_equal(np.concatenate([part[name] for part in parts]), values)
