"""The centred moving window over a signal: one copy for every moving mean and moving RMS of greybox, and for
flags widened on either side."""

from __future__ import annotations

import numpy as np

__all__ = ["centred_mean", "centred_nanmean", "widened"]


def centred_mean(values, width: int, counts=None) -> np.ndarray:
    """Mean of ``values`` over the centred window of ``width`` samples, shortened at both ends of the signal.

    Sample ``i``'s window holds the samples ``i - width // 2`` to ``i - width // 2 + width - 1`` that lie
    inside the signal (a running sum, O(n) whatever the width). With ``counts``, only the samples whose
    count is 1 are averaged, and a window holding none gives 0.

    Parameters
    ----------
    values : array_like, shape (n,)
        Signal, in any unit (the mean is in the same unit).
    width : int
        Window length [samples], at least 1 (1 returns the signal).
    counts : array_like of 0 and 1, shape (n,), optional
        Which samples count; default all.

    Returns
    -------
    ndarray, shape (n,)
    """
    values = np.asarray(values, dtype=float)
    weights = np.ones(values.size) if counts is None else np.asarray(counts, dtype=float)
    total, number = _window_sums(values * weights, weights, width)
    return total / np.maximum(number, 1.0)


def centred_nanmean(values, width: int, *, complete: bool = False) -> np.ndarray:
    """Mean over the centred window of ``width`` samples (as :func:`centred_mean`) of the finite samples only.

    Parameters
    ----------
    values : array_like, shape (n,)
        Signal, in any unit; NaN (or infinity) marks a missing sample.
    width : int
        Window length [samples], at least 1.
    complete : bool, default False
        NaN also where the window holds fewer than ``width`` finite samples (at the ends, next to missing
        ones); else NaN only where it holds none.

    Returns
    -------
    ndarray, shape (n,)
    """
    values = np.asarray(values, dtype=float)
    valid = np.isfinite(values)
    total, number = _window_sums(np.where(valid, values, 0.0), valid.astype(float), width)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(number >= (int(width) if complete else 1), total / np.maximum(number, 1.0), np.nan)


def widened(flags, pad: int) -> np.ndarray:
    """``flags`` widened by ``pad`` samples on either side: true where a flag lies within ``pad`` samples.

    Parameters
    ----------
    flags : array_like of bool, shape (n,)
        The samples flagged.
    pad : int
        Samples added on either side of each flag [samples], at least 0.

    Returns
    -------
    ndarray of bool, shape (n,)
    """
    flags = np.asarray(flags, dtype=bool)
    if not pad or not flags.any():
        return flags
    return np.convolve(flags.astype(float), np.ones(2 * int(pad) + 1), mode="same") > 0.5


def _window_sums(weighted, weights, width: int):
    """Sums of ``weighted`` and of ``weights`` over each sample's centred window of ``width`` (running sums)."""
    if width < 1:
        raise ValueError(f"the window must hold at least one sample, got {width}")
    width = int(width)
    total = np.concatenate(([0.0], np.cumsum(weighted)))
    number = np.concatenate(([0.0], np.cumsum(weights)))
    index = np.arange(weighted.size)
    start = np.clip(index - width // 2, 0, weighted.size)
    stop = np.clip(index - width // 2 + width, 0, weighted.size)
    return total[stop] - total[start], number[stop] - number[start]
