"""The one centred moving window (greybox.windows) against a plain loop over each sample's window."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.windows import centred_mean, centred_nanmean, widened


def _reference(values, width, counts=None):
    """Each sample's window, summed by a loop: the definition written out."""
    n = len(values)
    counts = np.ones(n) if counts is None else np.asarray(counts, float)
    out = np.empty(n)
    for i in range(n):
        inside = range(max(i - width // 2, 0), min(i - width // 2 + width, n))
        number = sum(counts[k] for k in inside)
        out[i] = sum(values[k] * counts[k] for k in inside) / max(number, 1.0)
    return out


def test_the_mean_is_centred_and_exact_at_the_ends():
    values = np.array([1.0, 2.0, 3.0, 4.0, 10.0])
    np.testing.assert_allclose(centred_mean(values, 3), [1.5, 2.0, 3.0, 17 / 3, 7.0])
    np.testing.assert_array_equal(centred_mean(values, 1), values)
    # a 100 Hz ripple sampled at 2 ms averages out over whole periods
    t = np.arange(5000) * 0.002
    ripple = -0.5 + 0.2 * np.sin(2 * np.pi * 100.0 * t)
    np.testing.assert_allclose(centred_mean(ripple, 50)[100:-100], -0.5, atol=1e-12)


@pytest.mark.parametrize("width", [1, 2, 5, 8, 40])
def test_it_is_the_loop_over_each_window_with_and_without_counts(width):
    rng = np.random.default_rng(width)
    values = rng.normal(size=30)
    counts = rng.random(30) < 0.4
    counts[10:20] = False  # windows holding no counted sample give 0
    np.testing.assert_allclose(centred_mean(values, width), _reference(values, width), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(centred_mean(values, width, counts=counts), _reference(values, width, counts),
                               rtol=1e-12, atol=1e-12)


def test_a_window_of_no_sample_is_refused():
    with pytest.raises(ValueError, match="at least one sample"):
        centred_mean([1.0, 2.0], 0)


def test_the_nan_mean_leaves_missing_samples_out_and_says_where_a_window_is_short():
    values = np.arange(10.0)
    values[4] = np.nan
    out = centred_nanmean(values, 3)
    assert out[1] == pytest.approx(1.0) and out[4] == pytest.approx(4.0)  # (3 + 5) / 2
    finite = np.isfinite(values)
    np.testing.assert_allclose(out, _reference(np.where(finite, values, 0.0), 3, finite), rtol=1e-12)
    complete = centred_nanmean(values, 3, complete=True)
    assert np.isnan(complete[[0, 3, 4, 5, 9]]).all() and complete[1] == pytest.approx(1.0)
    assert np.isnan(centred_nanmean(np.full(5, np.nan), 3)).all()


@pytest.mark.parametrize("pad", [0, 1, 3])
def test_widened_flags_are_the_loop_over_each_sample_within_pad(pad):
    flags = np.random.default_rng(pad).random(40) < 0.1
    flags[0] = flags[-1] = True  # flags at both ends: the widening stops at the signal's edges
    expected = [bool(flags[max(0, i - pad):i + pad + 1].any()) for i in range(flags.size)]
    assert widened(flags, pad).tolist() == expected
    assert widened(np.zeros(5, dtype=bool), 2).tolist() == [False] * 5
