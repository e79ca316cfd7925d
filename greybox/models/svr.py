"""Support vector regression of the motor current: the paper's data-driven benchmark.

:class:`SVRCurrentModel` is the pure SVR model of Rüppel et al. (2024, eq. 9),

    I = J * a + offset + f(p, v),

with an RBF-kernel support vector regression ``f`` of position ``p`` [mm] and
velocity ``v`` [mm/s], both standardised. The inertia ``J`` [A s^2/mm]
(unless given) and the ``offset`` [A] come first, from one linear
least-squares fit of the current to a Coulomb + viscous proxy,

    I ~ J a + F_c sgn(v) + mu v + offset,

over the samples in motion (``|v|`` above 1 % of the largest speed, so that
``sgn(v)`` is defined). Only ``J`` and ``offset`` are kept; the SVR then
learns all of the friction, ``f = I - J a - offset``, including its
Coulomb, viscous and position-dependent parts. ``J a`` has to be taken out
first because the kernel does not see the acceleration.

The machinery shared with the grey-box model
(:class:`greybox.models.gmssvr.GMSSVRModel`) is :func:`fit_svr_expansion`:
standardise the inputs, choose the hyperparameters (C, epsilon, gamma) by
Bayesian optimisation over a time-blocked cross-validation, train on a
subset that covers the (p, v) plane, and keep the kernel expansion as plain
arrays (support vectors, dual coefficients, intercept), evaluated by
:func:`greybox.models.rbf.rbf_expansion`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Callable, Mapping, Sequence

import numpy as np
from numba import njit
from sklearn.utils.validation import check_is_fitted

from ..base import EFFORT, LENGTH, Parameter
from ..data.log import AxisLog
from ..errors import ParameterError, Setting, SettingWarning
from ..estimator import CurrentModel
from ..identify.bayes import minimize_log_uniform
from ..identify.cv import blocked_folds
from ..identify.linear import bounded_lstsq
from ..identify.optimize import check_seed
from ..identify.progress import ProgressEvent
from .chunked import DEFAULT_CHUNK_S, chunk_slices, samples_per_chunk
from .handover import hand_over, handover_rows, handover_weight, handover_width
from .rbf import BLOCK_SAMPLES, _expansion_blocks, expansion_cutoff, rbf_expansion
from .subset import coverage_subset

__all__ = ["KernelFrame",
    "KernelRegressionModel",
    "SVRCurrentModel",
    "SVRExpansion",
    "fit_svr_expansion",
    "coulomb_viscous_proxy",
    "default_bounds",
    "HYPERPARAMETERS",
    "BOUNDED",
    "WEIGHT_BOUNDS",
]

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
        velocity), see :func:`greybox.models.subset.coverage_subset`.
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


def coulomb_viscous_proxy(runs: Sequence[AxisLog], inertia: float | None = None
                          ) -> tuple[float, float, float, float]:
    """Inertia, offset, Coulomb level and viscous coefficient from a Coulomb + viscous least-squares proxy.

    Fits ``I ~ J a + F_c sgn(v) + mu v + offset`` over the samples with
    ``|v| > 0.01 max|v|`` of all runs (all samples if fewer than 4 move),
    with ``J``, ``F_c`` and ``mu`` non-negative.

    Parameters
    ----------
    runs : list of AxisLog
        Prepared runs.
    inertia : float, optional
        Known J [A s^2/mm]; then only the other proxy terms are fitted.

    Returns
    -------
    J : float
        Inertia [A s^2/mm] (or [N s^2/mm] for force logs).
    offset : float
        Constant effort [A] (e.g. a weight share on an inclined axis).
    coulomb : float
        Coulomb level ``F_c`` [A].
    viscous : float
        Viscous coefficient ``mu`` [A s/mm].
    """
    v = np.concatenate([run.velocity for run in runs])
    a = np.concatenate([run.acceleration for run in runs])
    effort = np.concatenate([run.effort for run in runs])
    moving = np.abs(v) > 0.01 * np.max(np.abs(v))
    if np.count_nonzero(moving) < 4:
        moving = np.ones(v.shape, dtype=bool)
    if inertia is not None:
        if not np.isfinite(inertia):
            raise ParameterError(f"inertia must be finite, got {inertia}")
        effort = effort - inertia * a
    design = np.column_stack((np.sign(v), v, np.ones_like(v), a))[moving]
    if inertia is not None:
        design = design[:, :3]
    lower = np.full(design.shape[1], -np.inf)
    lower[:2] = 0.0  # a friction level and a viscous coefficient are never negative
    if inertia is None:
        lower[3] = 0.0  # nor is an identified inertia
    coef, _ = bounded_lstsq(design, effort[moving], lower=lower)
    J = float(inertia) if inertia is not None else float(coef[3])
    return J, float(coef[2]), float(coef[0]), float(coef[1])


class KernelRegressionModel(CurrentModel):
    """Shared parts of the current models with an RBF support vector regression stage.

    The subclass stores the SVR settings ``C``, ``epsilon``, ``gamma``,
    ``n_subset``, ``optimize``, ``n_calls``, ``cv_folds``, ``cv_blocks``,
    ``bounds``, ``random_state`` and ``handover`` (see :class:`SVRCurrentModel`); this class
    checks them, fits the expansion (:func:`fit_svr_expansion`) into the
    learned attributes ``input_mean_``, ``input_scale_``, ``support_vectors_``,
    ``dual_coef_``, ``intercept_``, ``epsilon_``, ``C_``, ``gamma_``,
    ``optimised_``, ``cv_rmse_``, ``search_history_``, ``at_bounds_``,
    ``n_train_``, ``input_weights_`` (the kernel's weight of each input, see
    :class:`SVRExpansion`), ``input_range_`` (the lowest and highest value of each
    input over the training data, shape (2, n_features)) and ``handover_width_`` (see
    :mod:`greybox.models.handover`; None without the hand-over), and evaluates it.
    The subclass weighs its correction by :meth:`_handover` and says what it hands over to.
    A subclass gives the inputs of a chunk of a run by ``_inputs_chunk(run, state, sample_time)``,
    and names in ``_weighted`` (``{setting: input column}``) the settings that weight an input in the kernel.
    """

    #: ``{setting name: input column}`` of the inputs the kernel weighs by a setting of that name.
    _weighted: Mapping[str, int] = {}

    def _check_params(self) -> None:
        names = HYPERPARAMETERS + tuple(self._weighted)
        for name in names:
            value = getattr(self, name)
            smallest_allowed = 0.0 if name == "epsilon" else np.nextafter(0.0, 1.0)
            if value is not None and not (isinstance(value, (int, float, np.number)) and np.isfinite(value)
                                          and value >= smallest_allowed):
                kind = "non-negative" if name == "epsilon" else "positive"
                raise ParameterError(f"SVR hyperparameter {name} must be {kind} and finite, got {value!r}")
        for name, least in (("n_subset", 2), ("n_calls", 1), ("cv_folds", 2), ("cv_blocks", 2)):
            value = getattr(self, name)
            if not (isinstance(value, (int, np.integer)) and not isinstance(value, bool) and value >= least):
                raise ParameterError(Setting(name, assign=False),
                                     f" must be an integer of at least {least}, got {value!r}")
        check_seed(self.random_state)
        self._check_flags("optimize", "handover")
        _check_bounds(self.bounds, names)

    def _fit_kernel(self, X, y, coverage, run_lengths: Sequence[int],
                    progress: Callable[[ProgressEvent], None] | None, *,
                    stage: str = "SVR hyperparameters") -> None:
        """Fit :func:`fit_svr_expansion` with this model's SVR settings and keep it as learned attributes."""
        fit = fit_svr_expansion(
            X, y, coverage, run_lengths,
            fixed={name: getattr(self, name) for name in HYPERPARAMETERS + tuple(self._weighted)},
            n_subset=self.n_subset, optimize=self.optimize, n_calls=self.n_calls,
            cv_folds=self.cv_folds, cv_blocks=self.cv_blocks, bounds=self.bounds,
            random_state=self.random_state, progress=progress, stage=stage, weighted=self._weighted)
        self.input_mean_ = fit.input_mean
        self.input_scale_ = fit.input_scale
        self.support_vectors_ = fit.support_vectors
        self.dual_coef_ = fit.dual_coef
        self.intercept_ = fit.intercept
        self.epsilon_ = fit.hyperparameters["epsilon"]
        self.C_ = fit.hyperparameters["C"]
        self.gamma_ = fit.hyperparameters["gamma"]
        self.optimised_ = list(fit.optimised)
        self.cv_rmse_ = fit.cv_rmse
        self.search_history_ = list(fit.history)
        self.at_bounds_ = list(fit.at_bounds)
        self.n_train_ = fit.n_train
        self.input_weights_ = fit.input_weights
        self.input_range_ = np.vstack((np.min(X, axis=0), np.max(X, axis=0)))
        self.handover_width_ = handover_width(self.gamma_) if self.handover else None

    def _inputs_chunk(self, run: AxisLog, state, sample_time: float):  # pragma: no cover - abstract
        """Raw SVR inputs of a chunk of a run, shape (n, n_features), and the state after it."""
        raise NotImplementedError

    def outside_training(self, log: AxisLog) -> dict[str, np.ndarray]:
        """As :meth:`CurrentModel.outside_training <greybox.estimator.CurrentModel.outside_training>`, with
        ``"inputs"``: True where any SVR input lies outside its range over the training data. Computed
        in chunks, so that the inputs of a long run need not be held at once.

        Parameters
        ----------
        log : AxisLog
            One prepared run.
        """
        state, parts = self.region_state(), []
        for samples in chunk_slices(len(log), samples_per_chunk(log.sample_time, DEFAULT_CHUNK_S)):
            flags, state = self.outside_training_chunk(log.select(samples), state, sample_time=log.sample_time)
            parts.append(flags)
        return {name: np.concatenate([flags[name] for flags in parts]) for name in parts[0]}

    def _region_flags(self, log: AxisLog, state, sample_time: float):
        """The base class's flags, with ``"inputs"`` where an SVR input lies outside its training range."""
        if getattr(self, "input_range_", None) is None:  # a file that predates the record
            return super()._region_flags(log, state, sample_time)
        X, state = self._inputs_chunk(log, state, sample_time)
        return self._flags(log, X, sample_time), state

    def _flags(self, log: AxisLog, X, sample_time: float, outside=None) -> dict[str, np.ndarray]:
        """The training-region flags of a chunk whose SVR inputs are ``X`` (``outside``: their ``"inputs"``
        flag, from :meth:`KernelFrame.terms`, when at hand)."""
        out, _ = super()._region_flags(log, None, sample_time)
        if outside is not None:
            out["inputs"] = outside
        elif getattr(self, "input_range_", None) is not None:
            low, high = (np.ascontiguousarray(bound, dtype=np.float64) for bound in self.input_range_)
            out["inputs"] = np.empty(len(X), dtype=np.bool_)
            outside_rows(np.ascontiguousarray(X, dtype=np.float64), low, high, out["inputs"])
        return out

    def kernel_frame(self) -> "KernelFrame":
        """The kernel's coordinates and hand-over box, checked once (:class:`KernelFrame`).

        Returns
        -------
        KernelFrame

        Raises
        ------
        ParameterError
            For kernel weights that are not one positive number per input.
        """
        return KernelFrame(self)

    def _kernel_predict(self, X) -> np.ndarray:
        """The fitted expansion at raw (unscaled) inputs ``X``, shape (n, n_features) [A]."""
        return self.kernel_frame().expansion(X)

    def _handover(self, X) -> np.ndarray | None:
        """Weight of the correction at raw inputs ``X`` (:func:`greybox.models.handover.handover_weight`).

        None for a model without the hand-over (fitted with ``handover=False``, or read from a file that
        predates it): its correction applies everywhere, as it was fitted.
        """
        return self.kernel_frame().weight(X)

    def _kernel_parameters(self) -> list[Parameter]:
        """Rows of the SVR stage for the parameter table."""
        return [
            Parameter("C", self.C_, EFFORT, "SVR regularisation"),
            Parameter("epsilon", self.epsilon_, EFFORT, "SVR insensitive tube half-width"),
            Parameter("gamma", self.gamma_, "1/(standardised unit)^2", "RBF kernel parameter"),
            *(Parameter(name, self._weight(name), "-", f"kernel weight of input {self.input_names[column]}")
              for name, column in self._weighted.items()),
            Parameter("n_support", int(self.dual_coef_.size), "-", "support vectors"),
            Parameter("intercept", self.intercept_, EFFORT, "SVR intercept"),
            *([] if getattr(self, "handover_width_", None) is None else
              [Parameter("handover_width", self.handover_width_, "standardised unit",
                         "distance from the training inputs' box over which the correction is handed over")]),
        ]

    def interval_notes(self) -> dict[str, str]:
        """The kernel stage's rows: settings chosen by cross-validation and the expansion, not identified parameters."""
        chosen = "hyperparameter, set or chosen by cross-validation, not identified"
        notes = dict.fromkeys(["C", "epsilon", "gamma", *self._weighted], chosen)
        notes.update(n_support="a count of the kernel expansion", intercept="part of the kernel expansion")
        return notes

    def _weight(self, name: str) -> float:
        """The fitted kernel weight of the setting ``name`` of ``_weighted`` (1 in a file that predates weights)."""
        weights = getattr(self, "input_weights_", None)
        return 1.0 if weights is None else float(weights[self._weighted[name]])

    def _fit_statistics(self) -> dict:
        unit = self.effort_unit_
        return {"n_train": self.n_train_, "optimised": list(self.optimised_), f"cv_rmse_{unit}": self.cv_rmse_,
                "at_bounds": list(self.at_bounds_)}

    def hyperparameters_table(self) -> dict[str, object]:
        """The SVR settings as in the paper's Table 2.

        Returns
        -------
        dict
            ``kernel`` ("rbf"), ``epsilon`` [A], ``C`` [A], ``gamma``
            [1/(standardised unit)^2], the input weights of ``_weighted`` by
            their setting's name (e.g. ``velocity_weight``), ``n_support``, ``n_train``,
            ``optimised`` (names chosen by Bayesian optimisation),
            ``at_bounds`` (those that ended at an end of their search
            interval) and ``cv_rmse`` [A].
        """
        check_is_fitted(self)
        return {
            "kernel": "rbf",
            "epsilon": self.epsilon_,
            "C": self.C_,
            "gamma": self.gamma_,
            **{name: self._weight(name) for name in self._weighted},
            "n_support": int(self.dual_coef_.size),
            "n_train": self.n_train_,
            "optimised": list(self.optimised_),
            "at_bounds": list(self.at_bounds_),
            "cv_rmse": self.cv_rmse_,
        }


