"""Bounded local searches and seeded multi-start for parameter identification.

A problem is given as a residual function ``residuals(theta) -> r`` of the
internal parameter vector ``theta`` (for instance logarithms of positive
parameters), with box bounds on ``theta``; its cost is ``r @ r``. Two local
searches are offered:

- ``"nelder-mead"``: the bounded Nelder-Mead simplex of
  :func:`scipy.optimize.minimize` on the cost (the method used by
  Tjahjowidodo et al. for friction identification); derivative-free and robust
  to the kinks that stick/slip switching puts into the cost;
- ``"least-squares"``: bounded trust-region least squares
  (:func:`scipy.optimize.least_squares`, method ``trf``) on the residuals with
  a finite-difference Jacobian.

:func:`multistart` runs the local search from the initial guess and from
perturbed copies drawn with ``numpy.random.default_rng(random_state)``, so the
same seed always gives the same result.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import least_squares, minimize
from scipy.special import ndtri
from threadpoolctl import threadpool_limits

from ..errors import ParameterError, Setting
from .progress import ProgressEvent

__all__ = ["METHODS", "SearchResult", "Stall", "local_search", "multistart", "multistart_results", "fixed_design"]

#: Names of the local search methods.
METHODS = ("nelder-mead", "least-squares")

#: Relative finite-difference step of the least-squares Jacobian (in the units of theta).
_DIFF_STEP = 1e-3


@dataclass(frozen=True)
class Stall:
    """When a Nelder-Mead search has stalled: its best cost fell by less than ``tolerance`` (relative) over the
    last ``window`` times ``p + 1`` evaluations (``p`` coordinates).

    One Nelder-Mead iteration replaces one vertex of the ``p + 1`` of the simplex (one or two evaluations, a
    shrink ``p + 1``), so ``window`` counts how many times, about, every vertex could have been replaced.

    Attributes
    ----------
    tolerance : float
        Least relative decrease of the best cost [-] that counts as progress.
    window : int
        Evaluations per vertex of the simplex [-] over which the decrease is measured.
    """

    tolerance: float
    window: int

    def evaluations(self, n_coordinates: int) -> int:
        """The evaluations over which the decrease is measured, for a search of ``n_coordinates``.

        Parameters
        ----------
        n_coordinates : int
            Coordinates ``p`` of the search.
        """
        return int(self.window) * (int(n_coordinates) + 1)


class _Stalled(Exception):
    """Raised inside a Nelder-Mead search by a :class:`Stall` rule; the best point so far is the result."""


@dataclass
class SearchResult:
    """Best point found by a search.

    Attributes
    ----------
    x : ndarray
        Best internal parameter vector evaluated.
    cost : float
        Its cost ``r @ r``.
    n_evaluations : int
        Number of residual evaluations.
    start : int
        Index of the start that found ``x`` (0 = the initial guess).
    """

    x: np.ndarray
    cost: float
    n_evaluations: int
    start: int = 0


class _TrackedResiduals:
    """Residual function that remembers the best point and reports progress."""

    def __init__(self, residuals, stage, start, n_starts, progress, best_so_far, stall_after=None,
                 stall_tolerance=0.0):
        self.residuals = residuals
        self.stall_after = stall_after
        self.stall_tolerance = stall_tolerance
        self.bests = []
        self.stage = stage
        self.start = start
        self.n_starts = n_starts
        self.progress = progress
        self.stage_best = best_so_far
        self.n_evaluations = 0
        self.best_x = None
        self.best_cost = np.inf
        self.last_cost = np.inf

    def __call__(self, theta):
        r = self.residuals(theta)
        cost = float(r @ r)
        if not np.isfinite(cost):
            cost = np.inf
        self.n_evaluations += 1
        self.last_cost = cost
        if cost < self.best_cost:
            self.best_cost = cost
            self.best_x = np.array(theta, dtype=float)
        self.stage_best = min(self.stage_best, cost)
        if self.progress is not None:
            self.progress(ProgressEvent(self.stage, self.start, self.n_starts, self.n_evaluations,
                                        cost, self.stage_best))
        if self.stall_after is not None:
            self.bests.append(self.best_cost)
            if (self.n_evaluations > self.stall_after and np.isfinite(self.best_cost)
                    and self.best_cost > (1.0 - self.stall_tolerance) * self.bests[-1 - self.stall_after]):
                raise _Stalled
        return r

    def cost(self, theta):
        r = self(theta)
        return float(r @ r) if np.all(np.isfinite(r)) else np.inf

    def finish(self):
        if self.progress is not None:
            self.progress(ProgressEvent(self.stage, self.start, self.n_starts, self.n_evaluations,
                                        self.last_cost, self.stage_best, done=True))


def check_search_settings(model) -> None:
    """Raise :class:`ParameterError` unless a model's search settings are valid.

    Checks ``method`` (one of :data:`METHODS`), ``n_starts`` and ``max_iter``
    (positive integers) and ``random_state`` (None or a non-negative integer
    seed) of an estimator that fits by :func:`multistart`.
    """
    if model.method not in METHODS:
        raise ParameterError(f"unknown method {model.method!r}; expected one of {METHODS}")
    for name in ("n_starts", "max_iter"):
        value = getattr(model, name)
        if not (isinstance(value, (int, np.integer)) and not isinstance(value, bool) and value >= 1):
            raise ParameterError(Setting(name, assign=False), f" must be a positive integer, got {value!r}")
    check_seed(model.random_state, allow_none=True)


def check_seed(seed, *, name: str = "random_state", allow_none: bool = False) -> None:
    """Raise :class:`ParameterError` unless ``seed`` is a non-negative integer (or None if allowed)."""
    if seed is None and allow_none:
        return
    if not (isinstance(seed, (int, np.integer)) and not isinstance(seed, bool) and seed >= 0):
        raise ParameterError(Setting(name, assign=False), f" must be a non-negative integer seed, got {seed!r}")


def _check_bounds(x0, lower, upper):
    x0 = np.asarray(x0, dtype=float)
    lower = np.asarray(lower, dtype=float)
    upper = np.asarray(upper, dtype=float)
    if not (x0.shape == lower.shape == upper.shape) or np.any(lower >= upper):
        raise ValueError("bounds must have the shape of x0 and lower < upper")
    return np.clip(x0, lower, upper), lower, upper


def local_search(residuals: Callable[[np.ndarray], np.ndarray], x0, lower, upper, *, scale,
                 method: str = "nelder-mead", max_iter: int = 500, stage: str = "fit",
                 progress=None, start: int = 0, n_starts: int = 1,
                 best_so_far: float = np.inf, stall: Stall | None = None) -> SearchResult:
    """One bounded local search from ``x0``.

    Parameters
    ----------
    residuals : callable
        ``residuals(theta) -> ndarray``; the cost is the sum of squares.
    x0 : array_like, shape (p,)
        Starting point (clipped into the bounds).
    lower, upper : array_like, shape (p,)
        Box bounds on ``theta``.
    scale : array_like, shape (p,)
        Typical change of each coordinate: the edge lengths of the initial
        Nelder-Mead simplex, and the variable scaling of least squares.
    method : {"nelder-mead", "least-squares"}
        Local search (see the module notes).
    max_iter : int, default 500
        Nelder-Mead iterations, or least-squares residual evaluations
        (without those of the finite-difference Jacobian).
    stage, start, n_starts, best_so_far
        Labels and running best for the progress events.
    progress : callable, optional
        Receives a :class:`ProgressEvent` after every evaluation.
    stall : Stall, optional
        Also end a Nelder-Mead search once it has stalled (:class:`Stall`); by default it runs until its
        simplex has shrunk (``xatol`` 1e-4 and ``fatol`` 1e-10) or ``max_iter`` ends it. Not used by least
        squares.

    Returns
    -------
    SearchResult
        The best point evaluated during the search.
    """
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; expected one of {METHODS}")
    x0, lower, upper = _check_bounds(x0, lower, upper)
    scale = np.broadcast_to(np.asarray(scale, dtype=float), x0.shape)
    stall_after = stall.evaluations(x0.size) if stall is not None and method == "nelder-mead" else None
    tracked = _TrackedResiduals(residuals, stage, start, n_starts, progress, best_so_far, stall_after,
                                stall.tolerance if stall is not None else 0.0)
    # the residuals are tall-and-thin products: threaded BLAS only adds contention there
    with threadpool_limits(limits=1, user_api="blas"):
        if method == "nelder-mead":
            simplex = np.tile(x0, (x0.size + 1, 1))
            for j in range(x0.size):
                step = scale[j] if x0[j] + scale[j] <= upper[j] else -scale[j]
                simplex[j + 1, j] = np.clip(x0[j] + step, lower[j], upper[j])
            try:
                minimize(tracked.cost, x0, method="Nelder-Mead", bounds=list(zip(lower, upper)),
                         options={"maxiter": int(max_iter), "initial_simplex": simplex,
                                  "xatol": 1e-4, "fatol": 1e-10})
            except _Stalled:
                pass  # the best point so far is the result
        else:
            least_squares(tracked, x0, bounds=(lower, upper), method="trf", x_scale=scale,
                          diff_step=_DIFF_STEP, max_nfev=int(max_iter))
    tracked.finish()
    return SearchResult(tracked.best_x, tracked.best_cost, tracked.n_evaluations, start)


def fixed_design(n_points: int, n_dims: int) -> np.ndarray:
    """Standard-normal deviates of a fixed low-discrepancy design: the same points for every seed and call.

    Point ``k`` (from 1) of the Kronecker sequence ``u_k = frac(k g)``, with
    ``g_j = phi_d^-(j+1)`` and ``phi_d`` the positive root of ``x^(d+1) = x + 1``
    (the generalised golden ratio: the sequence fills the unit cube evenly
    for any number of points), mapped through the normal quantile function.

    Parameters
    ----------
    n_points : int
        Number of points (>= 0).
    n_dims : int
        Dimension d (>= 1).

    Returns
    -------
    ndarray, shape (n_points, n_dims)
        Deviates [-] with the spread of ``N(0, 1)`` draws, for perturbed starts shared by all seeds.
    """
    phi = 2.0
    for _ in range(64):  # fixed-point iteration of x = (1 + x)^(1 / (d + 1))
        phi = (1.0 + phi) ** (1.0 / (n_dims + 1))
    g = phi ** -np.arange(1.0, n_dims + 1.0)
    u = np.mod(0.5 + np.outer(np.arange(1.0, n_points + 1.0), g), 1.0)
    return ndtri(u)


def multistart(residuals: Callable[[np.ndarray], np.ndarray], x0, lower, upper, *, scale,
               n_starts: int = 1, random_state=0, method: str = "nelder-mead",
               max_iter: int = 500, stage: str = "fit", progress=None) -> SearchResult:
    """Bounded local searches from ``x0`` and from seeded perturbations of it.

    Start 0 is ``x0`` itself; start ``j > 0`` is ``x0 + scale * N(0, 1)``
    clipped into the bounds, drawn from ``numpy.random.default_rng(random_state)``.

    Parameters
    ----------
    residuals, x0, lower, upper, scale, method, max_iter, stage, progress
        As in :func:`local_search`.
    n_starts : int, default 1
        Number of local searches.
    random_state : int or None, default 0
        Seed of the perturbations.

    Returns
    -------
    SearchResult
        The best point over all starts; ``n_evaluations`` is the total.
    """
    results = multistart_results(residuals, x0, lower, upper, scale=scale, n_starts=n_starts,
                                 random_state=random_state, method=method, max_iter=max_iter, stage=stage,
                                 progress=progress)
    best = min(results, key=lambda result: (result.cost, result.start))
    best.n_evaluations = sum(result.n_evaluations for result in results)
    return best


def multistart_results(residuals: Callable[[np.ndarray], np.ndarray], x0, lower, upper, *, scale,
                       n_starts: int = 1, random_state=0, method: str = "nelder-mead",
                       max_iter: int = 500, stage: str = "fit", progress=None,
                       fixed_starts=(), deviates=None, stall: Stall | None = None) -> list[SearchResult]:
    """The result of every start, in the order of the starts.

    The starts are ``x0``, then the ``fixed_starts`` (the same for every
    seed: for instance points along a parameter whose cost is known to have
    several basins), then the ``n_starts - 1`` perturbations of ``x0`` of
    :func:`multistart`.

    Parameters
    ----------
    residuals, x0, lower, upper, scale, method, max_iter, stage, progress, n_starts, random_state
        As in :func:`multistart`.
    fixed_starts : sequence of array_like, optional
        Further deterministic starts (clipped into the bounds).
    deviates : array_like, shape (n_starts - 1, p), optional
        The perturbations of ``x0`` in units of ``scale`` (e.g. :func:`fixed_design`), instead of
        seeded ``N(0, 1)`` draws; ``random_state`` is then not used.
    stall : Stall, optional
        The stall rule of every start, as in :func:`local_search`.

    Returns
    -------
    list of SearchResult
        One per start (``n_starts + len(fixed_starts)``); ``n_evaluations`` of each counts its own
        start's evaluations.
    """
    if n_starts < 1:
        raise ValueError(f"n_starts must be at least 1, got {n_starts}")
    x0, lower, upper = _check_bounds(x0, lower, upper)
    scale = np.broadcast_to(np.asarray(scale, dtype=float), x0.shape)
    if deviates is None:
        rng = np.random.default_rng(random_state)
        deviates = [rng.standard_normal(x0.size) for _ in range(n_starts - 1)]
    deviates = np.asarray(deviates, dtype=float).reshape(-1, x0.size)
    if len(deviates) != n_starts - 1:
        raise ValueError(f"{len(deviates)} deviates for {n_starts - 1} perturbed starts")
    starts = [x0] + [np.clip(x0 + scale * deviate, lower, upper) for deviate in deviates]
    starts[1:1] = [np.clip(np.asarray(start, dtype=float), lower, upper) for start in fixed_starts]
    results = []
    for index, start in enumerate(starts):
        best_so_far = min((result.cost for result in results), default=np.inf)
        results.append(local_search(residuals, start, lower, upper, scale=scale, method=method,
                                    max_iter=max_iter, stage=stage, progress=progress, start=index,
                                    n_starts=len(starts), best_so_far=best_so_far, stall=stall))
    return results
