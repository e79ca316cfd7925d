"""The grey-box current model: GMS friction plus an SVR correction (Rüppel et al. 2024, eq. 8).

Two stages:

1. a :class:`~greybox.models.friction.GMSModel` (inertia + Generalized Maxwell-Slip
   friction) is identified, and its parameters are then frozen;
2. an RBF support vector regression corrects it, with the position ``p``
   [mm], the frozen GMS model's current ``I_GMS`` [A] and its element
   deflections ``z_1..z_N`` [mm] as inputs, all standardised:

       I = I_GMS + SVR(p, I_GMS, z_1, ..., z_N).

By default (``target="residual"``) the SVR learns only the GMS stage's
residual ``I - I_GMS`` and the prediction is ``I_GMS + SVR(...)``. The
position input lets the kernel learn the dependence of the friction on the
position along the screw that the GMS model lacks. With ``target="current"``
the SVR learns the current itself, as the paper's eq. 8 is printed,

    I = SVR(p, I_GMS, z_1, ..., z_N),

with the GMS prediction as one input the kernel may correct in any
direction. Far from its training data an RBF expansion falls back to its
intercept (a constant, or the GMS physics plus a constant for the residual
target); with ``handover=True`` (the default) the prediction is instead
handed over to the GMS stage's alone, smoothly, within one kernel length
scale of the box of the training inputs (:mod:`greybox.models.handover`),
and is unchanged inside it. Both targets search the same
intervals (:func:`greybox.models.kernel.expansion.default_bounds`). The residual target
was chosen on the training runs of a development family of truth axes
(``studies/priors.py`` in the repository): fitted on three quarters of dataset A and
scored on the rest of A and on B, it is far better than the current target
on B (the whole travel, beyond A's window), and a floor on the kernel
parameter gamma, meant to keep the correction local, made no difference
there (docs/svr.md). The hyperparameters, the training subset and the kernel
evaluation are those of :mod:`greybox.models.svr`.

The stages may be fitted on the same runs (:meth:`GMSSVRModel.fit`) or on
different ones (:meth:`GMSSVRModel.fit_gms`, then
:meth:`GMSSVRModel.fit_svr`), and :meth:`GMSSVRModel.fit_svr` also accepts a
GMS model identified elsewhere (e.g. loaded from a model file).
"""

from __future__ import annotations

import copy
from typing import Iterable

import numpy as np
from sklearn.base import clone
from sklearn.utils.validation import check_is_fitted

from ..base import Parameter
from ..data.log import AxisLog
from ..errors import LogError, ParameterError, Setting
from ..identify.progress import make_progress
from .estimator import check_runs
from .friction.gms import GMSModel
from .handover import hand_over
from .svr import KernelRegressionModel

__all__ = ["GMSSVRModel", "TARGETS"]

#: What the SVR stage may learn: the GMS stage's residual (default) or the current (paper).
TARGETS = ("residual", "current")


