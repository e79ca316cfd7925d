"""The centred moving window over a signal: one copy for every moving mean and moving RMS of greybox."""

from __future__ import annotations

import numpy as np

__all__ = ["centred_mean"]


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
    if width < 1:
        raise ValueError(f"the window must hold at least one sample, got {width}")
    weights = np.ones(values.size) if counts is None else np.asarray(counts, dtype=float)
    total = np.concatenate(([0.0], np.cumsum(values * weights)))
    number = np.concatenate(([0.0], np.cumsum(weights)))
    index = np.arange(values.size)
    start = np.clip(index - width // 2, 0, values.size)
    stop = np.clip(index - width // 2 + width, 0, values.size)
    return (total[stop] - total[start]) / np.maximum(number[stop] - number[start], 1.0)
