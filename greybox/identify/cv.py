"""Time-blocked cross-validation over one or several runs.

Neighbouring samples of an axis log (2 ms apart) are almost equal, so
shuffling single samples into training and test sets would measure
interpolation between neighbours, not prediction. Here every run is cut into
contiguous blocks of time, a block never spans two runs, and each block goes
as a whole to one fold. The blocks are dealt to the folds in turn (block
``b`` to fold ``b % n_folds``), so that every fold samples the whole
recording rather than one stretch of it. Optionally ``gap`` samples on either
side of a test block are left out of the training set as well.

Sample indices refer to the runs concatenated in the order given (run 0
first); they index arrays built with ``numpy.concatenate`` over the runs and
are never used to differentiate or simulate across a seam.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

__all__ = ["TimeBlock", "time_blocks", "blocked_folds"]


@dataclass(frozen=True)
class TimeBlock:
    """A contiguous stretch ``[start, stop)`` of samples of one run.

    Attributes
    ----------
    run : int
        Index of the run.
    start, stop : int
        Sample range within the run.
    offset : int
        Index of the run's first sample in the concatenation of all runs.
    """

    run: int
    start: int
    stop: int
    offset: int

    @property
    def indices(self) -> np.ndarray:
        """Indices of the block's samples in the concatenation of the runs."""
        return np.arange(self.offset + self.start, self.offset + self.stop)

    def __len__(self) -> int:
        return self.stop - self.start


def _run_lengths(run_lengths: Sequence[int]) -> np.ndarray:
    lengths = np.asarray([int(n) for n in run_lengths], dtype=np.int64)
    if lengths.size == 0:
        raise ValueError("no runs given")
    if np.any(lengths < 1):
        raise ValueError(f"every run needs at least one sample, got lengths {lengths.tolist()}")
    return lengths


def time_blocks(run_lengths: Sequence[int], n_blocks: int) -> list[TimeBlock]:
    """Cut runs into contiguous blocks of nearly equal length.

    The blocks are shared among the runs in proportion to their lengths
    (largest remainder), with at least one block per run; within a run the
    block lengths differ by at most one sample.

    Parameters
    ----------
    run_lengths : sequence of int
        Number of samples of each run.
    n_blocks : int
        Total number of blocks; raised to the number of runs if smaller.

    Returns
    -------
    list of TimeBlock
        In time order, run by run.

    Raises
    ------
    ValueError
        If a run would get a block with no samples.
    """
    lengths = _run_lengths(run_lengths)
    n_blocks = max(int(n_blocks), lengths.size)
    share = lengths / lengths.sum() * n_blocks
    per_run = np.maximum(1, np.floor(share).astype(np.int64))
    remainder = share - np.floor(share)
    for run in np.argsort(-remainder, kind="stable"):
        if per_run.sum() >= n_blocks:
            break
        per_run[run] += 1
    while per_run.sum() > n_blocks:  # the minimum of one block per run overshot
        candidates = np.flatnonzero(per_run > 1)
        per_run[candidates[np.argmax(per_run[candidates])]] -= 1

    offsets = np.concatenate(([0], np.cumsum(lengths)[:-1]))
    blocks = []
    for run, (n, k, offset) in enumerate(zip(lengths, per_run, offsets)):
        if k > n:
            raise ValueError(f"run {run} has {n} samples, too few for {k} blocks")
        edges = np.linspace(0, n, k + 1).round().astype(np.int64)
        blocks.extend(TimeBlock(run, int(a), int(b), int(offset)) for a, b in zip(edges[:-1], edges[1:]))
    return blocks


def blocked_folds(
    run_lengths: Sequence[int],
    n_folds: int = 3,
    n_blocks: int | None = None,
    gap: int = 0,
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Training and test indices of a time-blocked cross-validation.

    Parameters
    ----------
    run_lengths : sequence of int
        Number of samples of each run.
    n_folds : int, default 3
        Number of folds, >= 2.
    n_blocks : int, optional
        Number of contiguous blocks (see :func:`time_blocks`), >= ``n_folds``;
        by default ``4 * n_folds``.
    gap : int, default 0
        Samples on each side of a test block (within its run) that are
        excluded from training, against leakage through autocorrelation.

    Returns
    -------
    list of (train, test)
        One pair per fold of sorted integer index arrays into the
        concatenated runs; each test set is a union of whole blocks, and the
        test sets of all folds partition the samples.

    Raises
    ------
    ValueError
        On fewer than two folds, fewer blocks than folds, a negative gap, or
        a fold left without training samples.
    """
    n_folds = int(n_folds)
    if n_folds < 2:
        raise ValueError(f"n_folds must be >= 2, got {n_folds}")
    n_blocks = 4 * n_folds if n_blocks is None else int(n_blocks)
    if n_blocks < n_folds:
        raise ValueError(f"n_blocks ({n_blocks}) must be >= n_folds ({n_folds})")
    if gap < 0:
        raise ValueError(f"gap must be >= 0, got {gap}")
    lengths = _run_lengths(run_lengths)
    blocks = time_blocks(lengths, n_blocks)
    if len(blocks) < n_folds:
        raise ValueError(f"{len(blocks)} blocks are too few for {n_folds} folds")
    run_end = np.cumsum(lengths)

    total = int(lengths.sum())
    folds = []
    for fold in range(n_folds):
        test = np.zeros(total, dtype=bool)
        excluded = np.zeros(total, dtype=bool)
        for b, block in enumerate(blocks):
            if b % n_folds != fold:
                continue
            first, last = block.offset + block.start, block.offset + block.stop
            test[first:last] = True
            low = max(block.offset, first - gap)
            high = min(int(run_end[block.run]), last + gap)
            excluded[low:high] = True
        train = np.flatnonzero(~excluded)
        if train.size == 0:
            raise ValueError(f"fold {fold} has no training samples left (gap={gap} too large?)")
        folds.append((train, np.flatnonzero(test)))
    return folds
