"""The kernel engine of the SVR models: fitting a support vector expansion and evaluating it fast.

:func:`fit_svr_expansion` standardises the inputs, chooses the hyperparameters (C, epsilon, gamma,
and kernel weights) by Bayesian optimisation over a time-blocked cross-validation, trains on a subset
that covers the input space, and keeps the expansion as plain arrays (:class:`SVRExpansion`: support
vectors, dual coefficients, intercept). :class:`KernelFrame` holds a fitted model's expansion and
hand-over box in the coordinates the compiled kernels (:func:`frame_terms`, :func:`outside_rows`,
:func:`coordinate_rows`) evaluate, checked once. The model classes that use it are in
:mod:`greybox.models.svr` and :mod:`greybox.models.gmssvr`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Callable, Mapping, Sequence

import numba
import numpy as np
from numba import njit

from ...errors import ParameterError, Setting, SettingWarning
from ...identify.bayes import minimize_log_uniform
from ...identify.cv import blocked_folds
from ...identify.progress import ProgressEvent
from ..handover import handover_rows, handover_weight
from .rbf import BLOCK_SAMPLES, _expansion_blocks, add_expansion, expansion_cutoff, rbf_expansion, threads_for
from .subset import coverage_subset

__all__ = ["HYPERPARAMETERS", "WEIGHT_BOUNDS", "KernelFrame", "SVRExpansion", "coordinate_rows", "default_bounds",
           "fit_svr_expansion", "frame_terms", "outside_rows"]

#: Names of the SVR hyperparameters, in the order of the paper's Table 2.
HYPERPARAMETERS = ("epsilon", "C", "gamma")

#: Search interval of an input weight (see ``weighted`` of :func:`fit_svr_expansion`): the weight multiplies
#: the input's squared standardised distance in the kernel, so 1e4 makes the kernel 100 times narrower in
#: that input than in the unweighted ones, 1e-2 ten times wider.
WEIGHT_BOUNDS = (1e-2, 1e4)

#: At most this many test samples per cross-validation fold are predicted
#: (an even stride through the fold), to bound the cost of one evaluation.
MAX_TEST_SAMPLES_PER_FOLD = 20_000


def default_bounds(target_std: float) -> dict[str, tuple[float, float]]:
    """Search intervals of the hyperparameters for a target of spread ``target_std``.

    Parameters
    ----------
    target_std : float
        Standard deviation of the SVR's target [A].

    Returns
    -------
    dict
        ``epsilon`` in ``[1e-3, 0.5] * target_std`` [A], ``C`` in
        ``[1e-2, 1e2] * target_std`` [A] (larger C makes libsvm's training
        time explode without a visible gain), ``gamma`` in ``[1e-2, 1e3]``
        [1/(standardised unit)^2].
    """
    scale = float(target_std) if np.isfinite(target_std) and target_std > 0 else 1.0
    return {
        "epsilon": (1e-3 * scale, 0.5 * scale),
        "C": (1e-2 * scale, 1e2 * scale),
        "gamma": (1e-2, 1e3),
    }


def _default_value(name: str, target_std: float, n_features: int) -> float:
    """Hyperparameter used when it is neither given nor optimised."""
    scale = float(target_std) if np.isfinite(target_std) and target_std > 0 else 1.0
    return {"epsilon": 0.05 * scale, "C": 3.0 * scale, "gamma": 1.0 / n_features}[name]


@dataclass
class SVRExpansion:
    """A fitted RBF support vector regression as plain arrays.

    Attributes
    ----------
    input_mean, input_scale : ndarray, shape (n_features,)
        Standardisation of the inputs: ``x_std = (x - mean) / scale``.
    support_vectors : ndarray, shape (n_support, n_features)
        In standardised coordinates.
    dual_coef : ndarray, shape (n_support,)
        Dual coefficients [unit of the target].
    intercept : float
        [unit of the target].
    hyperparameters : dict
        ``epsilon`` and ``C`` [unit of the target], ``gamma`` [1/(standardised unit)^2].
    optimised : list of str
        Names of the hyperparameters chosen by the Bayesian optimisation.
    cv_rmse : float
        Cross-validated RMSE at the chosen hyperparameters [unit of the
        target]; NaN when nothing was optimised.
    history : list of dict
        Every evaluation of the optimisation: hyperparameters and ``cv_rmse``.
    at_bounds : list of str
        Optimised hyperparameters that ended at an end of their search
        interval (within 1 % of its width in log scale): the optimum may lie
        outside it.
    n_train : int
        Number of training samples (the subset).
    input_weights : ndarray, shape (n_features,)
        Weight of each input's squared standardised distance in the kernel,
        ``K(x, x') = exp(-gamma sum_d w_d (x_d - x'_d)^2)``; the support
        vectors are stored multiplied by ``sqrt(w)``. Ones unless some inputs
        were weighted.
    """

    input_mean: np.ndarray
    input_scale: np.ndarray
    support_vectors: np.ndarray
    dual_coef: np.ndarray
    intercept: float
    hyperparameters: dict[str, float]
    optimised: list[str] = field(default_factory=list)
    cv_rmse: float = float("nan")
    history: list[dict[str, float]] = field(default_factory=list)
    at_bounds: list[str] = field(default_factory=list)
    n_train: int = 0
    input_weights: np.ndarray | None = None


def _train(X, y, hyper: Mapping[str, float]):
    """Train libsvm on standardised ``X``; return (support vectors, dual coefficients, intercept)."""
    from sklearn.svm import SVR

    svr = SVR(kernel="rbf", C=hyper["C"], epsilon=hyper["epsilon"], gamma=hyper["gamma"], cache_size=500)
    svr.fit(X, y)
    return svr.support_vectors_.copy(), svr.dual_coef_.ravel().copy(), float(svr.intercept_[0])


def fit_svr_expansion(
    X,
    y,
    coverage,
    run_lengths: Sequence[int],
    *,
    fixed: Mapping[str, float | None],
    n_subset: int,
    optimize: bool,
    n_calls: int,
    cv_folds: int,
    cv_blocks: int,
    bounds: Mapping[str, tuple[float, float]] | None,
    random_state: int,
    progress: Callable[[ProgressEvent], None] | None = None,
    stage: str = "SVR hyperparameters",
    weighted: Mapping[str, int] | None = None,
) -> SVRExpansion:
    """Standardise, choose hyperparameters, train on a covering subset.

    Parameters
    ----------
    X : ndarray, shape (n_samples, n_features)
        Raw inputs, the runs concatenated in order.
    y : ndarray, shape (n_samples,)
        Target [A].
    coverage : ndarray, shape (n_samples, k)
        Features whose plane the training subset must cover (position and
        velocity), see :func:`greybox.models.kernel.subset.coverage_subset`.
    run_lengths : sequence of int
        Samples per run, so that cross-validation blocks never span runs.
    fixed : dict
        ``{name: value or None}`` for ``epsilon``, ``C``, ``gamma`` and the
        names of ``weighted``; a value is kept as given, ``None`` is optimised
        (or defaulted, see below).
    n_subset : int
        Training samples (in every fold and in the final fit).
    optimize : bool
        Optimise the ``None`` hyperparameters; when false they take
        defaults: ``epsilon = 0.05 std(y)``, ``C = 3 std(y)``,
        ``gamma = 1 / n_features``.
    n_calls, cv_folds, cv_blocks : int
        Bayesian optimisation budget and cross-validation layout
        (see :func:`greybox.identify.cv.blocked_folds`).
    bounds : dict, optional
        Search intervals overriding :func:`default_bounds`.
    random_state : int
        Seed of the subsets and of the optimisation.
    progress : callable, optional
        Receives a :class:`~greybox.identify.progress.ProgressEvent` per
        evaluation; its cost is the CV mean squared error over ``var(y)``.
    stage : str
        Stage name in the progress events.
    weighted : dict, optional
        ``{name: column}``: input columns whose squared standardised distance
        the kernel weighs by a hyperparameter of that name (an anisotropic
        Gaussian kernel; the unweighted columns have weight 1, and ``gamma``
        sets the overall width). Searched over :data:`WEIGHT_BOUNDS` in log
        scale when optimised, 1 when defaulted.

    Returns
    -------
    SVRExpansion
    """
    if not isinstance(random_state, (int, np.integer)) or isinstance(random_state, bool):
        raise ParameterError(Setting("random_state", assign=False), f" must be an integer seed, got {random_state!r}")
    X = np.asarray(X, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    n_features = X.shape[1]
    mean = X.mean(axis=0)
    scale = X.std(axis=0)
    scale[~(scale > 0)] = 1.0
    Xs = (X - mean) / scale
    target_std = float(np.std(y))
    variance = target_std**2 if target_std > 0 else 1.0

    weighted = dict(weighted or {})
    if any(not 0 <= column < n_features for column in weighted.values()):
        raise ParameterError(f"weighted names input columns {sorted(weighted.values())}; the inputs have "
                             f"{n_features} columns")
    names = HYPERPARAMETERS + tuple(weighted)
    unknown = [name for name in list(fixed) + list(bounds or {}) if name not in names]
    if unknown:
        raise ParameterError(f"unknown SVR hyperparameter(s) {unknown}; expected {names}")

    def weights(values: Mapping[str, float]) -> np.ndarray:
        out = np.ones(n_features)
        for name, column in weighted.items():
            out[column] = values[name]
        return out

    hyper: dict[str, float] = {}
    for name in names:
        value = fixed.get(name)
        if value is not None:
            smallest_allowed = 0.0 if name == "epsilon" else np.nextafter(0.0, 1.0)
            if not (np.isfinite(value) and value >= smallest_allowed):
                kind = "non-negative" if name == "epsilon" else "positive"
                raise ParameterError(f"SVR hyperparameter {name} must be {kind} and finite, got {value}")
            hyper[name] = float(value)
    free = [name for name in names if name not in hyper]

    history: list[dict[str, float]] = []
    cv_rmse = float("nan")
    optimised: list[str] = []
    at_bounds: list[str] = []
    if optimize and free:
        search = {**default_bounds(target_std), **{name: WEIGHT_BOUNDS for name in weighted}}
        search.update(bounds or {})
        folds = blocked_folds(run_lengths, n_folds=cv_folds, n_blocks=cv_blocks)
        prepared = []
        for k, (train, test) in enumerate(folds):
            chosen = train[coverage_subset(coverage[train], n_subset, random_state=random_state + k)]
            step = max(1, test.size // MAX_TEST_SAMPLES_PER_FOLD)
            prepared.append((chosen, test[::step]))

        best = [np.inf]

        def objective(params: dict[str, float]) -> float:
            trial = {**hyper, **params}
            Xw = Xs * np.sqrt(weights(trial)) if weighted else Xs
            squared, count = 0.0, 0
            for chosen, test in prepared:
                sv, alpha, b = _train(Xw[chosen], y[chosen], trial)
                error = rbf_expansion(Xw[test], sv, alpha, b, trial["gamma"]) - y[test]
                squared += float(error @ error)
                count += test.size
            return float(np.sqrt(squared / count))

        def report(i: int, params: dict[str, float], value: float) -> None:
            best[0] = min(best[0], value)
            if progress is not None:
                progress(ProgressEvent(stage=stage, start=0, n_starts=1, evaluation=i + 1,
                                       cost=value**2 / variance, best=best[0] ** 2 / variance,
                                       done=i + 1 == n_calls))

        chosen_params, trials = minimize_log_uniform(
            objective, {name: search[name] for name in free}, n_calls=n_calls,
            random_state=random_state, progress=report)
        hyper.update(chosen_params)
        optimised = list(free)
        history = [{**{k: v for k, v in t.items() if k != "objective"}, "cv_rmse": t["objective"]} for t in trials]
        cv_rmse = min(t["objective"] for t in trials)
        at_bounds = [name for name in free if _near_bound(hyper[name], search[name])]
        if at_bounds:
            warnings.warn(SettingWarning(
                f"{stage}: {', '.join(f'{n} = {hyper[n]:.3g}' for n in at_bounds)} ended at the end of "
                "its search interval; the optimum may lie outside (widen it with ", Setting("bounds", keys=at_bounds),
                ")"), stacklevel=3)
    else:
        for name in free:
            hyper[name] = 1.0 if name in weighted else _default_value(name, target_std, n_features)

    chosen = coverage_subset(coverage, n_subset, random_state=random_state)
    input_weights = weights(hyper)
    sv, alpha, b = _train(Xs[chosen] * np.sqrt(input_weights), y[chosen], hyper)
    return SVRExpansion(
        input_mean=mean, input_scale=scale, support_vectors=sv, dual_coef=alpha, intercept=b,
        hyperparameters={name: hyper[name] for name in names}, optimised=optimised,
        cv_rmse=cv_rmse, history=history, at_bounds=at_bounds, n_train=int(chosen.size),
        input_weights=input_weights,
    )


def _check_bounds(bounds, names: Sequence[str] = HYPERPARAMETERS) -> None:
    """Raise :class:`ParameterError` unless ``bounds`` is None or ``{name: (low, high)}`` with 0 < low < high < inf
    and every name one of ``names``."""
    if bounds is None:
        return
    if not isinstance(bounds, Mapping):
        raise ParameterError(f"bounds must map hyperparameter names to (low, high), got {bounds!r}")
    for name, interval in bounds.items():
        if name not in names:
            raise ParameterError(f"bounds name an unknown SVR hyperparameter {name!r}; expected {tuple(names)}")
        try:
            low, high = (float(value) for value in interval)
        except (TypeError, ValueError):
            raise ParameterError(f"bounds of {name!r} must be two numbers (low, high), got {interval!r}") from None
        if not (0.0 < low < high < np.inf):
            raise ParameterError(f"bounds of {name!r} must satisfy 0 < low < high < inf, got {interval!r}")


def _near_bound(value: float, interval: tuple[float, float], fraction: float = 0.01) -> bool:
    """True if ``value`` lies within ``fraction`` of the log-width of ``interval`` from either end."""
    low, high = np.log(interval[0]), np.log(interval[1])
    margin = fraction * (high - low)
    return bool(np.log(value) <= low + margin or np.log(value) >= high - margin)


class KernelFrame:
    """The coordinates of a fitted kernel model's expansion and its hand-over box, checked once.

    Raw SVR inputs are standardised and multiplied by the square root of their kernel weight; the
    hand-over (:mod:`greybox.models.handover`) tapers the correction beyond the box of the training
    inputs in those coordinates. A stream of chunks builds the frame once instead of per chunk.

    Parameters
    ----------
    model : KernelRegressionModel
        A fitted kernel model.

    Raises
    ------
    ParameterError
        For kernel weights that are not one positive number per input.
    """

    def __init__(self, model: "KernelRegressionModel"):  # noqa: F821 (greybox.models.svr, which imports this module)
        self.model = model
        self.mean = model.input_mean_
        self.scale = model.input_scale_
        weights = getattr(model, "input_weights_", None)  # None: a file that predates the weights (all 1)
        if weights is not None and (np.shape(weights) != np.shape(self.scale) or not np.all(np.asarray(weights) > 0)):
            raise ParameterError(f"input_weights_ must hold one positive weight per input "
                                 f"({np.size(self.scale)}), got {weights!r}")
        self.root_weights = None if weights is None else np.sqrt(weights)
        n_features = np.size(self.scale)
        self._rows = tuple(np.ascontiguousarray(values, dtype=np.float64).reshape(n_features) for values in (
            self.mean, self.scale, np.ones(n_features) if self.root_weights is None else self.root_weights))
        self.width = getattr(model, "handover_width_", None)
        self.box = None if self.width is None else self.coordinates(model.input_range_)
        self._compiled = None

    def _arguments(self):
        """The arrays of :func:`frame_terms`, made contiguous once (support vectors column-wise)."""
        if self._compiled is None:
            m = self.model
            n_features = np.size(self.scale)
            alpha = np.ascontiguousarray(m.dual_coef_, dtype=np.float64).ravel()
            cutoff = expansion_cutoff(alpha)
            ranges = getattr(m, "input_range_", None)
            box = (np.zeros((2, n_features)), 0.0) if self.width is None else (np.asarray(self.box), float(self.width))
            as_row = lambda values: np.ascontiguousarray(values, dtype=np.float64).reshape(n_features)  # noqa: E731
            self._compiled = (
                *self._rows, np.ascontiguousarray(np.asarray(m.support_vectors_, dtype=np.float64).T), alpha,
                float(m.intercept_), float(m.gamma_), -1.0 if cutoff is None else cutoff,
                as_row(box[0][0]), as_row(box[0][1]), box[1],
                as_row(np.zeros(n_features) if ranges is None else ranges[0]),
                as_row(np.zeros(n_features) if ranges is None else ranges[1]),
                self.width is not None, ranges is not None)
        return self._compiled

    def terms(self, X):
        """Expansion, hand-over weight and input-range flags of raw inputs ``X`` in one compiled pass.

        A chunk of a log long enough to share (:func:`~greybox.models.kernel.rbf.threads_for` of two threads)
        has its kernel sums added by :func:`~greybox.models.kernel.rbf.add_expansion`, dealt out over the threads
        of :func:`numba.get_num_threads` (one or more): the same compiled code whatever their number, so the
        same sums to the last bit.

        What :meth:`expansion`, :meth:`weight` and the model's ``"inputs"`` flag give, for the few samples of
        a live message: the per-call checks and copies of :func:`~greybox.models.kernel.rbf.rbf_expansion` are done
        once per frame.

        Parameters
        ----------
        X : array_like, shape (n, n_features)
            Raw SVR inputs (their units: mm, A, mm/s, ...).

        Returns
        -------
        expansion : ndarray, shape (n,)
            The fitted expansion [A].
        weight : ndarray of shape (n,), or None
            Weight of the correction; None for a model without the hand-over.
        outside : ndarray of bool, shape (n,), or None
            True where an input lies outside its training range; None for a file without the ranges.
        """
        X = np.ascontiguousarray(X, dtype=np.float64)
        arguments = self._arguments()
        expansion, weight, outside = np.empty(len(X)), np.empty(len(X)), np.empty(len(X), dtype=np.bool_)
        support_t, alpha, _, gamma, cutoff = arguments[3:8]
        if threads_for(len(X), 2) == 1 or cutoff < 0.0:  # the few samples of a live message: one call
            frame_terms(X, *arguments, expansion, weight, outside)
        else:  # a chunk of a log: the kernel sums (over threads), the rest in one pass without them
            frame_terms(X, *arguments[:7], -1.0, *arguments[8:], expansion, weight, outside)
            add_expansion(self.coordinates(X), support_t, alpha, gamma, cutoff, expansion, numba.get_num_threads())
        return expansion, (weight if arguments[-2] else None), (outside if arguments[-1] else None)

    def coordinates(self, X) -> np.ndarray:
        """Raw inputs ``X``, shape (n, n_features), in the kernel's coordinates: standardised, times sqrt(weight).

        Parameters
        ----------
        X : array_like, shape (n, n_features)
            Raw SVR inputs (their units: mm, A, mm/s, ...).
        """
        X = np.ascontiguousarray(X, dtype=np.float64)
        out = np.empty(X.shape)
        coordinate_rows(X, *self._rows, out)
        return out

    def expansion(self, X, scaled=None) -> np.ndarray:
        """The fitted expansion at raw inputs ``X`` [A].

        Parameters
        ----------
        X : array_like, shape (n, n_features)
            Raw SVR inputs.
        scaled : ndarray, optional
            ``coordinates(X)`` when already at hand.
        """
        m = self.model
        return rbf_expansion(self.coordinates(X) if scaled is None else scaled, m.support_vectors_, m.dual_coef_,
                             m.intercept_, m.gamma_)

    def weight(self, X, scaled=None) -> np.ndarray | None:
        """Weight of the correction at raw inputs ``X``; None for a model without the hand-over.

        Parameters
        ----------
        X : array_like, shape (n, n_features)
            Raw SVR inputs.
        scaled : ndarray, optional
            ``coordinates(X)`` when already at hand.
        """
        if self.width is None:
            return None
        return handover_weight(self.coordinates(X) if scaled is None else scaled, self.box[0], self.box[1],
                               self.width)


@njit(cache=True, nogil=True, error_model="numpy")
def outside_rows(X, low, high, out):
    """True in ``out`` where any input of a row of ``X`` lies outside ``[low, high]``.

    Parameters
    ----------
    X : ndarray, shape (n, n_features)
        Raw SVR inputs.
    low, high : ndarray, shape (n_features,)
        Lowest and highest value of each input over the training data.
    out : ndarray of bool, shape (n,)
        Receives the flags.
    """
    for i in range(X.shape[0]):
        outside = False
        for f in range(X.shape[1]):
            outside = outside or X[i, f] < low[f] or X[i, f] > high[f]
        out[i] = outside


@njit(cache=True, nogil=True, error_model="numpy")
def frame_terms(X, mean, scale, root_weights, support_t, alpha, intercept, gamma, cutoff, box_low, box_high, width,
                range_low, range_high, has_box, has_range, expansion, weight, outside):
    """The kernel sum, the hand-over weight and the input-range flags of the rows of ``X``, in one call.

    Parameters
    ----------
    X : ndarray, shape (n, n_features)
        Raw SVR inputs.
    mean, scale, root_weights : ndarray, shape (n_features,)
        The kernel's coordinates: ``(X - mean) / scale * root_weights``.
    support_t : ndarray, shape (n_features, n_support)
        Support vectors, column-wise, in those coordinates.
    alpha : ndarray, shape (n_support,)
        Dual coefficients [A].
    intercept : float
        Intercept [A].
    gamma : float
        Kernel parameter [1/(coordinate unit)^2].
    cutoff : float
        :func:`~greybox.models.kernel.rbf.expansion_cutoff`; negative: no term counts.
    box_low, box_high : ndarray, shape (n_features,)
        Hand-over box in the kernel's coordinates.
    width : float
        Hand-over width [coordinate unit].
    range_low, range_high : ndarray, shape (n_features,)
        Training range of the raw inputs.
    has_box, has_range : bool
        Whether ``weight`` and ``outside`` are to be filled.
    expansion, weight : ndarray, shape (n,)
        Receive the expansion [A] and the weight.
    outside : ndarray of bool, shape (n,)
        Receives the flags.
    """
    scaled = np.empty(X.shape)
    coordinate_rows(X, mean, scale, root_weights, scaled)
    expansion[:] = intercept
    if cutoff >= 0.0:
        _expansion_blocks(scaled, support_t, alpha, gamma, cutoff, BLOCK_SAMPLES, 0, 1, expansion)
    if has_box:
        handover_rows(scaled, box_low, box_high, width, weight)
    if has_range:
        outside_rows(X, range_low, range_high, outside)


@njit(cache=True, nogil=True, error_model="numpy")
def coordinate_rows(X, mean, scale, root_weights, out):
    """Raw inputs in the kernel's coordinates, ``(X - mean) / scale * root_weights``, written to ``out``.

    Parameters
    ----------
    X : ndarray, shape (n, n_features)
        Raw SVR inputs.
    mean, scale, root_weights : ndarray, shape (n_features,)
        Mean and scale of each input over the training data, square root of its kernel weight.
    out : ndarray, shape (n, n_features)
        Receives the coordinates.
    """
    for i in range(X.shape[0]):
        for f in range(X.shape[1]):
            out[i, f] = (X[i, f] - mean[f]) / scale[f] * root_weights[f]
