"""Position references: filtered random signals and references from logs."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.control.references import STROKES_MM, filtered_random_reference, reference_from_log, stroke_reference
from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError, LogError


def test_stroke_start_and_seed():
    ref = filtered_random_reference(0.3, 20.0, 5, start_mm=-12.0)
    assert np.ptp(ref.position) == pytest.approx(0.3, rel=1e-12)
    assert ref.position[0] == -12.0
    assert abs(ref.velocity[0]) < 1e-4 * np.max(np.abs(ref.velocity))  # starts practically at rest
    again = filtered_random_reference(0.3, 20.0, 5, start_mm=-12.0)
    np.testing.assert_array_equal(ref.position, again.position)
    other = filtered_random_reference(0.3, 20.0, 6, start_mm=-12.0)
    assert not np.allclose(ref.position, other.position)
    assert len(ref) == 10001 and ref.sample_time == pytest.approx(0.002)


def test_the_spectrum_is_that_of_a_1_hz_fourth_order_low_pass():
    from scipy.signal import welch

    ref = filtered_random_reference(1.0, 400.0, 2)
    frequency, spectrum = welch(ref.position, fs=1.0 / ref.sample_time, nperseg=8192)

    def band(low, high):
        return np.mean(spectrum[(frequency >= low) & (frequency < high)])

    # flat pass band, -24 dB per octave above the corner: a factor 2 in frequency is a factor 256 in power
    assert band(0.1, 0.5) / band(0.5, 0.8) == pytest.approx(1.0, abs=0.35)
    assert band(3.8, 4.2) / band(7.6, 8.4) == pytest.approx(256.0, rel=0.35)


def test_derivatives_are_consistent_with_the_position():
    ref = filtered_random_reference(2.0, 30.0, 1)
    step = ref.sample_time
    # trapezoidal integral of the velocity returns the position
    position = ref.position[0] + np.concatenate(
        ([0.0], np.cumsum(0.5 * step * (ref.velocity[1:] + ref.velocity[:-1]))))
    np.testing.assert_allclose(position, ref.position, atol=1e-4 * np.ptp(ref.position))
    velocity = ref.velocity[0] + np.concatenate(
        ([0.0], np.cumsum(0.5 * step * (ref.acceleration[1:] + ref.acceleration[:-1]))))
    np.testing.assert_allclose(velocity, ref.velocity, atol=1e-3 * np.ptp(ref.velocity))


def test_low_and_high_stroke():
    low, high = stroke_reference("low", 30.0, seed=1), stroke_reference("high", 30.0, seed=1)
    assert (low.name, high.name) == ("low-stroke", "high-stroke")
    assert np.ptp(low.position) == pytest.approx(STROKES_MM["low"])
    assert np.ptp(high.position) == pytest.approx(STROKES_MM["high"])
    assert not np.allclose(low.position / STROKES_MM["low"], high.position / STROKES_MM["high"])
    # the low stroke moves below the Stribeck velocity of a few mm/s, the high stroke far above it
    assert np.max(np.abs(low.velocity)) < 2.0 < 10.0 < np.max(np.abs(high.velocity))
    with pytest.raises(GreyboxError, match="unknown reference"):
        stroke_reference("medium")


@pytest.mark.parametrize("kwargs, message", [
    ({"stroke_mm": 0.0}, "stroke"), ({"duration_s": 0.01}, "duration"), ({"cutoff_hz": 300.0}, "cut-off"),
])
def test_bad_settings(kwargs, message):
    settings = {"stroke_mm": 1.0, "duration_s": 10.0, "seed": 0, **kwargs}
    with pytest.raises(GreyboxError, match=message):
        filtered_random_reference(**settings)


def test_reference_from_a_prepared_log(make_log):
    raw = make_log(n=500).replace(time=np.arange(500) * 0.002 + 3.0, source="run7.csv")
    with pytest.raises(LogError, match="not prepared"):
        reference_from_log(raw)
    (log,) = prepare(raw)
    ref = reference_from_log(log)
    assert ref.name == "run7" and ref.time[0] == 0.0
    np.testing.assert_array_equal(ref.position, log.position)
    np.testing.assert_array_equal(ref.acceleration, log.acceleration)
    back = ref.to_log()
    assert isinstance(back, AxisLog) and back.is_prepared and np.all(back.effort == 0.0)
