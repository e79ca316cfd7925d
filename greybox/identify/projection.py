"""Least-squares projections for scoring candidate terms against many residuals at once.

A candidate term with columns ``X`` is scored by how much it lowers the
residual sum of squares of a target ``y`` when added to the columns ``N`` that
the model refits anyway (its *nuisance*): with ``P`` the orthogonal projector
onto the span of ``N`` and ``y_perp = (I - P) y``,

    reduction = y_perp' X_perp (X_perp' X_perp)^+ X_perp' y_perp,  X_perp = (I - P) X.

The same columns are scored against the measured residual and against many
simulated null residuals in one matrix product. :class:`PositionScan` scans a
sine/cosine pair over many periods in position using sums over fine position
bins (the scan's cost no longer grows with the number of samples).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
import scipy.sparse

__all__ = ["Nuisance", "added_squares", "PositionScan"]

#: Columns (or directions) whose part outside the nuisance is smaller than
#: this fraction of their norm count as absorbed: they add nothing.
_RELATIVE_FLOOR = 1e-6
#: Position bins per shortest scanned period.
_BINS_PER_PERIOD = 16
#: Targets transformed together in a position scan (bounds its memory).
_TARGET_BLOCK = 32


class Nuisance:
    """Orthonormal basis of the columns a model refits anyway.

    Parameters
    ----------
    columns : ndarray, shape (n, q)
        Regressors; linearly dependent columns are dropped (QR with pivoting).
    """

    def __init__(self, columns: np.ndarray):
        columns = np.asarray(columns, dtype=float)
        if columns.ndim != 2:
            raise ValueError(f"nuisance columns must be 2-D, got shape {columns.shape}")
        norms = np.linalg.norm(columns, axis=0)
        keep = norms > 0.0
        if not np.any(keep):
            self.basis = np.empty((columns.shape[0], 0))
            return
        q, r, _ = scipy.linalg.qr(columns[:, keep] / norms[keep], mode="economic", pivoting=True)
        diagonal = np.abs(np.diag(r))
        rank = int(np.sum(diagonal > 1e-10 * diagonal[0]))
        self.basis = q[:, :rank]

    @property
    def rank(self) -> int:
        """Number of independent nuisance columns."""
        return self.basis.shape[1]

    def project(self, values: np.ndarray) -> np.ndarray:
        """``(I - P) values``: the part of each column outside the nuisance span.

        Parameters
        ----------
        values : ndarray, shape (n, m)
            Columns to project, with one row per row of the nuisance columns (or shape (n,)).
        """
        return values - self.basis @ (self.basis.T @ values)

    def coordinates(self, values) -> np.ndarray:
        """``basis' values`` (dense result) for dense or sparse ``values``.

        Parameters
        ----------
        values : ndarray or scipy.sparse matrix, shape (n, m)
            Columns with one row per row of the nuisance columns.
        """
        if scipy.sparse.issparse(values):
            return np.asarray((values.T @ self.basis).T)
        return self.basis.T @ values


def _reduction(gram: np.ndarray, norms_sq: np.ndarray, cross: np.ndarray) -> np.ndarray:
    """``c' G^+ c`` per column of ``cross``, ignoring directions absorbed by the nuisance.

    ``gram`` is the Gram matrix of the projected columns, ``norms_sq`` the
    squared norms of the columns before projection, ``cross`` (p, m) their
    products with the projected targets.
    """
    scale = np.sqrt(np.where(norms_sq > 0.0, norms_sq, 1.0))
    scaled = gram / scale[:, None] / scale[None, :]
    values, vectors = np.linalg.eigh(0.5 * (scaled + scaled.T))
    keep = values > _RELATIVE_FLOOR ** 2
    if not np.any(keep):
        return np.zeros(cross.shape[1])
    rotated = vectors[:, keep].T @ (cross / scale[:, None])
    return np.sum(rotated ** 2 / values[keep, None], axis=0)


def _reduction_pairs(g11, g12, g22, n11, n22, c1, c2) -> np.ndarray:
    """:func:`_reduction` for many two-column candidates at once (closed-form 2 x 2 eigen-decomposition).

    ``g11, g12, g22, n11, n22`` have shape (k,), ``c1, c2`` shape (k, m).
    """
    s1 = np.sqrt(np.where(n11 > 0.0, n11, 1.0))
    s2 = np.sqrt(np.where(n22 > 0.0, n22, 1.0))
    a, b, d = g11 / (s1 * s1), g12 / (s1 * s2), g22 / (s2 * s2)
    u1, u2 = c1 / s1[:, None], c2 / s2[:, None]
    half_trace, radius = 0.5 * (a + d), np.hypot(0.5 * (a - d), b)
    high, low = half_trace + radius, half_trace - radius
    floor = _RELATIVE_FLOOR ** 2
    # leading eigenvector (b, high - a), or an axis when the matrix is diagonal
    e1, e2 = b, high - a
    diagonal = np.hypot(e1, e2) <= 1e-300
    e1, e2 = np.where(diagonal, np.where(a >= d, 1.0, 0.0), e1), np.where(diagonal, np.where(a >= d, 0.0, 1.0), e2)
    norm = np.hypot(e1, e2)
    e1, e2 = e1 / norm, e2 / norm
    along = (e1[:, None] * u1 + e2[:, None] * u2) ** 2 / np.where(high > floor, high, 1.0)[:, None]
    across = (-e2[:, None] * u1 + e1[:, None] * u2) ** 2 / np.where(low > floor, low, 1.0)[:, None]
    return np.where((high > floor)[:, None], along, 0.0) + np.where((low > floor)[:, None], across, 0.0)


def added_squares(columns, targets_perp: np.ndarray, nuisance: Nuisance) -> np.ndarray:
    """Reduction of each target's residual sum of squares when ``columns`` join the nuisance.

    Parameters
    ----------
    columns : ndarray or scipy sparse matrix, shape (n, p)
        Candidate regressors (dense columns are projected explicitly, sparse
        ones through their Gram matrix).
    targets_perp : ndarray, shape (n, m)
        Targets already projected off the nuisance (:meth:`Nuisance.project`).
    nuisance : Nuisance
        The columns refitted anyway.

    Returns
    -------
    ndarray, shape (m,)
        Reduction of the sum of squares of each target column (>= 0).
    """
    if scipy.sparse.issparse(columns):
        columns = columns.tocsc()
        norms_sq = np.asarray(columns.multiply(columns).sum(axis=0)).ravel()
        inside = nuisance.coordinates(columns)
        gram = np.asarray((columns.T @ columns).todense()) - inside.T @ inside
        cross = np.asarray(columns.T @ targets_perp)
    else:
        columns = np.asarray(columns, dtype=float).reshape(targets_perp.shape[0], -1)
        norms_sq = np.sum(columns ** 2, axis=0)
        perp = nuisance.project(nuisance.project(columns))
        gram = perp.T @ perp
        cross = perp.T @ targets_perp
    return _reduction(gram, norms_sq, cross)


class PositionScan:
    """Least-squares scan of ``w(t) [sin(2 pi x / P), cos(2 pi x / P)]`` over periods ``P``.

    The scanned spatial frequencies ``1 / P`` are integer multiples of
    ``frequency_step``. The samples are summed into position bins of width
    ``h = 1 / (L * frequency_step)`` (at most a sixteenth of the shortest
    period), and every sum over the samples that the least-squares fit needs
    becomes a discrete Fourier transform of the bin sums, evaluated for all
    periods at once by one FFT of length ``L``. Each sample takes the phase
    of its bin's lower edge: a common shift (immaterial: the sine and cosine
    span every phase) plus an error of at most ``pi h / P``, which costs less
    than 1.5 % of a sine's explained variance.

    Parameters
    ----------
    position_mm : ndarray, shape (n,)
        Position of every sample [mm].
    weight : ndarray, shape (n,)
        Factor of the sine and cosine (1 for a force, the direction of motion for a friction).
    nuisance : Nuisance
        The columns refitted anyway.
    targets_perp : ndarray, shape (n, m)
        Targets projected off the nuisance.
    frequency_step : float
        Step of the spatial frequency grid [1/mm].
    max_frequency : float
        Highest spatial frequency that will be asked for [1/mm].
    """

    def __init__(self, position_mm, weight, nuisance: Nuisance, targets_perp: np.ndarray, frequency_step: float,
                 max_frequency: float):
        from scipy.fft import next_fast_len

        x = np.asarray(position_mm, dtype=float)
        w = np.asarray(weight, dtype=float)
        self.frequency_step = float(frequency_step)
        self.length = next_fast_len(int(np.ceil(_BINS_PER_PERIOD * max_frequency / frequency_step)) + 1)
        width = 1.0 / (self.length * frequency_step)
        index = np.floor((x - x.min()) / width + 0.5).astype(np.int64)  # bins start half a width below
        if index.max() >= self.length // 2:
            raise ValueError("frequency step too coarse for the position range: it must be at most half "
                             "the inverse of the range")
        summing = scipy.sparse.csr_matrix((w, (index, np.arange(x.size))), shape=(self.length, x.size))
        self.weight_sq = np.bincount(index, w * w, self.length)
        self.nuisance_sums = np.asarray(summing @ nuisance.basis)
        self.target_sums = np.asarray(summing @ targets_perp)

    def _indices(self, periods_mm) -> np.ndarray:
        ratio = 1.0 / (np.asarray(periods_mm, dtype=float) * self.frequency_step)
        index = np.rint(ratio).astype(np.int64)
        if np.any(np.abs(ratio - index) > 1e-6 * np.maximum(ratio, 1.0)) or np.any(index < 1):
            raise ValueError("periods must be inverse integer multiples of the frequency step")
        if np.any(2 * index > self.length // 2):
            raise ValueError("a period is shorter than the scan was prepared for")
        return index

    def reductions(self, periods_mm) -> np.ndarray:
        """Reduction of every target's sum of squares at every period.

        Parameters
        ----------
        periods_mm : ndarray, shape (k,)
            Periods [mm], each ``1 / (j * frequency_step)`` for an integer ``j``.

        Returns
        -------
        ndarray, shape (k, m)
        """
        from scipy.fft import rfft

        index = self._indices(periods_mm)
        doubled = rfft(self.weight_sq)[2 * index]
        total = self.weight_sq.sum()
        cc = 0.5 * (total + doubled.real)
        ss = 0.5 * (total - doubled.real)
        sc = -0.5 * doubled.imag
        q = rfft(self.nuisance_sums, axis=0)[index]
        qc, qs = q.real, -q.imag
        g11 = ss - np.sum(qs * qs, axis=1)
        g22 = cc - np.sum(qc * qc, axis=1)
        g12 = sc - np.sum(qs * qc, axis=1)
        out = np.empty((index.size, self.target_sums.shape[1]))
        for start in range(0, self.target_sums.shape[1], _TARGET_BLOCK):
            stop = min(start + _TARGET_BLOCK, self.target_sums.shape[1])
            y = rfft(self.target_sums[:, start:stop], axis=0)[index]
            out[:, start:stop] = _reduction_pairs(g11, g12, g22, ss, cc, -y.imag, y.real)
        return out