class GMSSVRModel(KernelRegressionModel):
    """Grey-box current model ``I = I_GMS + SVR(p, I_GMS, z_1..z_N)`` with a frozen GMS stage.

    With ``target="current"`` (the paper's eq. 8): ``I = SVR(p, I_GMS, z_1..z_N)``.

    Parameters
    ----------
    gms : GMSModel, optional
        Settings of the first stage (an unfitted :class:`GMSModel`, cloned
        before fitting); ``GMSModel()`` by default. To use a GMS model that
        is already fitted, pass it to :meth:`fit_svr` instead.
    C : float, optional
        SVR regularisation [A]; optimised (or defaulted) when None.
    epsilon : float, optional
        Width of the SVR's insensitive tube [A]; optimised when None.
    gamma : float, optional
        RBF kernel parameter [1/(standardised unit)^2]; optimised when None.
    target : {"residual", "current"}, default "residual"
        What the SVR learns: the residual ``I - I_GMS`` of the GMS stage,
        added back in prediction, or the current itself (the paper's eq. 8).
    n_subset : int, default 2000
        SVR training samples, chosen to cover the (p, v) plane evenly.
    optimize : bool, default True
        Choose the hyperparameters left None by Bayesian optimisation over a
        time-blocked cross-validation (see :func:`greybox.models.kernel.expansion.fit_svr_expansion`).
    n_calls : int, default 25
        Evaluations of the Bayesian optimisation.
    cv_folds : int, default 3
        Cross-validation folds.
    cv_blocks : int, default 12
        Contiguous time blocks dealt to the folds (never spanning runs).
    bounds : dict, optional
        Search intervals ``{name: (low, high)}`` replacing those of
        :func:`greybox.models.kernel.expansion.default_bounds`.
    random_state : int, default 0
        Seed of subset choice and optimisation.
    handover : bool, default True
        Outside the box of the training inputs (p, I_GMS, z) hand the
        prediction over from the corrected one to the GMS stage's, over one
        kernel length scale (:mod:`greybox.models.handover`): the correction
        never extrapolates on its own. Inside the box the prediction is the
        fitted one. False: the correction everywhere (the only behaviour before
        the setting existed, and that of model files written before it).

    Attributes
    ----------
    gms_ : GMSModel
        The frozen first stage.
    J_, offset_ : float
        Inertia [A s^2/mm] and offset [A] of the GMS stage; the friction
        reported by :meth:`friction` is the prediction minus ``J_ a + offset_``.
    input_mean_, input_scale_ : ndarray, shape (2 + N,)
        Standardisation of (position [mm], I_GMS [A], z_1..z_N [mm]).
    support_vectors_ : ndarray, shape (n_support, 2 + N)
        Standardised support vectors.
    dual_coef_ : ndarray, shape (n_support,)
        Dual coefficients [A] (of the current or of the residual, see ``target``).
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
        Size of the SVR training subset.
    handover_width_ : float or None
        Width of the hand-over [standardised unit] (None without it).
    """

    def __init__(self, *, gms=None, C=None, epsilon=None, gamma=None, target="residual", n_subset=2000,
                 optimize=True, n_calls=25, cv_folds=3, cv_blocks=12, bounds=None, random_state=0, handover=True):
        self.gms = gms
        self.C = C
        self.epsilon = epsilon
        self.gamma = gamma
        self.target = target
        self.n_subset = n_subset
        self.optimize = optimize
        self.n_calls = n_calls
        self.cv_folds = cv_folds
        self.cv_blocks = cv_blocks
        self.bounds = bounds
        self.random_state = random_state
        self.handover = handover

    def __sklearn_is_fitted__(self) -> bool:
        """Fitted once the SVR stage is (the GMS stage alone is not a usable model)."""
        return hasattr(self, "dual_coef_")

    @property
    def input_names(self) -> tuple[str, ...]:
        """Names of the SVR inputs, in the order of the columns of the support vectors."""
        check_is_fitted(self, "gms_")
        return ("position_mm", "gms_current_A") + tuple(f"z{i + 1}_mm" for i in range(len(self.gms_.alpha_)))

    # ---------------------------------------------------------------- fitting
    def fit(self, logs: AxisLog | Iterable[AxisLog], progress=None) -> "GMSSVRModel":
        """Fit both stages on the same prepared runs: :meth:`fit_gms`, then :meth:`fit_svr`.

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs (velocity [mm/s] and acceleration [mm/s^2] present).
        progress : None, bool or callable, optional
            See :meth:`greybox.models.estimator.CurrentModel.fit`.

        Returns
        -------
        self
        """
        self.fit_gms(logs, progress=progress)
        return self.fit_svr(logs, progress=progress)

    first_stage_param = "gms"

    def held_out_search(self) -> "GMSSVRModel":
        """A copy with fewer Bayesian calls and the GMS stage's held-out search (for scoring on held-out runs).

        Returns
        -------
        GMSSVRModel
        """
        return super().held_out_search().set_params(gms=self.first_stage().held_out_search())

    def first_stage(self) -> GMSModel:
        """Unfitted GMS stage: a clone of ``gms`` (``GMSModel()`` by default)."""
        return clone(GMSModel() if self.gms is None else self.gms)

    def fit_staged(self, logs, stage2_logs=None, *, progress=None, first_stage=None) -> "GMSSVRModel":
        """Fit the GMS stage on ``logs`` (or freeze ``first_stage``), then the SVR stage on ``stage2_logs``.

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs of the GMS stage (unused when ``first_stage`` is given).
        stage2_logs : AxisLog or list of AxisLog, optional
            Prepared runs of the SVR stage; default ``logs``.
        progress : None, bool or callable, optional
            See :meth:`greybox.models.estimator.CurrentModel.fit`.
        first_stage : GMSModel, optional
            A fitted GMS model to freeze instead of fitting one.

        Returns
        -------
        self
        """
        second = logs if stage2_logs is None else stage2_logs
        if first_stage is None:
            self.fit_gms(logs, progress=progress)
        return self.fit_svr(second, progress=progress, gms=first_stage)

    def fit_gms(self, logs: AxisLog | Iterable[AxisLog], progress=None) -> "GMSSVRModel":
        """Identify the GMS stage (a clone of ``gms``) and forget any fitted SVR stage.

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs.
        progress : None, bool or callable, optional
            See :meth:`greybox.models.estimator.CurrentModel.fit`.

        Returns
        -------
        self
        """
        self._check_params()
        template = GMSModel() if self.gms is None else self.gms
        for name in [n for n in vars(self) if n.endswith("_") and not n.startswith("_")]:
            delattr(self, name)
        self.gms_ = clone(template).fit(logs, progress=progress)
        return self

    def fit_svr(self, logs: AxisLog | Iterable[AxisLog], progress=None, gms: GMSModel | None = None
                ) -> "GMSSVRModel":
        """Fit the SVR stage with the GMS stage frozen.

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs; may differ from the runs the GMS stage was fitted on.
        progress : None, bool or callable, optional
            See :meth:`greybox.models.estimator.CurrentModel.fit`.
        gms : GMSModel, optional
            A fitted GMS model to freeze (a copy is kept as ``gms_``); by
            default the one from :meth:`fit_gms`.

        Returns
        -------
        self

        Raises
        ------
        ParameterError
            If there is no fitted GMS stage.
        LogError
            If the runs' effort unit differs from the GMS stage's.
        """
        self._check_params()
        if gms is not None:
            if not isinstance(gms, GMSModel):
                raise ParameterError(f"gms must be a fitted GMSModel, got {type(gms).__name__}")
            check_is_fitted(gms)
            self.gms_ = copy.deepcopy(gms)
        elif not hasattr(self, "gms_"):
            raise ParameterError("no GMS stage: call fit_gms first, or pass a fitted GMSModel as ", Setting("gms"))
        runs = check_runs(logs)
        for run in runs:
            if run.effort_unit != self.gms_.effort_unit_:
                raise LogError(run.source or None, f"log carries effort in {run.effort_unit}, "
                                                   f"the GMS stage was fitted on {self.gms_.effort_unit_}")
        self._set_fit_info(runs)
        self._widen_region(self.gms_)
        self.J_ = float(self.gms_.J_)
        self.offset_ = float(self.gms_.offset_)
        self.notes_ = self.gms_.fit_notes()

        X = np.concatenate([self._inputs(run, self.gms_.initial_state(), run.sample_time)[0] for run in runs])
        coverage = np.concatenate([np.column_stack((run.position, run.velocity)) for run in runs])
        y = np.concatenate([run.effort for run in runs])
        if self.target == "residual":
            y = y - X[:, 1]
        self._fit_kernel(X, y, coverage, [len(run) for run in runs], make_progress(progress),
                         stage="GMS-SVR hyperparameters")
        return self

    def _check_params(self) -> None:
        super()._check_params()
        if self.target not in TARGETS:
            raise ParameterError(f"target must be one of {TARGETS}, got {self.target!r}")
        if self.gms is not None and not isinstance(self.gms, GMSModel):
            raise ParameterError(f"gms must be a GMSModel or None, got {type(self.gms).__name__}")

    # ---------------------------------------------------------------- prediction
    def _inputs(self, run: AxisLog, state, sample_time: float, trajectory=None):
        """SVR inputs of one run or chunk: position [mm], GMS current [A], deflections [mm]; and the end state.

        One simulation of the GMS stage gives both its current and its element states (``trajectory``: the
        stage's :meth:`~greybox.models.friction.GMSModel.trajectory_runner` of a stream, checked once).
        """
        if trajectory is None:
            gms_current, z, _, end = self.gms_.trajectory(run, state, sample_time=sample_time)
        else:
            gms_current, z, _, end = trajectory(run, state)
        return np.column_stack((run.position, gms_current, z)), end

    def _inputs_chunk(self, run: AxisLog, state, sample_time: float):
        return self._inputs(run, state, sample_time)

    def _own_region_state(self):
        """The GMS stage's state at the start of a run: the SVR inputs hold its element deflections."""
        return self.gms_.initial_state()

    def initial_state(self):
        """State of the frozen GMS stage at the start of a run (all elements at rest)."""
        return self.gms_.initial_state()

    def _simulate(self, run: AxisLog, state, sample_time):
        inputs, end = self._inputs(run, state, sample_time)
        return self._friction_of(run, inputs), end

    def _friction_of(self, run: AxisLog, inputs, expansion=None, weight=None) -> np.ndarray:
        """Friction [A] of a chunk whose SVR inputs are ``inputs``: the prediction less inertia and offset.

        Outside the box of the training inputs the prediction is handed over to the GMS stage's
        (:mod:`greybox.models.handover`). ``expansion``, ``weight``: the kernel frame's
        :meth:`~greybox.models.kernel.expansion.KernelFrame.terms` of a stream, when at hand.
        """
        if expansion is None:
            frame = self.kernel_frame()
            scaled = frame.coordinates(inputs)
            expansion, weight = frame.expansion(inputs, scaled), frame.weight(inputs, scaled)
        current = expansion
        if self.target == "residual":
            current = current + inputs[:, 1]
        current = hand_over(inputs[:, 1], current, weight)
        return current - self.J_ * run.acceleration - self.offset_

    def _stream_step(self, sample_time: float):
        """The prediction and region check of checked chunks, the GMS stage simulated once for both, its
        parameters and the kernel's frame checked once."""
        check_is_fitted(self, "gms_")
        trajectory = self.gms_.trajectory_runner(sample_time)
        frame = self.kernel_frame()

        def step(run, state, region):
            inputs, end = self._inputs(run, state, sample_time, trajectory)
            expansion, weight, outside = frame.terms(inputs)
            current = self.J_ * run.acceleration + self._friction_of(run, inputs, expansion, weight) + self.offset_
            return current, end, self._flags(run, inputs, sample_time, outside), end

        return step

    def _n_params(self) -> int:
        return int(self.dual_coef_.size) + 1 + self.gms_.n_params

    def _fit_statistics(self) -> dict:
        stage = {f"gms.{name}": value for name, value in self.gms_.fit_summary().items()}
        return {**stage, **super()._fit_statistics()}

    def _own_parameters(self) -> list[Parameter]:
        stage = [Parameter(f"gms.{p.name}", p.value, p.unit, f"GMS stage: {p.description}")
                 for p in self.gms_.parameter_table() if p.name not in ("J", "offset")]
        return stage + self._kernel_parameters()

    def interval_stage(self, runs):
        """The GMS stage, fitted alone on the first stage's runs, identifies the physical parameters.

        Parameters
        ----------
        runs : list of AxisLog
            The prepared runs the GMS stage was fitted on.
        """
        return self.gms_, "gms.", runs

    def gms_predict(self, logs: AxisLog | Iterable[AxisLog]) -> np.ndarray:
        """Current of the frozen GMS stage alone [A], the runs concatenated.

        Parameters
        ----------
        logs : AxisLog or iterable of AxisLog
            Prepared runs.
        """
        check_is_fitted(self, "gms_")
        return self.gms_.predict(logs)

    def states(self, logs: AxisLog | Iterable[AxisLog]) -> tuple[np.ndarray, np.ndarray]:
        """GMS element deflections and stick flags (see :meth:`greybox.models.friction.GMSModel.states`).

        Parameters
        ----------
        logs : AxisLog or iterable of AxisLog
            Prepared runs; the rows of the results are their samples, concatenated.

        Returns
        -------
        z : ndarray, shape (n_samples, N)
            Deflection of each element [mm].
        stick : ndarray of bool, shape (n_samples, N)
            True where the element sticks.
        """
        check_is_fitted(self, "gms_")
        return self.gms_.states(logs)
