"""The operating region of training runs: local span, grid, flags chunk by chunk, record check."""

import copy

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from greybox.data.log import AxisLog
from greybox.data.operating import (
    OperatingRegion,
    _span_kernel,
    check_operating_record,
    local_span,
    operating_record,
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
        out = np.empty(position.size)
        kernel(np.concatenate((history, position)), history.size, window, out)
        np.testing.assert_array_equal(out, expected)
    span, _ = local_span(position, window, history if history.size else None)
    np.testing.assert_array_equal(span, expected)


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
])
def test_a_malformed_record_is_refused_naming_the_key(change, word):
    record = copy.deepcopy(operating_record([_run(20.0, 0.25)]))
    change(record)
    with pytest.raises(ValueError, match=word):
        check_operating_record(record)


def test_the_compiled_motion_flags_equal_the_plain_grid_lookup():
    region = _region([_run(20.0, 0.25), _run(5.0, 1.0)])
    run = _run(3.0, 2.0, seconds=6.0)
    flags, _ = region.flags(run, region.start(), sample_time=0.002)
    span = _reference_span(run.position, 250)  # 0.5 s at 2 ms
    speed_edges, span_edges = region.operating["speed_edges"], region.operating["span_edges"]
    seen = {tuple(cell) for cell in region.operating["cells"]}
    plain = [(int(np.searchsorted(speed_edges[1:-1], abs(v), side="right")),
              int(np.searchsorted(span_edges[1:-1], s, side="right"))) not in seen
             for v, s in zip(run.velocity, span)]
    np.testing.assert_array_equal(flags["motion"], plain)
    assert flags["motion"].any() and not flags["motion"].all()
