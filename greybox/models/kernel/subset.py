"""Training subsets that cover the operating range evenly.

Training a support vector regression costs roughly the square of the number
of samples, and an axis log at 500 Hz holds millions. A random subset would
mirror the log's dwell times: mostly standstill and constant feed, few
samples at reversals and high speed. :func:`coverage_subset` instead lays a
grid over a few features (position and velocity, normally), and gives every
occupied cell the same quota, so rare operating points weigh as much as
frequent ones. :func:`accuracy_vs_subset_size` measures what a smaller
subset costs in accuracy.
"""

from __future__ import annotations

import time
from typing import Sequence

import numpy as np

from ...metrics import metrics_table

__all__ = ["coverage_subset", "grid_cells", "accuracy_vs_subset_size"]


def grid_cells(features, n_bins: int) -> np.ndarray:
    """Cell number of each row of ``features`` on an equal-width grid.

    Parameters
    ----------
    features : array_like, shape (n_samples, n_features)
        Points; each column is binned over its own range [min, max].
    n_bins : int
        Bins per column, >= 1.

    Returns
    -------
    ndarray of int, shape (n_samples,)
        Cell number in ``[0, n_bins ** n_features)``.
    """
    features = np.asarray(features, dtype=np.float64)
    if features.ndim == 1:
        features = features[:, None]
    if n_bins < 1:
        raise ValueError(f"n_bins must be >= 1, got {n_bins}")
    if not np.all(np.isfinite(features)):
        raise ValueError("features contain NaN or infinite values")
    cell = np.zeros(features.shape[0], dtype=np.int64)
    for column in features.T:
        low, high = column.min(), column.max()
        width = (high - low) / n_bins
        if width > 0:
            index = np.minimum(((column - low) / width).astype(np.int64), n_bins - 1)
        else:
            index = np.zeros(column.shape[0], dtype=np.int64)
        cell = cell * n_bins + index
    return cell


def coverage_subset(features, n_subset: int, *, n_bins: int = 20, random_state: int = 0) -> np.ndarray:
    """Choose ``n_subset`` rows that cover the feature space evenly.

    Each column of ``features`` is cut into equal-width bins; the occupied
    cells of the resulting grid share the quota equally (cells with fewer
    samples than their share give them all, and the rest is shared among the
    other cells), and within a cell the samples are drawn at random.
    The bins per column are capped at ``floor(n_subset ** (1 / n_features))``
    so that every occupied cell is represented.

    Parameters
    ----------
    features : array_like, shape (n_samples, n_features)
        Points to choose from, e.g. ``column_stack((position_mm, velocity_mm_s))``.
    n_subset : int
        Number of rows wanted, >= 1; all rows are returned if there are fewer.
    n_bins : int, default 20
        Bins per column (before the cap above).
    random_state : int, default 0
        Seed of the draws within cells (and of ties in the quota).

    Returns
    -------
    ndarray of int
        Sorted row indices, ``min(n_subset, n_samples)`` of them.
    """
    features = np.asarray(features, dtype=np.float64)
    if features.ndim == 1:
        features = features[:, None]
    n_samples, n_features = features.shape
    n_subset = int(n_subset)
    if n_subset < 1:
        raise ValueError(f"n_subset must be >= 1, got {n_subset}")
    if n_subset >= n_samples:
        return np.arange(n_samples)
    rng = np.random.default_rng(random_state)
    bins = max(1, min(int(n_bins), int(np.floor(n_subset ** (1.0 / n_features) + 1e-9))))
    cells = grid_cells(features, bins)

    order = np.argsort(cells, kind="stable")
    occupied, starts, counts = np.unique(cells[order], return_index=True, return_counts=True)
    quota = np.zeros(occupied.size, dtype=np.int64)
    remaining = n_subset
    left = occupied.size
    # Water filling: small cells give all their samples, the rest share equally.
    for k in np.argsort(counts, kind="stable"):
        share = remaining // left
        if counts[k] <= share:
            quota[k] = counts[k]
            remaining -= counts[k]
            left -= 1
        else:
            break
    open_cells = np.flatnonzero(quota == 0)
    if open_cells.size:
        quota[open_cells] = remaining // open_cells.size
        extra = remaining - quota[open_cells].sum()
        quota[rng.choice(open_cells, size=extra, replace=False)] += 1

    chosen = [
        rng.choice(order[start : start + count], size=q, replace=False)
        for start, count, q in zip(starts, counts, quota)
        if q > 0
    ]
    return np.sort(np.concatenate(chosen))


def accuracy_vs_subset_size(model, train_logs, test_logs, sizes: Sequence[int]) -> list[dict[str, float]]:
    """Fit a copy of ``model`` for each training-subset size and score it.

    Parameters
    ----------
    model : estimator with an ``n_subset`` parameter
        E.g. :class:`greybox.models.svr.SVRCurrentModel`. Its other
        parameters are kept: fix ``C``, ``epsilon`` and ``gamma`` (or set
        ``optimize=False``) to see the effect of the subset alone.
    train_logs, test_logs : AxisLog or list of AxisLog
        Prepared runs to fit on and to score on.
    sizes : sequence of int
        Subset sizes to try.

    Returns
    -------
    list of dict
        Per size: ``n_subset``, ``fit_seconds`` [s], ``predict_seconds`` [s],
        and the metrics of :func:`greybox.metrics.metrics_table` on
        the test logs (``rmse`` [A], ``re`` [%], ...).
    """
    from sklearn.base import clone

    from ...data.log import as_log_list

    test_runs = as_log_list(test_logs)
    measured = np.concatenate([run.current for run in test_runs])
    rows = []
    for size in sizes:
        candidate = clone(model).set_params(n_subset=int(size))
        start = time.perf_counter()
        candidate.fit(train_logs)
        fitted = time.perf_counter()
        predicted = candidate.predict(test_runs)
        done = time.perf_counter()
        rows.append(
            {
                "n_subset": int(size),
                "fit_seconds": fitted - start,
                "predict_seconds": done - fitted,
                **metrics_table(measured, predicted),
            }
        )
    return rows
