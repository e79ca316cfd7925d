"""The causal derivative of ``--latency low`` against a plain-Python reference, its delay, and the stream's use."""

from __future__ import annotations

import io

import numpy as np
import pytest
from live_helpers import EXAMPLE_AXIS, joined, json_batches
from scipy.signal import sosfilt, sosfilt_zi

from greybox.data.prepare import derivative_filter
from greybox.live.causal import CausalStream, causal_cutoff, causal_differences, group_delay_samples
from greybox.live.run import run_live

STEP = 0.002


def lead_of(sos, step, differences):
    """The velocity's lead with two differences: the delay of the first difference [s]."""
    return group_delay_samples(sos, 1) * step if differences == 2 else 0.0


def causal_reference(sos, x, step, differences):
    """scipy's causal filter from the steady state of the first value, then backward differences; with two, the
    first led by its delay times the second."""
    filtered = sosfilt(sos, x, zi=sosfilt_zi(sos) * x[0])[0]
    first = np.diff(filtered, prepend=x[0]) / step
    if differences == 1:
        return np.array([first])
    second = np.diff(first, prepend=0.0) / step
    return np.array([first + lead_of(sos, step, 2) * second, second])


def causal_loop_reference(sos, x, step, differences):
    """Plain Python: direct form II transposed section by section from the first value's steady state, then
    backward differences, sample by sample."""
    state = [list(row * x[0]) for row in sosfilt_zi(sos)]
    lead = lead_of(sos, step, differences)
    last, last_first, out = x[0], 0.0, [[] for _ in range(differences)]
    for value in x:
        for s in range(len(sos)):
            b0, b1, b2, _, a1, a2 = sos[s]
            y = b0 * value + state[s][0]
            state[s][0] = b1 * value - a1 * y + state[s][1]
            state[s][1] = b2 * value - a2 * y
            value = y
        first = (value - last) / step
        if differences == 2:
            second = (first - last_first) / step
            out[0].append(first + lead * second)
            out[1].append(second)
        else:
            out[0].append(first)
        last, last_first = value, first
    return np.array(out)


@pytest.fixture(scope="module")
def sos():
    return derivative_filter(STEP)[0]


def signal(n, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * STEP
    return 50.0 * np.sin(2 * np.pi * 0.7 * t) + np.cumsum(rng.normal(0.0, 0.05, n))


@pytest.mark.parametrize("differences", [1, 2])
def test_kernel_equals_the_reference_whatever_the_messages(sos, differences):
    x = signal(700)
    expected = causal_reference(sos, x, STEP, differences)
    np.testing.assert_allclose(causal_loop_reference(sos, x, STEP, differences), expected, rtol=1e-12, atol=1e-9)
    stream, start, got = CausalStream(sos, sample_time=STEP, differences=differences), 0, []
    for size in (1, 10, 7, 250, 3, 429):
        stream.push(x[start:start + size])
        got.append(np.array(stream.derivatives(start, start + size, final=False)))
        start += size
    np.testing.assert_allclose(np.concatenate(got, axis=1), expected, rtol=1e-12, atol=1e-9)
    state, previous = sosfilt_zi(sos) * x[0], np.array([x[0], 0.0])
    np.testing.assert_allclose(causal_differences(sos, state, previous, x, STEP, differences,
                                                  lead_of(sos, STEP, differences)), expected,
                               rtol=1e-12, atol=1e-9)


def test_the_stated_delay_is_the_lag_of_a_ramp(sos):
    """On a ramp in velocity (constant acceleration) the causal derivative of the velocity settles to the slope;
    on a slow sine it lags the true derivative by the stated group delay."""
    delay = group_delay_samples(sos, 1)
    assert 4.0 < delay < 5.0  # 4th-order Butterworth at 50 Hz, 2 ms: its zero-frequency group delay + half a step
    t = np.arange(5000) * STEP
    omega = 2 * np.pi * 0.5
    derivative = causal_reference(sos, np.sin(omega * t), STEP, 1)[0][1000:]
    lagged = omega * np.cos(omega * (t[1000:] - delay * STEP))
    assert np.max(np.abs(derivative - lagged)) < 1e-3 * omega
    assert np.max(np.abs(derivative - omega * np.cos(omega * t[1000:]))) > 10 * np.max(np.abs(derivative - lagged))


@pytest.mark.parametrize("cutoff_hz", [50.0, None])
def test_the_led_velocity_of_a_position_has_no_delay(cutoff_hz):
    """With two differences the velocity is led by its delay: on a slow sine it follows the true derivative
    (its residual phase error of second order), far closer than the first difference without the lead, which
    lags by the stated delay."""
    sos = derivative_filter(STEP, cutoff_hz=cutoff_hz or causal_cutoff(STEP))[0]
    t = np.arange(5000) * STEP
    omega = 2 * np.pi * 0.5
    position = np.sin(omega * t)
    stream = CausalStream(sos, sample_time=STEP, differences=2)
    stream.push(position)
    velocity = stream.derivatives(0, t.size, final=False)[0][1000:]
    true = omega * np.cos(omega * t[1000:])
    unled = causal_reference(sos, position, STEP, 1)[0][1000:]
    assert np.max(np.abs(velocity - true)) < 0.02 * np.max(np.abs(unled - true))
    assert stream.lead == pytest.approx(group_delay_samples(sos, 1) * STEP)


def test_the_causal_cutoff_is_its_fraction_of_nyquist_and_shortens_the_delay(sos):
    assert causal_cutoff(STEP) == pytest.approx(0.9 * 250.0)
    default = derivative_filter(STEP, cutoff_hz=causal_cutoff(STEP))[0]
    assert group_delay_samples(default, 1) < 0.25 * group_delay_samples(sos, 1)


def test_low_latency_estimates_come_with_their_message(model_file, cut_raw):
    out, said = io.StringIO(), []
    messages = json_batches(cut_raw, (10,))
    outcome = run_live(model_file("gms"), source="-", axis_config_path=EXAMPLE_AXIS, sample_time=STEP,
                       latency="low", stdin=io.StringIO("\n".join(messages)), stdout=out, say=said.append)
    lines = out.getvalue().splitlines()
    assert len(lines) == len(messages) and '"seq":0' in lines[0]  # every message answered by itself
    table = joined(lines)
    np.testing.assert_array_equal(table["time_s"], cut_raw.time)
    assert outcome.stats.samples_estimated == len(cut_raw)
    delay = group_delay_samples(derivative_filter(STEP, cutoff_hz=causal_cutoff(STEP))[0], 1)  # a logged velocity
    assert any("causal derivatives" in line and f"acceleration lags by {delay:.3g} samples ({2 * delay:.3g} ms)"
               in line for line in said)
