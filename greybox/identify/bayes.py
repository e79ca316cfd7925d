"""Bayesian optimisation of positive hyperparameters (the one interface to scikit-optimize).

Every use of :mod:`skopt` in greybox goes through :func:`minimize_log_uniform`,
so that a change of the optimisation library, or a work-around for one of its
versions, touches this module only.

Compatibility (scikit-optimize 0.10.2 with numpy 2.4 and scikit-learn 1.9):
the ask/tell :class:`skopt.Optimizer` with its default Gaussian-process
surrogate (Matern 5/2 kernel, Gaussian noise, ``gp_hedge`` acquisition) runs
without error or deprecation warning; the removed numpy aliases (``np.int``
and the like) are not used by that path. Three things do need care and are
handled here: skopt accepts only an integer seed (or a legacy
``RandomState``), not a :class:`numpy.random.Generator`; a non-finite
objective value (e.g. a diverged fit) breaks the surrogate fit, so it is
replaced by a finite penalty; and when the surrogate proposes a point it has
already evaluated (typically a corner of the box), skopt draws a random
point instead and says so in a ``UserWarning`` per occurrence, which is
silenced (the point actually evaluated is in the history).
"""

from __future__ import annotations

import math
import warnings
from typing import Callable, Mapping

import numpy as np

__all__ = ["minimize_log_uniform"]


def _check_bounds(bounds: Mapping[str, tuple[float, float]]) -> dict[str, tuple[float, float]]:
    if not bounds:
        raise ValueError("no hyperparameters to optimise: bounds is empty")
    checked = {}
    for name, pair in bounds.items():
        low, high = (float(v) for v in pair)
        if not (0.0 < low < high and math.isfinite(high)):
            raise ValueError(f"bounds of {name!r} must satisfy 0 < low < high < inf, got ({low}, {high})")
        checked[str(name)] = (low, high)
    return checked


def minimize_log_uniform(
    objective: Callable[[dict[str, float]], float],
    bounds: Mapping[str, tuple[float, float]],
    n_calls: int = 30,
    *,
    n_initial_points: int | None = None,
    random_state: int = 0,
    progress: Callable[[int, dict[str, float], float], None] | None = None,
) -> tuple[dict[str, float], list[dict[str, float]]]:
    """Minimise ``objective`` over positive parameters with log-uniform priors.

    A Gaussian-process surrogate (scikit-optimize) proposes each next point;
    the first ``n_initial_points`` points are drawn at random, log-uniformly
    within the bounds. The acquisition function (``gp_hedge``) is minimised
    over 10 000 random points rather than by L-BFGS restarts: as good for the
    two or three dimensions of a hyperparameter search, at half the cost.

    Parameters
    ----------
    objective : callable
        ``objective(params) -> float`` with ``params`` a dict ``{name: value}``;
        smaller is better. A non-finite return value is recorded as given in
        the history but shown to the surrogate as a penalty (the worst finite
        value seen plus ``max(1, |worst|)``, or 1e12 before any).
    bounds : dict of str to (float, float)
        Search interval ``(low, high)`` of each parameter, ``0 < low < high``.
    n_calls : int, default 30
        Number of objective evaluations, >= 1.
    n_initial_points : int, optional
        Random points before the surrogate takes over; by default
        ``min(10, max(1, n_calls // 2))``.
    random_state : int, default 0
        Seed; equal seeds give equal sequences of points.
    progress : callable, optional
        Called as ``progress(i, params, value)`` after evaluation ``i``
        (0-based), e.g. to print or log the search.

    Returns
    -------
    best_params : dict of str to float
        Parameters with the smallest finite objective value (ties: the first).
    history : list of dict
        One dict per evaluation, in order: the parameters plus ``"objective"``.

    Raises
    ------
    ValueError
        On invalid bounds or ``n_calls``, or if no evaluation gave a finite value.
    """
    from skopt import Optimizer
    from skopt.space import Real

    bounds = _check_bounds(bounds)
    n_calls = int(n_calls)
    if n_calls < 1:
        raise ValueError(f"n_calls must be >= 1, got {n_calls}")
    if n_initial_points is None:
        n_initial_points = min(10, max(1, n_calls // 2))
    n_initial_points = int(min(max(1, n_initial_points), n_calls))

    names = list(bounds)
    space = [Real(low, high, prior="log-uniform", name=name) for name, (low, high) in bounds.items()]
    optimizer = Optimizer(
        space,
        base_estimator="GP",
        n_initial_points=n_initial_points,
        initial_point_generator="random",
        acq_func="gp_hedge",
        acq_optimizer="sampling",
        random_state=int(random_state),
    )

    history: list[dict[str, float]] = []
    worst_finite = -math.inf
    best_value, best_params = math.inf, None
    for i in range(n_calls):
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="The objective has been evaluated at point",
                                    category=UserWarning)
            point = optimizer.ask()
        # Guard against the surrogate's optimiser stepping a hair outside the box.
        params = {name: float(np.clip(v, *bounds[name])) for name, v in zip(names, point)}
        value = float(objective(params))
        history.append({**params, "objective": value})
        if math.isfinite(value):
            worst_finite = max(worst_finite, value)
            if value < best_value:
                best_value, best_params = value, params
            told = value
        else:
            told = worst_finite + max(1.0, abs(worst_finite)) if math.isfinite(worst_finite) else 1e12
        optimizer.tell(list(point), told)
        if progress is not None:
            progress(i, params, value)

    if best_params is None:
        raise ValueError(f"the objective was not finite at any of the {n_calls} points tried")
    return best_params, history
