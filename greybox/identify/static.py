"""Least-squares fits of the static (memoryless) friction models.

Both fits regress the effort ``y`` [A] on the motion of the axis, with the
inertia ``J`` estimated jointly:

- Coulomb + viscous (the inverse-dynamic-model least squares, IDIM-LS):
  ``y = J a + F_c sgn(v) + F_v v (+ offset)``, optionally with separate
  Coulomb and viscous levels for the two directions of motion. Linear.
- Stribeck + viscous:
  ``y = J a + sgn(v) (F_c + (F_s - F_c) exp(-|v|/v_s)) + mu v (+ offset)``,
  optionally with a separate curve ``F_c, F_s, v_s, mu`` for each direction
  of motion. Linear in everything but ``v_s``: a separable least-squares fit
  searches ``v_s`` (log grid, then a bounded scalar refinement) and solves the
  linear parameters, constrained non-negative, at every trial. The two
  Stribeck velocities of the asymmetric model are searched one direction at
  a time (coordinate search) from the best common value: the friction
  columns of the two directions touch disjoint samples, only ``J`` couples
  them.

:func:`stribeck_curve` is the one NumPy copy of the Stribeck curve that the
models, these fits and the initial guesses evaluate (the compiled kernels
evaluate the same curve per sample: :func:`greybox.models.friction.kernels.stribeck_at`).
"""

from __future__ import annotations

from functools import partial

import numpy as np
from scipy.optimize import minimize_scalar
from threadpoolctl import threadpool_limits

from ..errors import ParameterError, Setting
from .linear import bounded_lstsq, bounded_normal_solve

__all__ = ["check_direction_settings", "coulomb_from_normal_equations", "coulomb_regressors", "fit_coulomb",
           "fit_stribeck", "stribeck_curve", "stribeck_regressors", "velocity_range"]

#: Number of log-spaced Stribeck velocities tried before the local refinement.
_N_GRID = 40
#: Tolerance of the refined log Stribeck velocities (relative tolerance of ``v_s``).
_XATOL = 1e-6
#: Most rounds of the coordinate search of the two Stribeck velocities of the asymmetric model.
_MAX_ROUNDS = 20


def stribeck_curve(velocity, s_0: float, s_inf: float, v_s: float) -> np.ndarray:
    """Decaying Stribeck curve ``s(v) = s_inf + (s_0 - s_inf) exp(-|v| / v_s)``.

    Parameters
    ----------
    velocity : array_like
        Velocity [mm/s].
    s_0 : float
        Value at rest (static friction level, or GMS break-away deflection).
    s_inf : float
        Value at high speed (Coulomb level), same unit as ``s_0``.
    v_s : float
        Stribeck velocity [mm/s], positive.

    Returns
    -------
    ndarray
        ``s(v)`` in the unit of ``s_0``; even in ``v``.
    """
    return s_inf + (s_0 - s_inf) * np.exp(-np.abs(np.asarray(velocity, dtype=float)) / v_s)


def check_direction_settings(asymmetric: bool, fit_offset: bool) -> None:
    """Raise :class:`ParameterError` if direction-dependent friction and an offset are both asked for.

    An offset shifts the mean of the two directions' sliding levels, which
    the two levels already set: the three are not separately identifiable.

    Parameters
    ----------
    asymmetric : bool
        Whether the model has separate friction levels for the two directions of motion.
    fit_offset : bool
        Whether the model fits a constant offset [A].
    """
    if asymmetric and fit_offset:
        raise ParameterError("an offset and direction-dependent friction levels are not separately identifiable: "
                             "choose ", Setting("asymmetric", assign=False), " or ",
                             Setting("fit_offset", assign=False), ", not both")