class SVRCurrentModel(KernelRegressionModel):
    """Pure SVR current model (benchmark): ``I = J a + offset + f(p, v)``.

    Parameters
    ----------
    inertia : float, optional
        Inertia J [A s^2/mm], e.g. from the drive's commissioning; identified
        with the offset by the Coulomb + viscous proxy when None.
    C : float, optional
        SVR regularisation [A]; optimised (or defaulted) when None.
    epsilon : float, optional
        Width of the SVR's insensitive tube [A]; optimised when None.
    gamma : float, optional
        RBF kernel parameter [1/(standardised unit)^2]; optimised when None.
    velocity_weight : float, optional
        Weight of the velocity's squared standardised distance in the kernel,
        ``K = exp(-gamma (dp^2 + velocity_weight dv^2))`` (an anisotropic
        Gaussian kernel: above 1 it is narrower in velocity than in position,
        so that it can follow the friction's sign change at zero speed while
        staying smooth along the travel); searched over
        :data:`WEIGHT_BOUNDS` with the others when None (1 when not
        optimised). 1 is the isotropic kernel, the only one before the
        weight existed; searching it was chosen on the training runs of a
        development family of truth axes (``studies/priors.py`` in the repository).
    n_subset : int, default 2000
        Training samples, chosen to cover the (p, v) plane evenly
        (SVR training time grows roughly with its square).
    optimize : bool, default True
        Choose the hyperparameters left None by Bayesian optimisation
        (log-uniform priors, time-blocked cross-validation); when false
        they take the defaults of :func:`fit_svr_expansion`.
    n_calls : int, default 25
        Evaluations of the Bayesian optimisation.
    cv_folds : int, default 3
        Cross-validation folds.
    cv_blocks : int, default 12
        Contiguous time blocks dealt to the folds (never spanning runs).
    bounds : dict, optional
        Search intervals ``{name: (low, high)}`` replacing
        :func:`default_bounds` (which scale with the spread of the target).
    random_state : int, default 0
        Seed of subset choice and optimisation.
    handover : bool, default True
        Outside the box of the training inputs (position, velocity) hand the
        friction over from the SVR to the Coulomb + viscous proxy
        ``F_c sgn(v) + mu v`` fitted with ``J`` and the offset, over one kernel
        length scale (:mod:`greybox.models.handover`), so that beyond the
        training speeds the friction grows linearly, as the viscous law, instead
        of falling back to the SVR's intercept. Inside the box the prediction is
        the SVR's. False: the SVR everywhere (the only behaviour before the
        setting existed, and that of model files written before it).

    Attributes
    ----------
    J_ : float
        Inertia [A s^2/mm].
    offset_ : float
        Constant current [A].
    proxy_coulomb_, proxy_viscous_ : float
        Coulomb level [A] and viscous coefficient [A s/mm] of the proxy, the friction handed over to
        outside the training region; only with ``handover``.
    handover_width_ : float or None
        Width of the hand-over [standardised unit] (None without it).
    input_mean_, input_scale_ : ndarray, shape (2,)
        Standardisation of (position [mm], velocity [mm/s]).
    support_vectors_ : ndarray, shape (n_support, 2)
        Standardised support vectors, multiplied by the square root of their input's kernel weight.
    dual_coef_ : ndarray, shape (n_support,)
        Dual coefficients [A].
    intercept_ : float
        [A].
    C_, epsilon_, gamma_ : float
        Hyperparameters used.
    optimised_ : list of str
        Hyperparameters chosen by the optimisation.
    cv_rmse_ : float
        Cross-validated RMSE at the chosen hyperparameters [A] (NaN if none were optimised).
    search_history_ : list of dict
        Every evaluation of the optimisation.
    at_bounds_ : list of str
        Optimised hyperparameters that ended at an end of their search interval.
    n_train_ : int
        Size of the training subset.
    input_weights_ : ndarray, shape (2,)
        Kernel weights of (position, velocity): ``(1, velocity weight used)``.
    """

    #: Names of the model inputs, in the order of the columns of the support vectors.
    input_names = ("position_mm", "velocity_mm_s")

    _weighted = {"velocity_weight": 1}

    def __init__(self, *, inertia=None, C=None, epsilon=None, gamma=None, velocity_weight=None, n_subset=2000,
                 optimize=True, n_calls=25, cv_folds=3, cv_blocks=12, bounds=None, random_state=0, handover=True):
        self.inertia = inertia
        self.C = C
        self.epsilon = epsilon
        self.gamma = gamma
        self.velocity_weight = velocity_weight
        self.n_subset = n_subset
        self.optimize = optimize
        self.n_calls = n_calls
        self.cv_folds = cv_folds
        self.cv_blocks = cv_blocks
        self.bounds = bounds
        self.random_state = random_state
        self.handover = handover

    def _check_params(self) -> None:
        super()._check_params()
        if self.inertia is not None and not (isinstance(self.inertia, (int, float, np.number))
                                             and np.isfinite(self.inertia)):
            raise ParameterError(f"inertia must be a finite number in A s^2/mm, got {self.inertia!r}")

    def _inputs(self, run: AxisLog) -> np.ndarray:
        return np.column_stack((run.position, run.velocity))

    def _inputs_chunk(self, run: AxisLog, state, sample_time: float):
        return self._inputs(run), state

    def _fit_runs(self, runs, progress) -> None:
        self.J_, self.offset_, coulomb, viscous = coulomb_viscous_proxy(runs, self.inertia)
        if self.handover:
            self.proxy_coulomb_, self.proxy_viscous_ = coulomb, viscous
        X = np.concatenate([self._inputs(run) for run in runs])
        target = np.concatenate([run.effort - self.J_ * run.acceleration for run in runs]) - self.offset_
        self._fit_kernel(X, target, X, [len(run) for run in runs], progress)

    def _simulate(self, run, state, sample_time):
        X = self._inputs(run)
        weight = self._handover(X)
        proxy = None
        if weight is not None:
            proxy = self.proxy_coulomb_ * np.sign(run.velocity) + self.proxy_viscous_ * run.velocity
        return hand_over(proxy, self._kernel_predict(X), weight), None

    def _n_params(self) -> int:
        # dual coefficients, intercept, J, offset (and the proxy's Coulomb level and viscous coefficient)
        return int(self.dual_coef_.size) + 3 + 2 * int(getattr(self, "handover_width_", None) is not None)

    def _own_parameters(self) -> list[Parameter]:
        if getattr(self, "handover_width_", None) is None:
            return self._kernel_parameters()
        return self._kernel_parameters() + [
            Parameter("proxy_coulomb", self.proxy_coulomb_, EFFORT, "Coulomb level handed over to outside the "
                                                                     "training region"),
            Parameter("proxy_viscous", self.proxy_viscous_, f"{EFFORT} s/{LENGTH}", "viscous coefficient handed "
                                                                                    "over to outside the training "
                                                                                    "region")]

    def interval_notes(self) -> dict[str, str]:
        """As the kernel stage's, and ``J``, ``offset`` fixed by a proxy fit before the kernel expansion."""
        fixed = "fixed by a proxy fit before the kernel expansion"
        return {**super().interval_notes(), "J": fixed, "offset": fixed}


#: Every name a search interval can be given for (``bounds=``) in the kernel models: the SVR
#: hyperparameters and the sole SVR's kernel weights.
BOUNDED = HYPERPARAMETERS + tuple(SVRCurrentModel._weighted)


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

    def __init__(self, model: KernelRegressionModel):
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

        What :meth:`expansion`, :meth:`weight` and the model's ``"inputs"`` flag give, for the few samples of
        a live message: the per-call checks and copies of :func:`~greybox.models.rbf.rbf_expansion` are done
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
        frame_terms(X, *arguments, expansion, weight, outside)
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
        :func:`~greybox.models.rbf.expansion_cutoff`; negative: no term counts.
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
