"""Least-squares fits of the static (memoryless) friction models.

Both fits regress the effort ``y`` [A] on the motion of the axis, with the
inertia ``J`` estimated jointly:

- Coulomb + viscous (the inverse-dynamic-model least squares, IDIM-LS):
  ``y = J a + F_c sgn(v) + F_v v (+ offset)``, optionally with separate
  Coulomb and viscous levels for the two directions of motion. Linear.
- Stribeck + viscous:
  ``y = J a + sgn(v) (F_c + (F_s - F_c) exp(-|v|/v_s)) + mu v (+ offset)``.
  Linear in everything but ``v_s``: a separable least-squares fit searches
  ``v_s`` (log grid, then a bounded scalar refinement) and solves the linear
  parameters, constrained non-negative, at every trial.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar
from threadpoolctl import threadpool_limits

from ..errors import ParameterError
from .linear import bounded_lstsq

__all__ = ["fit_coulomb", "fit_stribeck", "stribeck_regressors", "velocity_range"]

#: Number of log-spaced Stribeck velocities tried before the local refinement.
_N_GRID = 40


def velocity_range(velocity: np.ndarray) -> tuple[float, float]:
    """Search range of the Stribeck velocity ``v_s`` [mm/s] for given data.

    From 1e-3 to 1 times the largest speed in the data (the 99.9th percentile
    of ``|v|``, robust to single outliers; the maximum if fewer samples move).
    """
    speed = np.abs(velocity)
    v_max = float(np.percentile(speed, 99.9)) or float(np.max(speed, initial=0.0))
    if not v_max > 0.0:
        raise ValueError("the velocity is zero throughout: friction cannot be identified")
    return 1e-3 * v_max, v_max


def fit_coulomb(velocity, acceleration, effort, *, asymmetric: bool = False,
                fit_offset: bool = False) -> dict[str, float]:
    """Coulomb + viscous friction and inertia by linear least squares, the inertia non-negative.

    Where the unconstrained solution has ``J < 0`` (an acceleration too little
    excited, or correlated with an unmodelled friction), ``J`` is held at 0
    and the other parameters are refitted, so a positive current always
    accelerates the axis towards positive positions.

    Parameters
    ----------
    velocity : ndarray, shape (n,)
        Velocity [mm/s].
    acceleration : ndarray, shape (n,)
        Acceleration [mm/s^2].
    effort : ndarray, shape (n,)
        Current [A] (or force [N]).
    asymmetric : bool, default False
        Separate Coulomb and viscous levels for positive and negative motion.
    fit_offset : bool, default False
        Fit a constant offset [A].

    Returns
    -------
    dict
        ``J`` [A s^2/mm], ``coulomb_pos``/``coulomb_neg`` [A] (friction levels
        magnitudes for positive/negative motion), ``viscous_pos``/``viscous_neg``
        [A s/mm], ``offset`` [A] (0 when not fitted).

    Raises
    ------
    ParameterError
        If ``asymmetric`` and ``fit_offset`` are both requested (the offset is
        then not separable from the two Coulomb levels).
    """
    if asymmetric and fit_offset:
        raise ParameterError("an offset and direction-dependent Coulomb levels are not separately "
                             "identifiable; use asymmetric=True or fit_offset=True, not both")
    v = np.asarray(velocity, dtype=float)
    positive = (v > 0.0).astype(float)
    negative = (v < 0.0).astype(float)
    if asymmetric:
        columns = [acceleration, positive, -negative, v * positive, v * negative]
    else:
        columns = [acceleration, np.sign(v), v]
    if fit_offset:
        columns.append(np.ones_like(v))
    a = np.column_stack(columns)
    lower = np.full(a.shape[1], -np.inf)
    lower[0] = 0.0
    x, _ = bounded_lstsq(a, np.asarray(effort, dtype=float), lower=lower)
    x = [float(value) for value in x]
    if asymmetric:
        return {"J": x[0], "coulomb_pos": x[1], "coulomb_neg": x[2], "viscous_pos": x[3],
                "viscous_neg": x[4], "offset": 0.0}
    return {"J": x[0], "coulomb_pos": x[1], "coulomb_neg": x[1], "viscous_pos": x[2],
            "viscous_neg": x[2], "offset": x[3] if fit_offset else 0.0}


def stribeck_regressors(velocity, acceleration, v_s: float, fit_offset: bool) -> np.ndarray:
    """Regressors of the Stribeck + viscous model for a given ``v_s`` [mm/s].

    Columns: ``a``, ``sgn(v) (1 - e)``, ``sgn(v) e``, ``v`` (and ``1``), with
    ``e = exp(-|v|/v_s)``; their coefficients are ``J``, ``F_c``, ``F_s``,
    ``mu`` (and the offset).
    """
    v = np.asarray(velocity, dtype=float)
    e = np.exp(-np.abs(v) / v_s)
    sign = np.sign(v)
    columns = [acceleration, sign * (1.0 - e), sign * e, v]
    if fit_offset:
        columns.append(np.ones_like(v))
    return np.column_stack(columns)


def _stribeck_bounds(fit_offset: bool):
    lower = [0.0, 0.0, 0.0, 0.0] + ([-np.inf] if fit_offset else [])
    return np.array(lower), np.full(len(lower), np.inf)


def fit_stribeck(velocity, acceleration, effort, *, fit_offset: bool = False,
                 v_s_range: tuple[float, float] | None = None) -> dict[str, float]:
    """Stribeck + viscous friction and inertia by separable least squares.

    Parameters
    ----------
    velocity, acceleration, effort : ndarray, shape (n,)
        Velocity [mm/s], acceleration [mm/s^2], current [A] (or force [N]).
    fit_offset : bool, default False
        Fit a constant offset [A].
    v_s_range : (float, float), optional
        Search range of ``v_s`` [mm/s]; :func:`velocity_range` of the data by default.

    Returns
    -------
    dict
        ``J`` [A s^2/mm], ``coulomb`` ``F_c`` [A], ``static`` ``F_s`` [A],
        ``v_s`` [mm/s], ``viscous`` ``mu`` [A s/mm], ``offset`` [A] (0 when not
        fitted) and ``sse`` (sum of squared residuals [A^2]). ``J``, ``F_c``,
        ``F_s`` and ``mu`` are constrained non-negative.
    """
    lo, hi = velocity_range(velocity) if v_s_range is None else v_s_range
    lower, upper = _stribeck_bounds(fit_offset)

    def sse(log_v_s):
        a = stribeck_regressors(velocity, acceleration, float(np.exp(log_v_s)), fit_offset)
        residual = bounded_lstsq(a, effort, lower, upper)[1]
        return float(residual @ residual)

    grid = np.linspace(np.log(lo), np.log(hi), _N_GRID)
    with threadpool_limits(limits=1, user_api="blas"):  # tall-and-thin products: no gain from threads
        costs = [sse(g) for g in grid]
        best = int(np.argmin(costs))
        left, right = grid[max(best - 1, 0)], grid[min(best + 1, _N_GRID - 1)]
        refined = minimize_scalar(sse, bounds=(left, right), method="bounded", options={"xatol": 1e-6})
        log_v_s = refined.x if refined.fun < costs[best] else grid[best]
        v_s = float(np.exp(log_v_s))
        x, residual = bounded_lstsq(stribeck_regressors(velocity, acceleration, v_s, fit_offset), effort,
                                    lower, upper)
    x = [float(value) for value in x]
    return {"J": x[0], "coulomb": x[1], "static": x[2], "viscous": x[3], "v_s": v_s,
            "offset": x[4] if fit_offset else 0.0, "sse": float(residual @ residual)}
