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
(:class:`greybox.models.gmssvr.GMSSVRModel`) is :func:`greybox.models.kernel.expansion.fit_svr_expansion`:
standardise the inputs, choose the hyperparameters (C, epsilon, gamma) by
Bayesian optimisation over a time-blocked cross-validation, train on a
subset that covers the (p, v) plane, and keep the kernel expansion as plain
arrays (support vectors, dual coefficients, intercept), evaluated by
:func:`greybox.models.kernel.rbf.rbf_expansion`.
"""

from __future__ import annotations

from typing import Callable, Mapping, Sequence

import numpy as np
from sklearn.utils.validation import check_is_fitted

from ..base import EFFORT, LENGTH, Parameter
from ..data.log import AxisLog
from ..errors import ParameterError, Setting
from ..identify.linear import bounded_lstsq
from ..identify.optimize import check_seed
from ..identify.progress import ProgressEvent
from .chunked import DEFAULT_CHUNK_S, chunk_slices, samples_per_chunk
from .estimator import CurrentModel
from .handover import hand_over, handover_width
from .kernel.expansion import HYPERPARAMETERS, KernelFrame, _check_bounds, fit_svr_expansion, outside_rows

__all__ = ["KernelRegressionModel", "SVRCurrentModel", "coulomb_viscous_proxy", "BOUNDED"]

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


#: ``n_calls`` of a fit that only scores a candidate on held-out runs (:meth:`KernelRegressionModel.held_out_search`).
HELD_OUT_CALLS = 10


class KernelRegressionModel(CurrentModel):
    """Shared parts of the current models with an RBF support vector regression stage.

    The subclass stores the SVR settings ``C``, ``epsilon``, ``gamma``,
    ``n_subset``, ``optimize``, ``n_calls``, ``cv_folds``, ``cv_blocks``,
    ``bounds``, ``random_state`` and ``handover`` (see :class:`SVRCurrentModel`); this class
    checks them, fits the expansion (:func:`~greybox.models.kernel.expansion.fit_svr_expansion`) into the
    learned attributes ``input_mean_``, ``input_scale_``, ``support_vectors_``,
    ``dual_coef_``, ``intercept_``, ``epsilon_``, ``C_``, ``gamma_``,
    ``optimised_``, ``cv_rmse_``, ``search_history_``, ``at_bounds_``,
    ``n_train_``, ``input_weights_`` (the kernel's weight of each input, see
    :class:`~greybox.models.kernel.expansion.SVRExpansion`), ``input_range_`` (the lowest and highest value of each
    input over the training data, shape (2, n_features)) and ``handover_width_`` (see
    :mod:`greybox.models.handover`; None without the hand-over), and evaluates it.
    The subclass weighs its correction by :meth:`_handover` and says what it hands over to.
    A subclass gives the inputs of a chunk of a run by ``_inputs_chunk(run, state, sample_time)``,
    and names in ``_weighted`` (``{setting: input column}``) the settings that weight an input in the kernel.
    """

    #: ``{setting name: input column}`` of the inputs the kernel weighs by a setting of that name.
    _weighted: Mapping[str, int] = {}

    def held_out_search(self) -> "KernelRegressionModel":
        """A copy whose Bayesian search of the SVR hyperparameters makes at most :data:`HELD_OUT_CALLS` calls.

        Returns
        -------
        KernelRegressionModel
        """
        return super().held_out_search().set_params(n_calls=min(self.n_calls, HELD_OUT_CALLS))

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
        """Fit :func:`~.kernel.expansion.fit_svr_expansion` with this model's SVR settings; keep it as learned
        attributes."""
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

    def _input_region(self, log: AxisLog) -> dict[str, np.ndarray]:
        """The input flags of :meth:`~greybox.models.estimator.CurrentModel.outside_training`, with
        ``"inputs"``: True where any SVR input lies outside its range over the training data. Computed
        in chunks, so that the inputs of a long run need not be held at once.

        Parameters
        ----------
        log : AxisLog
            One prepared run.
        """
        state, parts = self._own_region_state(), []
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
        flag, from :meth:`~greybox.models.kernel.expansion.KernelFrame.terms`, when at hand)."""
        out, _ = super()._region_flags(log, None, sample_time)
        if outside is not None:
            out["inputs"] = outside
        elif getattr(self, "input_range_", None) is not None:
            low, high = (np.ascontiguousarray(bound, dtype=np.float64) for bound in self.input_range_)
            out["inputs"] = np.empty(len(X), dtype=np.bool_)
            outside_rows(np.ascontiguousarray(X, dtype=np.float64), low, high, out["inputs"])
        return out

    def kernel_frame(self) -> "KernelFrame":
        """The kernel's coordinates and hand-over box, checked once (:class:`~.kernel.expansion.KernelFrame`).

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