def velocity_range(velocity: np.ndarray) -> tuple[float, float]:
    """Search range of the Stribeck velocity ``v_s`` [mm/s] for given data.

    From 1e-3 to 1 times the largest speed in the data (the 99.9th percentile
    of ``|v|``, robust to single outliers; the maximum if fewer samples move).

    Parameters
    ----------
    velocity : ndarray, shape (n,)
        Velocity [mm/s].

    Returns
    -------
    (float, float)
        Lower and upper end of the range [mm/s].

    Raises
    ------
    ValueError
        If the velocity is zero throughout.
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
    check_direction_settings(asymmetric, fit_offset)
    a = coulomb_regressors(velocity, acceleration, asymmetric=asymmetric, fit_offset=fit_offset)
    effort = np.asarray(effort, dtype=float)
    return coulomb_from_normal_equations(a.T @ a, a.T @ effort, asymmetric=asymmetric, fit_offset=fit_offset)


def coulomb_regressors(velocity, acceleration, *, asymmetric: bool = False, fit_offset: bool = False) -> np.ndarray:
    """Regressors of the Coulomb + viscous model of :func:`fit_coulomb`, one column per parameter.

    Parameters
    ----------
    velocity : ndarray, shape (n,)
        Velocity [mm/s].
    acceleration : ndarray, shape (n,)
        Acceleration [mm/s^2].
    asymmetric : bool, default False
        Separate Coulomb and viscous levels for positive and negative motion.
    fit_offset : bool, default False
        Append a constant column for an offset.

    Returns
    -------
    ndarray, shape (n, p)
        ``a, sgn(v), v`` (symmetric) or ``a, [v > 0], -[v < 0], v [v > 0], v [v < 0]`` (asymmetric), then
        ``1`` with the offset; the parameters in the order of :func:`coulomb_from_normal_equations`.
    """
    v = np.asarray(velocity, dtype=float)
    acceleration = np.asarray(acceleration, dtype=float)
    positive = (v > 0.0).astype(float)
    negative = (v < 0.0).astype(float)
    if asymmetric:
        columns = [acceleration, positive, -negative, v * positive, v * negative]
    else:
        columns = [acceleration, np.sign(v), v]
    if fit_offset:
        columns.append(np.ones_like(v))
    return np.column_stack(columns)


def coulomb_from_normal_equations(gram, rhs, *, asymmetric: bool = False, fit_offset: bool = False,
                                  ) -> dict[str, float]:
    """The fit of :func:`fit_coulomb` from the normal equations of :func:`coulomb_regressors`.

    Parameters
    ----------
    gram : ndarray, shape (p, p)
        ``R.T @ R`` of the regressors ``R`` [products of the regressors' units].
    rhs : ndarray, shape (p,)
        ``R.T @ y`` of the regressors and the effort [regressor unit times A].
    asymmetric : bool, default False
        The regressors have separate levels per direction of motion.
    fit_offset : bool, default False
        The regressors end with the offset's constant column.

    Returns
    -------
    dict
        As :func:`fit_coulomb`, the inertia held non-negative.
    """
    lower = np.full(np.shape(rhs)[0], -np.inf)
    lower[0] = 0.0
    x = [float(value) for value in bounded_normal_solve(gram, rhs, lower=lower)]
    if asymmetric:
        return {"J": x[0], "coulomb_pos": x[1], "coulomb_neg": x[2], "viscous_pos": x[3],
                "viscous_neg": x[4], "offset": 0.0}
    return {"J": x[0], "coulomb_pos": x[1], "coulomb_neg": x[1], "viscous_pos": x[2],
            "viscous_neg": x[2], "offset": x[3] if fit_offset else 0.0}


def stribeck_regressors(velocity, acceleration, v_s, fit_offset: bool) -> np.ndarray:
    """Regressors of the Stribeck + viscous model for given Stribeck velocities.

    Parameters
    ----------
    velocity, acceleration : ndarray, shape (n,)
        Velocity [mm/s] and acceleration [mm/s^2].
    v_s : float or (float, float)
        Stribeck velocity [mm/s], or the pair ``(v_s+, v_s-)`` for positive and
        negative motion (asymmetric model).
    fit_offset : bool
        Append a column of ones for the offset.

    Returns
    -------
    ndarray, shape (n, p)
        With ``e = exp(-|v|/v_s)``: columns ``a``, ``sgn(v) (1 - e)``,
        ``sgn(v) e``, ``v`` (and ``1``), whose coefficients are ``J``, ``F_c``,
        ``F_s``, ``mu`` (and the offset). For a pair, with ``e+``, ``e-`` of
        ``v_s+``, ``v_s-``: ``a``, ``[v>0] (1 - e+)``, ``[v>0] e+``,
        ``-[v<0] (1 - e-)``, ``-[v<0] e-``, ``v [v>0]``, ``v [v<0]`` (and ``1``)
        for ``J``, ``F_c+``, ``F_s+``, ``F_c-``, ``F_s-``, ``mu+``, ``mu-``
        (and the offset); the levels of negative motion are magnitudes.
    """
    v = np.asarray(velocity, dtype=float)
    if np.ndim(v_s) == 0:
        directions, viscous = [(np.sign(v), v_s)], [v]
    else:
        positive, negative = (v > 0.0).astype(float), (v < 0.0).astype(float)
        directions, viscous = [(positive, v_s[0]), (-negative, v_s[1])], [v * positive, v * negative]
    columns = [acceleration]
    for sign, scale in directions:
        e = np.exp(-np.abs(v) / scale)
        columns += [sign * (1.0 - e), sign * e]
    columns += viscous
    if fit_offset:
        columns.append(np.ones_like(v))
    return np.column_stack(columns)


class _StribeckColumns:
    """The matrix of :func:`stribeck_regressors`, kept between trial Stribeck velocities of one fit.

    Only the columns of a direction whose ``v_s`` changed are written again, with the same operations as
    :func:`stribeck_regressors` (so the same values to the last bit): the coordinate search of the asymmetric
    fit moves one direction at a time, and neither the other direction's columns nor the motion columns are
    built again for each of its some 200 trials.
    """

    def __init__(self, velocity, acceleration, asymmetric: bool, fit_offset: bool):
        v = np.asarray(velocity, dtype=float)
        if asymmetric:
            positive, negative = (v > 0.0).astype(float), (v < 0.0).astype(float)
            self.signs, viscous = [positive, -negative], [v * positive, v * negative]
        else:
            self.signs, viscous = [np.sign(v)], [v]
        self.speed = np.abs(v)
        fixed = viscous + ([np.ones_like(v)] if fit_offset else [])
        self.matrix = np.empty((v.size, 1 + 2 * len(self.signs) + len(fixed)))
        self.matrix[:, 0] = acceleration
        for j, column in enumerate(fixed):
            self.matrix[:, 1 + 2 * len(self.signs) + j] = column
        self.scales = [None] * len(self.signs)

    def at(self, v_s) -> np.ndarray:
        """The regressors at ``v_s`` (a float, or the pair of an asymmetric fit); the array is reused."""
        for d, scale in enumerate([v_s] if np.ndim(v_s) == 0 else list(v_s)):
            if self.scales[d] != scale:
                e = np.exp(-self.speed / scale)
                self.matrix[:, 1 + 2 * d] = self.signs[d] * (1.0 - e)
                self.matrix[:, 2 + 2 * d] = self.signs[d] * e
                self.scales[d] = scale
        return self.matrix


def _stribeck_bounds(asymmetric: bool, fit_offset: bool):
    lower = [0.0] * (7 if asymmetric else 4) + ([-np.inf] if fit_offset else [])
    return np.array(lower), np.full(len(lower), np.inf)


def _refine(cost, left: float, right: float, x: float, fx: float) -> tuple[float, float]:
    """Bounded scalar minimisation of ``cost`` on ``[left, right]``; the point ``x`` of cost ``fx`` unless beaten."""
    refined = minimize_scalar(cost, bounds=(left, right), method="bounded", options={"xatol": _XATOL})
    return (float(refined.x), float(refined.fun)) if refined.fun < fx else (x, fx)


def _grid_search(cost, grid: np.ndarray) -> tuple[float, float]:
    """Minimiser of ``cost`` over ``grid``, refined between the grid neighbours of the best point, and its cost."""
    costs = [cost(g) for g in grid]
    best = int(np.argmin(costs))
    return _refine(cost, grid[max(best - 1, 0)], grid[min(best + 1, len(grid) - 1)], grid[best], costs[best])


def _along(cost, point: np.ndarray, axis: int, value: float) -> float:
    """``cost`` at ``point`` with coordinate ``axis`` replaced by ``value``."""
    trial = point.copy()
    trial[axis] = value
    return cost(trial)


def _coordinate_search(cost, grid: np.ndarray) -> np.ndarray:
    """Minimiser ``(log v_s+, log v_s-)`` of ``cost``, searched one direction at a time.

    Starts from the best common value (grid search of ``cost(g, g)``); the first
    round searches each direction over the whole ``grid``, the later ones refine
    within one grid step of the present value, until a round moves neither
    coordinate by more than the tolerance (at most :data:`_MAX_ROUNDS` rounds).
    """
    common, f = _grid_search(lambda g: cost(np.array([g, g])), grid)
    x = np.array([common, common])
    step = grid[1] - grid[0]
    for round_ in range(_MAX_ROUNDS):
        previous = x.copy()
        for axis in (0, 1):
            along = partial(_along, cost, x.copy(), axis)
            if round_ == 0:
                g, fg = _grid_search(along, grid)
            else:
                g, fg = _refine(along, max(x[axis] - step, grid[0]), min(x[axis] + step, grid[-1]), x[axis], f)
            if fg < f:
                x[axis], f = g, fg
        if np.max(np.abs(x - previous)) <= _XATOL:
            break
    return x


def fit_stribeck(velocity, acceleration, effort, *, asymmetric: bool = False, fit_offset: bool = False,
                 v_s_range: tuple[float, float] | None = None) -> dict[str, float]:
    """Stribeck + viscous friction and inertia by separable least squares.

    Parameters
    ----------
    velocity, acceleration, effort : ndarray, shape (n,)
        Velocity [mm/s], acceleration [mm/s^2], current [A] (or force [N]).
    asymmetric : bool, default False
        Separate Stribeck curve (``F_c``, ``F_s``, ``v_s``) and viscous
        coefficient for positive and negative motion.
    fit_offset : bool, default False
        Fit a constant offset [A].
    v_s_range : (float, float), optional
        Search range of ``v_s`` [mm/s] (of both directions);
        :func:`velocity_range` of the data by default.

    Returns
    -------
    dict
        ``J`` [A s^2/mm], ``coulomb`` ``F_c`` [A], ``static`` ``F_s`` [A],
        ``v_s`` [mm/s], ``viscous`` ``mu`` [A s/mm], ``offset`` [A] (0 when not
        fitted) and ``sse`` (sum of squared residuals [A^2]). If
        ``asymmetric``, ``coulomb``, ``static``, ``v_s`` and ``viscous`` are
        those of positive motion and ``coulomb_neg``, ``static_neg`` (level
        magnitudes [A]), ``v_s_neg`` [mm/s] and ``viscous_neg`` [A s/mm] those
        of negative motion. ``J`` and all friction levels and viscous
        coefficients are constrained non-negative.

    Raises
    ------
    ParameterError
        If ``asymmetric`` and ``fit_offset`` are both requested (the offset is
        then not separable from the two Stribeck curves).
    """
    check_direction_settings(asymmetric, fit_offset)
    lo, hi = velocity_range(velocity) if v_s_range is None else v_s_range
    lower, upper = _stribeck_bounds(asymmetric, fit_offset)

    columns = _StribeckColumns(velocity, acceleration, asymmetric, fit_offset)

    def sse(log_v_s):
        v_s = tuple(np.exp(log_v_s)) if asymmetric else float(np.exp(log_v_s))
        residual = bounded_lstsq(columns.at(v_s), effort, lower, upper)[1]
        return float(residual @ residual)

    grid = np.linspace(np.log(lo), np.log(hi), _N_GRID)
    with threadpool_limits(limits=1, user_api="blas"):  # tall-and-thin products: no gain from threads
        if asymmetric:
            v_s = tuple(float(value) for value in np.exp(_coordinate_search(sse, grid)))
        else:
            v_s = float(np.exp(_grid_search(sse, grid)[0]))
        x, residual = bounded_lstsq(stribeck_regressors(velocity, acceleration, v_s, fit_offset), effort,
                                    lower, upper)
    x = [float(value) for value in x]
    if asymmetric:
        return {"J": x[0], "coulomb": x[1], "static": x[2], "v_s": v_s[0], "viscous": x[5],
                "coulomb_neg": x[3], "static_neg": x[4], "v_s_neg": v_s[1], "viscous_neg": x[6],
                "offset": 0.0, "sse": float(residual @ residual)}
    return {"J": x[0], "coulomb": x[1], "static": x[2], "viscous": x[3], "v_s": v_s,
            "offset": x[4] if fit_offset else 0.0, "sse": float(residual @ residual)}
