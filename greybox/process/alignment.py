"""Where the parts of a part series are, and how one part lies against another.

A series comes as one log per part or as one long log. A long log is split by its part counter column
(:data:`PART_COLUMN`, as a control logs it) where it has one, else at the rests between the parts: every
stretch at standstill of at least ``min_rest_s`` ends a part (a part's own dwells and reversals must be
shorter).

Two parts of the same program differ by small timing differences (the loading time, the moment the cycle
starts). :func:`best_shift` finds the shift of one part against the reference part that maximises the
cross-correlation of their velocities, bounded to ``max_shift`` samples; :func:`shifted` lays the part on
the reference's sample grid (NaN where it has no sample).
"""

from __future__ import annotations

import numpy as np
from scipy.signal import correlate

from ..errors import GreyboxError
from ..predict.relevel import STANDSTILL_MM_S

__all__ = ["PART_COLUMN", "STANDSTILL_MM_S", "part_slices", "best_shift", "shifted"]

#: Name of the part counter column of a long log.
PART_COLUMN = "part"


def part_slices(velocity, *, counter=None, sample_time: float, min_rest_s: float = 2.0) -> list[slice]:
    """The sample ranges of the parts of a long log.

    Parameters
    ----------
    velocity : array_like, shape (n,)
        Axis velocity [mm/s or deg/s].
    counter : array_like, shape (n,), optional
        Part counter per sample; a part is a run of one value. Without it the log is split at rests.
    sample_time : float
        Sample time [s].
    min_rest_s : float, default 2.0
        Shortest standstill [s] that separates two parts (without a counter); each part starts
        ``min_rest_s / 2`` before its first motion after such a rest.

    Returns
    -------
    list of slice
        One per part, in order; a leading or trailing stretch without motion is no part.
    """
    v = np.asarray(velocity, dtype=float)
    if counter is not None:
        c = np.asarray(counter, dtype=float)
        edges = np.concatenate(([0], np.flatnonzero(np.diff(c) != 0) + 1, [len(c)]))
        return [slice(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]
    moving = np.abs(v) > STANDSTILL_MM_S
    if not moving.any():
        return []
    rest = max(1, int(round(min_rest_s / sample_time)))
    index = np.flatnonzero(moving)
    gaps = np.flatnonzero(np.diff(index) > rest)
    starts = np.concatenate(([index[0]], index[gaps + 1]))
    lead = rest // 2
    bounds = [max(0, int(s) - lead) for s in starts] + [len(v)]
    return [slice(a, b) for a, b in zip(bounds[:-1], bounds[1:])]


def best_shift(reference, signal, max_shift: int) -> int:
    """Shift ``k`` (samples, ``|k| <= max_shift``) for which ``signal[i + k]`` best matches ``reference[i]``.

    Parameters
    ----------
    reference : array_like, shape (m,)
        The reference part's velocity.
    signal : array_like, shape (n,)
        The other part's velocity.
    max_shift : int
        Largest shift tried, in samples.

    Raises
    ------
    GreyboxError
        If either is empty or the shift is negative.
    """
    r, s = np.asarray(reference, dtype=float), np.asarray(signal, dtype=float)
    if r.size == 0 or s.size == 0 or max_shift < 0:
        raise GreyboxError("alignment: empty part or negative largest shift")
    full = correlate(s, r, mode="full", method="fft")  # full[j] pairs s[i + j - (m - 1)] with r[i]
    lags = np.arange(-(r.size - 1), s.size)
    allowed = np.abs(lags) <= max_shift
    return int(lags[allowed][np.argmax(full[allowed])])


def shifted(values, shift: int, length: int) -> np.ndarray:
    """``values[i + shift]`` for ``i`` in ``range(length)``, NaN where that index falls outside.

    Parameters
    ----------
    values : array_like, shape (n,)
        A part's samples.
    shift : int
        Shift from :func:`best_shift` [samples].
    length : int
        Length of the reference grid.
    """
    v = np.asarray(values, dtype=float)
    out = np.full(length, np.nan)
    index = np.arange(length) + shift
    inside = (index >= 0) & (index < v.size)
    out[inside] = v[index[inside]]
    return out
