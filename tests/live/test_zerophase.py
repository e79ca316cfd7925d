"""The running zero-phase filter and differences against plain-Python references and against ``derive``."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import sosfiltfilt

from greybox.data.log import AxisLog
from greybox.data.prepare import derivative_filter, derivative_margin, derive
from greybox.errors import LogError
from greybox.live.lookahead import Lookahead
from greybox.live.zerophase import ZeroPhaseStream, backward_stretch, central_difference, sos_run

STEP = 0.002


def sos_run_reference(sos, state, x):
    """Direct form II transposed, section by section, sample by sample."""
    out = []
    for value in x:
        for s in range(len(sos)):
            b0, b1, b2, _, a1, a2 = sos[s]
            y = b0 * value + state[s][0]
            state[s][0] = b1 * value - a1 * y + state[s][1]
            state[s][1] = b2 * value - a2 * y
            value = y
        out.append(value)
    return np.array(out)


def backward_stretch_reference(sos, zi, state, tail, forward):
    """Odd extension of the tail, the forward pass continued over it, then backward over it and the stretch."""
    m = len(tail) - 1
    extension = [2.0 * tail[-1] - tail[m - 1 - j] for j in range(m)]
    ahead = sos_run_reference(sos, [list(row) for row in state], extension)
    back = [[zi[s][0] * ahead[-1], zi[s][1] * ahead[-1]] for s in range(len(zi))]
    sos_run_reference(sos, back, ahead[::-1])
    return sos_run_reference(sos, back, list(forward[::-1]))[::-1]


def central_difference_reference(values, step, first_is_start, last_is_end):
    k = len(values)
    out = [(values[i + 1] - values[i - 1]) / (2.0 * step) for i in range(1, k - 1)]
    first = (values[1] - values[0]) / step if first_is_start else np.nan
    last = (values[-1] - values[-2]) / step if last_is_end else np.nan
    return np.array([first, *out, last])


def signal(n, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * STEP
    return 50.0 * np.sin(2 * np.pi * 0.7 * t) + np.cumsum(rng.normal(0.0, 0.05, n)) + rng.normal(0.0, 1e-3, n)


@pytest.fixture(scope="module")
def sos():
    return derivative_filter(STEP)[0]


def test_sos_run_equals_its_reference_and_carries_its_state(sos):
    x = signal(300)
    state = np.full((len(sos), 2), 0.3)
    expected = sos_run_reference(sos, [list(row) for row in state], x)
    whole = sos_run(sos, state.copy(), x)
    np.testing.assert_allclose(whole, expected, rtol=1e-13, atol=1e-12)
    split_state = state.copy()
    parts = np.concatenate([sos_run(sos, split_state, x[:7]), sos_run(sos, split_state, x[7:])])
    np.testing.assert_array_equal(parts, whole)


def test_backward_stretch_equals_its_reference(sos):
    from scipy.signal import sosfilt_zi

    x = signal(120, seed=1)
    zi = sosfilt_zi(sos)
    state = zi * x[0]
    forward = sos_run(sos, state, x)
    got = backward_stretch(sos, zi, state, x[-16:], forward[40:])
    expected = backward_stretch_reference(sos, zi, state, x[-16:], forward[40:])
    np.testing.assert_allclose(got, expected, rtol=1e-13, atol=1e-12)


def test_backward_stretch_over_a_whole_signal_is_sosfiltfilt(sos):
    from scipy.signal import sosfilt_zi

    x = signal(200, seed=2)
    zi = sosfilt_zi(sos)
    head = 2.0 * x[0] - x[15:0:-1]
    state = zi * head[0]
    sos_run(sos, state, head)
    forward = sos_run(sos, state, x)
    np.testing.assert_allclose(backward_stretch(sos, zi, state, x[-16:], forward), sosfiltfilt(sos, x),
                               rtol=0, atol=1e-12 * np.abs(x).max())


@pytest.mark.parametrize("ends", [(True, True), (False, True), (True, False), (False, False)])
def test_central_difference_equals_its_reference_and_numpy(ends):
    values = signal(30, seed=3)
    got = central_difference(values, STEP, *ends)
    np.testing.assert_allclose(got, central_difference_reference(values, STEP, *ends), rtol=1e-15, equal_nan=True)
    whole = np.gradient(values, STEP)
    keep = slice(0 if ends[0] else 1, None if ends[1] else -1)
    np.testing.assert_array_equal(got[keep], whole[keep])
    assert np.isnan(got[0]) != ends[0] and np.isnan(got[-1]) != ends[1]


@pytest.mark.parametrize("differences", [1, 2])
def test_the_stream_gives_what_the_whole_signal_gives(sos, differences):
    x = signal(1500, seed=4)
    stream = ZeroPhaseStream(sos, sample_time=STEP, differences=differences)
    margin = derivative_margin(STEP)
    given, parts = 0, []
    rng = np.random.default_rng(5)
    k = 0
    while k < len(x):
        size = int(rng.integers(1, 30))
        stream.push(x[k:k + size])
        k += size
        ready = stream.received - given - margin
        if stream.started and ready >= 2:
            parts.append(stream.derivatives(given, given + ready, final=False))
            given += ready
    parts.append(stream.derivatives(given, len(x), final=True))
    filtered = sosfiltfilt(sos, x)
    expected = [np.gradient(filtered, STEP)]
    if differences == 2:
        expected.append(np.gradient(expected[0], STEP))
    for order, whole in enumerate(expected):
        got = np.concatenate([part[order] for part in parts])
        np.testing.assert_allclose(got, whole, rtol=0, atol=1e-9 * np.abs(whole).max())


def _log(n, *, velocity):
    t = np.arange(n) * STEP + 3.0
    position = signal(n, seed=6)
    return AxisLog(time=t, position=position, effort=np.cos(t), axis="X", source="stream.csv",
                   velocity=np.gradient(position, STEP) if velocity else None)


@pytest.mark.parametrize("velocity", [False, True])
def test_lookahead_gives_the_derived_log(velocity):
    log = _log(900, velocity=velocity)
    lookahead = Lookahead(sample_time=STEP)
    out = []
    for k in range(0, len(log), 13):
        ready = lookahead.push(log.select(slice(k, k + 13)))
        if ready is not None:
            out.append(ready)
    out.append(lookahead.finish())
    whole = derive(log, sample_time=STEP)
    assert sum(len(part) for part in out) == len(log) and lookahead.waiting == 0
    assert out[0].attrs["derivative_filter"] == whole.attrs["derivative_filter"]
    for name in ("time", "position", "effort", "velocity", "acceleration"):
        got = np.concatenate([getattr(part, name) for part in out])
        expected = getattr(whole, name)
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9 * max(1.0, np.abs(expected).max()), err_msg=name)


def test_lookahead_refuses_a_run_too_short_for_the_filter():
    lookahead = Lookahead(sample_time=STEP)
    assert lookahead.push(_log(10, velocity=False)) is None
    with pytest.raises(LogError, match="needs at least 16"):
        lookahead.finish()
    assert lookahead.waiting == 0


def test_lookahead_gives_the_derived_log_from_messages_of_any_size():
    log = _log(900, velocity=False)
    lookahead = Lookahead(sample_time=STEP)
    out, k = [], 0
    for size in [1, 3, 250, 2, 1, 400, 7, 236]:  # long after short: the buffers grow while samples wait
        ready = lookahead.push(log.select(slice(k, k + size)))
        k += size
        if ready is not None:
            out.append(ready)
    out.append(lookahead.finish())
    whole = derive(log, sample_time=STEP)
    for name in ("time", "position", "effort", "velocity", "acceleration"):
        expected = getattr(whole, name)
        np.testing.assert_allclose(np.concatenate([getattr(part, name) for part in out]), expected, rtol=0,
                                   atol=1e-9 * max(1.0, np.abs(expected).max()), err_msg=name)
