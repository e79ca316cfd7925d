"""Where the parts of a part series are, and how one part lies against another.

A series comes as one log per part or as one long log. A long log is split by its part counter column
(:data:`PART_COLUMN`, as a control logs it) where it has one, else at the rests between the parts: every
stretch at standstill of at least ``min_rest_s`` ends a part (a part's own dwells and reversals must be
shorter).

Two parts of the same program differ by small timing differences (the loading time, the moment the cycle
starts). :func:`best_shift` finds the shift of one part against the reference part that maximises the
cross-correlation of their velocities, bounded to ``max_shift`` samples; :func:`shifted` lays the part on
the reference's sample grid (NaN where it has no sample).

A log that carries the NC block number per sample (column :data:`BLOCK_COLUMN`, as a control logs it) is
aligned block by block instead (:func:`block_positions`, :func:`warped`): each run of one block number in the
reference is matched with the same run in the part (the k-th run of a number with its k-th run) and the part's
samples of that run are stretched linearly onto the reference's, so timing differences inside the part (a
feed override, a longer dwell) are taken out too.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import correlate

from ..errors import GreyboxError
from ..predict.relevel import STANDSTILL_MM_S

__all__ = ["BLOCK_COLUMN", "PART_COLUMN", "STANDSTILL_MM_S", "block_positions", "part_slices", "best_shift",
           "shifted", "warped"]

#: Name of the part counter column of a long log.
PART_COLUMN = "part"
#: Name of the NC block number column of a log.
BLOCK_COLUMN = "block"


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


def _runs(blocks: np.ndarray) -> dict:
    """``{(number, k): (start, end)}``: the k-th run of each block number (NaN counted as -1)."""
    b = np.nan_to_num(np.asarray(blocks, dtype=float), nan=-1.0)
    edges = np.concatenate(([0], np.flatnonzero(np.diff(b) != 0) + 1, [b.size]))
    runs, seen = {}, {}
    for a, e in zip(edges[:-1].tolist(), edges[1:].tolist()):
        key = float(b[a])
        runs[(key, seen.get(key, 0))] = (a, e)
        seen[key] = seen.get(key, 0) + 1
    return runs


def block_positions(reference_blocks, blocks) -> np.ndarray:
    """Where in a part each sample of the reference lies, block by block (module docstring).

    Parameters
    ----------
    reference_blocks : array_like, shape (m,)
        The reference part's NC block number per sample.
    blocks : array_like, shape (n,)
        The part's.

    Returns
    -------
    ndarray, shape (m,)
        Fractional sample index into the part per reference sample; NaN in the runs the part lacks.

    Raises
    ------
    GreyboxError
        If either is empty.
    """
    reference, part = _runs(reference_blocks), _runs(blocks)
    if not reference or not part:
        raise GreyboxError("alignment: a part without samples")
    positions = np.full(sum(e - a for a, e in reference.values()), np.nan)
    for key, (a, e) in reference.items():
        if key in part:
            pa, pe = part[key]
            positions[a:e] = pa - 0.5 + (np.arange(e - a) + 0.5) * (pe - pa) / (e - a)
    return positions


def warped(values, positions) -> np.ndarray:
    """``values`` at fractional sample indices, by linear interpolation; NaN where the index is NaN or outside.

    Parameters
    ----------
    values : array_like, shape (n,)
        A part's samples.
    positions : ndarray, shape (m,)
        From :func:`block_positions`.
    """
    v = np.asarray(values, dtype=float)
    out = np.full(positions.size, np.nan)
    inside = np.isfinite(positions) & (positions >= -0.5) & (positions <= v.size - 0.5)
    out[inside] = np.interp(positions[inside], np.arange(v.size), v)
    return out
