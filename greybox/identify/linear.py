"""Bounded linear least squares for separable (variable-projection) fits.

Most friction models are linear in several of their parameters once the
others are fixed (the inertia J, the viscous coefficient, the offset, the GMS
stiffnesses, ...). The identification then searches only the nonlinear
parameters and solves for the linear ones at every cost evaluation with
:func:`bounded_lstsq`, which is fast for many rows and few columns.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import lsq_linear

__all__ = ["bounded_lstsq", "bounded_normal_solve"]

#: Relative floor of the eigenvalues of the scaled Gram matrix: a tiny ridge
#: that keeps collinear regressors (e.g. GMS elements that never stick) solvable.
_EIGEN_FLOOR = 1e-13


def bounded_lstsq(a: np.ndarray, b: np.ndarray, lower=None, upper=None) -> tuple[np.ndarray, np.ndarray]:
    """Minimise ``||a x - b||^2`` subject to ``lower <= x <= upper``.

    Parameters
    ----------
    a : ndarray, shape (n, p)
        Regressors, one column per linear parameter.
    b : ndarray, shape (n,)
        Target.
    lower, upper : array_like of shape (p,), optional
        Bounds (``-inf``/``inf`` for none); unbounded if omitted.

    Returns
    -------
    x : ndarray, shape (p,)
        The solution. A column that is zero everywhere gets the coefficient
        nearest to 0 within its bounds.
    residual : ndarray, shape (n,)
        ``a x - b``.

    Notes
    -----
    The problem is reduced to ``p`` rows through the eigen-decomposition of the
    Gram matrix scaled to unit column norms, so the cost is ``O(n p^2)`` and no
    copy of ``a`` is made. When the unconstrained solution violates a bound,
    the reduced problem is solved by bounded-variable least squares.
    """
    x = bounded_normal_solve(a.T @ a, a.T @ b, lower=lower, upper=upper)
    return x, a @ x - b


def bounded_normal_solve(gram: np.ndarray, rhs: np.ndarray, lower=None, upper=None) -> np.ndarray:
    """The solution of :func:`bounded_lstsq` from the normal equations ``a.T a`` and ``a.T b``.

    Sums of these over groups of rows (e.g. the blocks of a block bootstrap) give the fit of the union of
    the groups without touching the rows again.

    Parameters
    ----------
    gram : ndarray, shape (p, p)
        ``a.T @ a`` [unit of a squared].
    rhs : ndarray, shape (p,)
        ``a.T @ b`` [unit of a times unit of b].
    lower, upper : array_like of shape (p,), optional
        Bounds (``-inf``/``inf`` for none); unbounded if omitted.

    Returns
    -------
    ndarray, shape (p,)
        The solution. A column that is zero everywhere gets the coefficient nearest to 0 within its bounds.
    """
    gram_full = np.asarray(gram, dtype=float)
    rhs = np.asarray(rhs, dtype=float)
    p = gram_full.shape[0]
    lower = np.full(p, -np.inf) if lower is None else np.asarray(lower, dtype=float)
    upper = np.full(p, np.inf) if upper is None else np.asarray(upper, dtype=float)
    norms = np.sqrt(np.maximum(np.diag(gram_full), 0.0))
    active = norms > 0.0
    x = np.clip(0.0, lower, upper)
    if np.any(active):
        inv = 1.0 / norms[active]
        scaled_gram = gram_full[np.ix_(active, active)] * inv[:, None] * inv[None, :]
        scaled_rhs = rhs[active] * inv
        eigval, eigvec = np.linalg.eigh(scaled_gram)
        eigval = np.maximum(eigval, _EIGEN_FLOOR * max(eigval[-1], 1.0))
        x_scaled = eigvec @ ((eigvec.T @ scaled_rhs) / eigval)
        lo = lower[active] * norms[active]
        hi = upper[active] * norms[active]
        if np.any(x_scaled < lo) or np.any(x_scaled > hi):
            root = np.sqrt(eigval)
            r_mat = root[:, None] * eigvec.T
            d_vec = (eigvec.T @ scaled_rhs) / root
            x_scaled = lsq_linear(r_mat, d_vec, bounds=(lo, hi), method="bvls").x
        # bvls may end a rounding error outside a bound (e.g. -3e-13 for a stiffness bounded at 0)
        x[active] = np.clip(x_scaled * inv, lower[active], upper[active])
    return x
