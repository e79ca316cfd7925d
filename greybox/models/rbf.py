"""Batched evaluation of a Gaussian (RBF) kernel expansion.

A fitted support vector regression with an RBF kernel predicts

.. math:: f(x) = \\sum_j \\alpha_j \\exp(-\\gamma \\lVert x - s_j \\rVert^2) + b

for support vectors :math:`s_j`, dual coefficients :math:`\\alpha_j` and
intercept :math:`b`. libsvm (behind :class:`sklearn.svm.SVR`) evaluates this
one sample and one support vector at a time. Here the squared distances of a
block of samples to all support vectors come from one matrix product,

.. math:: -\\gamma \\lVert x - s \\rVert^2 = 2\\gamma\\, x \\cdot s
          - \\gamma \\lVert x \\rVert^2 - \\gamma \\lVert s \\rVert^2,

followed by a vectorised ``exp`` and a matrix-vector product with the dual
coefficients. Blocks of rows keep the memory bounded (``chunk_elements``
kernel values at a time, 512 KiB by default) whatever the number of samples.
Samples and support vectors are first shifted by the mean support vector so
that the expansion above loses little to cancellation.
"""

from __future__ import annotations

import numpy as np

__all__ = ["rbf_expansion"]


def rbf_expansion(
    X,
    support_vectors,
    dual_coef,
    intercept: float = 0.0,
    gamma: float = 1.0,
    *,
    chunk_elements: int = 1 << 16,
) -> np.ndarray:
    """Evaluate ``sum_j dual_coef[j] * exp(-gamma * ||x - sv_j||^2) + intercept``.

    Parameters
    ----------
    X : array_like, shape (n_samples, n_features)
        Points at which to evaluate the expansion (already in the scaled
        coordinates of the support vectors).
    support_vectors : array_like, shape (n_support, n_features)
        Support vectors.
    dual_coef : array_like, shape (n_support,)
        Dual coefficients, in the unit of the output (e.g. A).
    intercept : float, default 0.0
        Constant added to every output, same unit.
    gamma : float, default 1.0
        Kernel width parameter [1 / (unit of X)^2], > 0.
    chunk_elements : int, default 65536
        Number of kernel values held in memory at once; bounds the memory
        use to ``8 * chunk_elements`` bytes plus one row per sample.

    Returns
    -------
    ndarray, shape (n_samples,)
        The expansion at each row of ``X``.

    Raises
    ------
    ValueError
        On inconsistent shapes or a non-positive ``gamma``/``chunk_elements``.
    """
    X = np.asarray(X, dtype=np.float64)
    sv = np.asarray(support_vectors, dtype=np.float64)
    alpha = np.asarray(dual_coef, dtype=np.float64).ravel()
    if X.ndim != 2 or sv.ndim != 2:
        raise ValueError("X and support_vectors must be two-dimensional")
    if X.shape[1] != sv.shape[1]:
        raise ValueError(f"X has {X.shape[1]} features, the support vectors {sv.shape[1]}")
    if alpha.shape[0] != sv.shape[0]:
        raise ValueError(f"{alpha.shape[0]} dual coefficients for {sv.shape[0]} support vectors")
    if not gamma > 0:
        raise ValueError(f"gamma must be positive, got {gamma}")
    if chunk_elements < 1:
        raise ValueError(f"chunk_elements must be positive, got {chunk_elements}")

    n_samples, n_features = X.shape
    n_support = sv.shape[0]
    out = np.full(n_samples, float(intercept))
    if n_support == 0 or n_samples == 0:
        return out

    # Augmented factors: [x, -g|x|^2, 1] . [2g s, 1, -g|s|^2] = -g |x - s|^2.
    centre = sv.mean(axis=0)
    sv_c = sv - centre
    right = np.empty((n_support, n_features + 2))
    right[:, :n_features] = (2.0 * gamma) * sv_c
    right[:, n_features] = 1.0
    right[:, n_features + 1] = -gamma * np.einsum("ij,ij->i", sv_c, sv_c)
    right_t = np.ascontiguousarray(right.T)

    rows = max(1, chunk_elements // n_support)
    left = np.empty((min(rows, n_samples), n_features + 2))
    left[:, n_features + 1] = 1.0
    kernel = np.empty((min(rows, n_samples), n_support))
    for start in range(0, n_samples, rows):
        stop = min(start + rows, n_samples)
        m = stop - start
        x_c = left[:m, :n_features]
        np.subtract(X[start:stop], centre, out=x_c)
        left[:m, n_features] = -gamma * np.einsum("ij,ij->i", x_c, x_c)
        k = kernel[:m]
        np.matmul(left[:m], right_t, out=k)
        # Rounding can leave a distance of -1e-16; the kernel must not exceed 1.
        np.minimum(k, 0.0, out=k)
        np.exp(k, out=k)
        out[start:stop] += k @ alpha
    return out
