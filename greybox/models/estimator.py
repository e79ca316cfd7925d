"""The shared implementation of the current models: fitting template, run checks, prediction.

A current model predicts the drive effort of a feed axis from its prepared
motion,

    I = J * a + I_friction(v, history) + offset,

in A (or in N when the logs carry force; the models are unit-agnostic and
remember the unit they were fitted on). A fit may use several runs: each run is
simulated from its own initial state, and predictions of a list of runs are
concatenated in order, never carrying a state across the seam between runs.
The methods callers rely on are those of :class:`greybox.base.ModelProtocol`.
"""

from __future__ import annotations

from typing import Iterable

import numpy as np
from sklearn.base import clone
from sklearn.utils.validation import check_is_fitted

from ..base import EFFORT, LENGTH, ModelProtocol, Parameter
from ..data.log import AxisLog, as_log_list
from ..data.operating import OperatingRegion
from ..data.quantities import MOTIONS, Motion
from ..errors import GreyboxError, LogError, ParameterError, Setting
from ..identify.inertia import axis_inertia_note, inertia_note
from ..identify.intervals import with_intervals
from ..identify.progress import make_progress
from ..metrics import rmse
from ..provenance import TRAINING_ATTRIBUTE

__all__ = ["CurrentModel", "StreamView", "check_inertia", "check_runs", "extrapolates", "outside_any",
           "EXTRAPOLATION_WARNING_SHARE", "MAX_PARAMETER_MAGNITUDE", "PLAUSIBLE_EFFORT_FACTOR", "STANDSTILL_SHARE",
           "check_plausible"]

#: Largest magnitude of an identified parameter a model file may carry: currents of a feed axis are
#: amperes, stiffnesses thousands of A/mm; 1e12 in any unit is a corrupt or hostile file.
MAX_PARAMETER_MAGNITUDE = 1e12

#: Learned attributes that record the training region: name -> channel of the runs (range [mm] or [mm/s]).
_REGION_CHANNELS = {"position_range_mm_": "position", "velocity_range_mm_s_": "velocity"}

#: Learned attribute that records the range of the measured effort of the training runs [A, N or Nm]: a
#: prediction beyond it is flagged ``"effort"`` by :meth:`CurrentModel.outside_training`.
_EFFORT_RANGE = "effort_range_"

#: A fit is refused when its simulated effort, on its own runs or at a constant speed within the speeds
#: they covered, exceeds this multiple of the largest effort measured in them [-]: friction at a speed the
#: drive moved at cannot exceed what the drive produced to move there (the break-away level included,
#: since every run starts from rest), so an effort three times beyond it is a search that ran into
#: parameters that contradict the runs (docs/defaults.md, "Identification that cannot blow up silently").
PLAUSIBLE_EFFORT_FACTOR = 3.0

#: Constant speeds of the plausibility probe, as shares of the largest training speed [-], each held in
#: both directions for :data:`_PROBE_TRAVEL_MM` of travel or :data:`_PROBE_MIN_S`, whichever is longer
#: (capped at :data:`_PROBE_MAX_S`): slow enough to reach the static level a Stribeck curve extrapolates to.
_PROBE_SHARES = (1.0, 0.3, 0.1, 0.03, 0.01)
_PROBE_TRAVEL_MM = 2.0
_PROBE_MIN_S = 0.2
_PROBE_MAX_S = 4.0

#: Speed below which a memoryless model's sample counts as standstill, as a share of the largest training
#: speed [-]: flagged ``"standstill"`` by :meth:`CurrentModel.outside_training`.
STANDSTILL_SHARE = 0.01

#: Share of a log's samples outside the training region above which ``greybox predict`` and
#: ``greybox evaluate`` warn [-].
EXTRAPOLATION_WARNING_SHARE = 0.05


def outside_any(flags: dict) -> np.ndarray | None:
    """The samples outside the training region in any quantity: what ``outside_training`` means.

    ``"standstill"`` does not count: it is what a memoryless model cannot know, not a region the training
    runs left out, and what counts as inside must not depend on the kind of model (it has a column of its own).

    Parameters
    ----------
    flags : dict of str to ndarray of bool
        :meth:`CurrentModel.outside_training` (or ``outside_training_chunk``) of a run.

    Returns
    -------
    ndarray of bool or None
        True where any flag but ``"standstill"`` is set; None when ``flags`` is empty (a model file that
        predates the record).
    """
    if not flags:
        return None
    region = [values for name, values in flags.items() if name != "standstill"]
    return np.logical_or.reduce(region) if region else np.zeros(len(next(iter(flags.values()))), dtype=bool)


def _effort_outside(bounds: tuple[float, float] | None, predicted: np.ndarray) -> dict[str, np.ndarray]:
    """``{"effort": ...}``: where ``predicted`` [A, N or Nm] leaves the checked ``bounds`` (empty without them)."""
    if bounds is None:
        return {}
    predicted = np.asarray(predicted, dtype=float)
    return {"effort": ~((predicted >= bounds[0]) & (predicted <= bounds[1]))}


def extrapolates(shares: dict, share: float) -> bool:
    """Whether a log lies outside the training region enough to warn about.

    Parameters
    ----------
    shares : dict of str to float
        Share of the samples flagged per quantity of :meth:`CurrentModel.outside_training` [-].
    share : float
        Share of the samples flagged in any quantity (:func:`outside_any`) [-].

    Returns
    -------
    bool
        True when ``share`` exceeds :data:`EXTRAPOLATION_WARNING_SHARE` and some quantity other than
        ``"standstill"`` is flagged (standstill alone is not extrapolation: it has a note of its own).
    """
    beyond = max([value for name, value in shares.items() if name != "standstill"] or [0.0])
    return share > EXTRAPOLATION_WARNING_SHARE and beyond > 0.0


def _probe(model: "CurrentModel", runs: list[AxisLog]) -> tuple[AxisLog, np.ndarray]:
    """Constant speeds within the training speeds, both directions (no acceleration): :func:`check_plausible`.

    Returns the probe run and the mask of its steady samples: the second half of each constant speed (the
    jumps between speeds are no motion a drive makes; a dynamic model's transient there is not judged).
    """
    step = float(model.sample_time_)
    top = float(max(np.max(np.abs(run.velocity)) for run in runs))
    pieces, steady = [], []
    for share in _PROBE_SHARES:
        speed = share * top
        seconds = float(np.clip(_PROBE_TRAVEL_MM / speed, _PROBE_MIN_S, _PROBE_MAX_S)) if speed > 0 else _PROBE_MIN_S
        n = max(int(round(seconds / step)), 2)
        for direction in (1.0, -1.0):
            pieces.append(np.full(n, direction * speed))
            steady.append(np.arange(n) >= n // 2)
    velocity = np.concatenate(pieces)
    time = np.arange(velocity.size) * step
    start = float(np.mean([np.median(run.position) for run in runs]))
    position = start + np.concatenate(([0.0], np.cumsum(velocity[:-1] * step)))
    return AxisLog(time=time, position=position, effort=np.zeros(velocity.size), velocity=velocity,
                   acceleration=np.zeros(velocity.size), effort_unit=runs[0].effort_unit,
                   motion=runs[0].motion), np.concatenate(steady)


def check_plausible(model: "CurrentModel", runs: list[AxisLog]) -> None:
    """Refuse a fitted model whose simulated effort is far beyond any effort measured in its training runs.

    The model predicts its own runs and a probe of constant speeds within the speeds they covered
    (shares :data:`_PROBE_SHARES` of the largest, both directions, no acceleration; judged in the second
    half of each speed, once a dynamic model has settled); neither may exceed
    :data:`PLAUSIBLE_EFFORT_FACTOR` times the largest measured effort.

    Parameters
    ----------
    model : CurrentModel
        The model just fitted on ``runs``.
    runs : list of AxisLog
        Its prepared training runs.

    Raises
    ------
    GreyboxError
        One line naming the model, where it predicts what, against the largest measured effort.
    """
    largest = float(max(np.max(np.abs(run.effort)) for run in runs))
    limit = PLAUSIBLE_EFFORT_FACTOR * largest
    unit = runs[0].effort_unit
    probe, steady = _probe(model, runs)
    cases = [(f"on its own run {run.source or i + 1}", run, np.ones(len(run), dtype=bool))
             for i, run in enumerate(runs)]
    for what, run, judged in cases + [("at a constant speed", probe, steady)]:
        predicted = np.where(judged, model.predict(run), 0.0)
        worst = int(np.argmax(np.abs(predicted))) if predicted.size else 0
        if predicted.size and not (np.isfinite(predicted[worst]) and abs(predicted[worst]) <= limit):
            raise GreyboxError(
                f"{type(model).__name__} fit refused: it predicts {predicted[worst]:.4g} {unit} {what} at "
                f"{run.velocity[worst]:.4g} {run.units.velocity_unit}, beyond {PLAUSIBLE_EFFORT_FACTOR:g} times the "
                f"largest effort measured in its runs ({largest:.4g} {unit}): its identified parameters contradict "
                f"the runs ({model.parameter_summary()})")


def check_runs(logs: AxisLog | Iterable[AxisLog]) -> list[AxisLog]:
    """Return ``logs`` as a list of prepared runs, or raise :class:`LogError`.

    Parameters
    ----------
    logs : AxisLog or iterable of AxisLog
        One run or several runs.

    Raises
    ------
    LogError
        If a run has no velocity or acceleration (not prepared), too few
        samples (fewer than 2), non-finite motion or effort values, or the runs mix effort
        units or linear and rotary axes. The message names the run's source file.
    """
    runs = as_log_list(logs)
    unit, motion = runs[0].effort_unit, runs[0].motion
    for run in runs:
        source = run.source or None
        if not run.is_prepared:
            missing = [name for name in ("velocity", "acceleration") if getattr(run, name) is None]
            raise LogError(source, f"log is not prepared: no {' and no '.join(missing)} channel "
                                   "(derive them with greybox.data.prepare first)")
        if len(run) < 2:
            raise LogError(source, f"log has {len(run)} sample(s), a model needs at least 2 (one time step)")
        for name in ("velocity", "acceleration", "effort"):
            values = getattr(run, name)
            if not np.all(np.isfinite(values)):
                bad = int(np.flatnonzero(~np.isfinite(values))[0])
                raise LogError(source, f"channel '{name}' is not finite at sample {bad} "
                                       f"(t = {run.time[bad]:.6g} s)")
        if not np.isfinite(run.sample_time) or run.sample_time <= 0.0:
            raise LogError(source, "time is not increasing: no positive sample time")
        if run.effort_unit != unit:
            raise LogError(source, f"runs mix effort units: {unit} and {run.effort_unit}")
        if run.motion != motion:
            raise LogError(source, f"runs mix a {motion} and a {run.motion} axis")
    return runs


def check_inertia(value) -> None:
    """Raise :class:`ParameterError` unless ``value`` is None or a finite, non-negative inertia.

    Parameters
    ----------
    value : object
        The ``inertia`` hyperparameter of a model [A s^2/mm] (or [N s^2/mm], [Nm s^2/deg]).
    """
    if value is None:
        return
    if not (isinstance(value, (int, float, np.number)) and not isinstance(value, (bool, np.bool_))
            and np.isfinite(value) and value >= 0.0):
        raise ParameterError(Setting("inertia", assign=False), " must be None (identified) or a finite, non-negative "
                             "inertia in effort s^2/length (0 for an effort measured at the load), got ", repr(value))


class CurrentModel(ModelProtocol):
    """Base class of the current models (scikit-learn estimator conventions).

    Subclasses store their keyword-only hyperparameters in ``__init__`` and implement

    - ``_check_params()``: raise :class:`~greybox.errors.ParameterError` for an
      invalid hyperparameter (called first by :meth:`fit`; default: nothing to check);
    - ``_fit_runs(runs, progress)``: identify the parameters from prepared
      runs and set the learned attributes (ending in ``_``), among them
      ``J_`` [A s^2/mm] and ``offset_`` [A];
    - ``_simulate(run, state, sample_time)``: the friction current of one run
      or chunk [A] from ``state``, and the state after its last sample;
    - ``_n_params()``: the number of identified parameters;
    - ``_own_parameters()``: the rows of the parameter table besides ``J`` and ``offset``;

    and the methods of :class:`~greybox.base.ModelProtocol` that apply to them.

    Learned attributes set here: ``effort_unit_`` ("A", "N" or "Nm"),
    ``motion_`` ("linear" or "rotary": the units of position and velocity,
    mm or deg), ``sample_time_`` (median step of the fitted runs [s]),
    ``n_samples_fit_`` and the training region ``position_range_mm_``,
    ``velocity_range_mm_s_`` (in the motion's units: [deg], [deg/s] for a
    rotary axis).
    """

    def fit(self, logs: AxisLog | Iterable[AxisLog], progress=None) -> "CurrentModel":
        """Identify the model from one or several prepared runs.

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs (velocity [mm/s] and acceleration [mm/s^2] present).
        progress : None, bool or callable, optional
            ``None``/``False``: silent. ``True``: print progress to stderr.
            A callable receives :class:`greybox.identify.progress.ProgressEvent`.

        Returns
        -------
        self
        """
        self._check_params()
        check_inertia(self.inertia)
        runs = check_runs(logs)
        self._set_fit_info(runs)
        if self.inertia is None:
            self._fit_runs(runs, make_progress(progress))
            note = inertia_note(runs, float(self.J_), f"{self.effort_unit_} s^2/{self.units_.length}")
            self.notes_ = [] if note is None else [note]
        else:
            known = float(self.inertia)
            self._fit_runs([run.replace(effort=run.effort - known * run.acceleration,
                                        acceleration=np.zeros(len(run))) for run in runs], make_progress(progress))
            self.J_ = known
            self.notes_ = []
        check_plausible(self, runs)
        return self

    def check_axis_inertia(self, expected: float, source: str = "the axis file") -> str | None:
        """Flag an identified inertia that disagrees with the one the axis file gives.

        Nothing is refitted: when ``J_`` was identified (``inertia`` None, also of a stage) and
        differs from ``expected`` by more than
        :data:`~greybox.identify.inertia.AXIS_INERTIA_FACTOR`, a note is added to
        :meth:`fit_notes` (and so to the model file and ``greybox info``).

        Parameters
        ----------
        expected : float
            The axis's inertia in the model's unit [effort s^2/length]
            (:meth:`greybox.data.axis_config.AxisConfig.model_inertia`).
        source : str, default "the axis file"
            Where ``expected`` comes from, for the note.

        Returns
        -------
        str or None
            The note added, or None.
        """
        check_is_fitted(self)
        settings = self.get_params(deep=True)  # a model with a stage (or a base) has the inertia there
        if any(value is not None for name, value in settings.items() if name.split("__")[-1] == "inertia"):
            return None  # given, not identified
        note = axis_inertia_note(float(self.J_), float(expected), f"{self.effort_unit_} s^2/{self.units_.length}",
                                 source)
        if note is not None:
            self.notes_ = list(getattr(self, "notes_", [])) + [note]
        return note

    def fit_notes(self) -> list[str]:
        """What the fit could not settle from the runs, one sentence each (empty when nothing).

        Returns
        -------
        list of str
            E.g. an inertia that the runs cannot tell from a spring force
            (:func:`greybox.identify.inertia.inertia_note`); empty for a model
            loaded from a file that predates the record.
        """
        check_is_fitted(self)
        return list(getattr(self, "notes_", []))

    #: Known inertia ``J`` [A s^2/mm] (hyperparameter of the models that take it; ``None``: identified from the
    #: runs). A model with a known inertia is fitted on the effort less ``J a``, with no inertia of its own to find:
    #: 0 for an effort measured at the load (a force or torque sensor on the device), where no inertia lies
    #: between the sensor and the friction.
    inertia: float | None = None

    #: Hyperparameter that holds the first-stage model of a two-stage model (``None``: one stage). Options
    #: of the command line that the model does not take but its first stage does are set there.
    first_stage_param: str | None = None

    def first_stage(self):
        """Unfitted model of the first stage of a two-stage model; ``None`` for a one-stage model (default)."""
        return None

    def held_out_search(self) -> "CurrentModel":
        """An unfitted copy whose identification searches less, for scoring on held-out runs.

        ``greybox train --model auto`` fits every candidate once per fold only to score it on runs it did not
        see, and refits the chosen one with the full search (:mod:`greybox.train.candidates`). Models whose
        identification is a multi-start or Bayesian search return a copy with fewer starts or calls; the
        others (default) a plain copy.

        Returns
        -------
        CurrentModel
        """
        return clone(self)

    def fit_staged(self, logs, stage2_logs=None, *, progress=None, first_stage=None) -> "CurrentModel":
        """Fit a model whose stages may learn from different runs.

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs of the first stage (of the whole model for a one-stage model).
        stage2_logs : AxisLog or list of AxisLog, optional
            Prepared runs of the second stage; default ``logs``.
        progress : None, bool or callable, optional
            See :meth:`fit`.
        first_stage : CurrentModel, optional
            An already fitted first stage (a fit of :meth:`first_stage`) to freeze instead of fitting one.

        Returns
        -------
        self

        Raises
        ------
        ParameterError
            For a one-stage model given ``stage2_logs`` or ``first_stage``.
        """
        if stage2_logs is not None or first_stage is not None:
            raise ParameterError(f"a {type(self).__name__} has one stage: it fits on one set of runs")
        return self.fit(logs, progress=progress)

    def predict(self, logs: AxisLog | Iterable[AxisLog]) -> np.ndarray:
        """Predicted effort ``J a + friction + offset`` [A, or N].

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs; the state of a dynamic model restarts at each run.

        Returns
        -------
        ndarray, shape (n_samples,)
            The prediction of each run, concatenated in order.
        """
        runs = self._check_predict_runs(logs)
        return np.concatenate([self._effort(run, self.initial_state(), run.sample_time)[0] for run in runs])

    def predict_chunk(self, log: AxisLog, state=None, *, sample_time: float | None = None):
        """Predict one chunk of a run from a given state.

        Splitting a run into consecutive chunks and passing each returned state
        to the next chunk gives the prediction of the whole run.

        Parameters
        ----------
        log : AxisLog
            Prepared chunk: consecutive samples of one run, at least two.
        state : object, optional
            State before the chunk's first sample, as returned for the previous
            chunk; default :meth:`initial_state` (the start of a run).
        sample_time : float, optional
            Integration step [s] of a dynamic model; default the chunk's own
            median step. Pass the step of the whole run so that every chunk of
            a run with jittered time stamps is integrated alike.

        Returns
        -------
        current : ndarray, shape (n,)
            Predicted effort ``J a + friction + offset`` [A, or N].
        state : object
            State after the chunk's last sample: the ``state`` of the next chunk.
        """
        return self._effort(*self._chunk_arguments(log, state, sample_time))

    def predict_flag_chunk(self, log: AxisLog, state, region, *, sample_time: float):
        """:meth:`predict_chunk` and :meth:`outside_training_chunk` of one chunk of a run, together.

        Parameters
        ----------
        log : AxisLog
            Prepared chunk: consecutive samples of one run.
        state, region : object
            The model's state and the state of its training-region check before the chunk
            (:meth:`initial_state` and :meth:`region_state` at the start of a run).
        sample_time : float
            Step [s] of the whole run.

        Returns
        -------
        current : ndarray, shape (n,)
            Predicted effort [A, or N].
        state : object
            The model's state after the chunk.
        flags : dict of str to ndarray of bool
            As :meth:`outside_training`.
        region : object
            The region check's state after the chunk.
        """
        run, start, step = self._chunk_arguments(log, state, sample_time)
        return self._flagged_step(step)(run, start, region)

    def stream_view(self, first: AxisLog, *, sample_time: float) -> "StreamView":
        """The model for the chunks of one stream: the checks of the model and of the stream done once here.

        :meth:`predict_flag_chunk` checks the model, its chunk and its step on every call; a live stream
        gives chunks of a few samples many times a second, whose columns were checked as they arrived.
        The view's :meth:`~StreamView.predict_flag_chunk` gives what this model's gives, without them.

        Parameters
        ----------
        first : AxisLog
            The stream's first prepared chunk: the effort unit and kind of axis of all that follow.
        sample_time : float
            Step [s] of the stream's run.

        Returns
        -------
        StreamView

        Raises
        ------
        LogError
            For a chunk the model does not take (see :func:`check_runs`), or a step that is not positive.
        ParameterError
            For learned parameters that do not give a stable simulation at ``sample_time``.
        """
        self._check_predict_runs(first)
        if not (np.isfinite(sample_time) and sample_time > 0.0):
            raise LogError(first.source or None, f"the step must be a positive number of seconds, got {sample_time!r}")
        return StreamView(self, self._flagged_step(float(sample_time)))

    def _flagged_step(self, sample_time: float):
        """:meth:`_stream_step` with the ``"effort"`` flag of its prediction added (:meth:`effort_flags`), its
        region flags those of the operating region where the training record holds one."""
        inner = self._stream_step(sample_time)
        bounds = self._effort_bounds()  # checked once here, not per chunk
        operating = self.operating_region()
        if operating is not None:
            own = self._own_region_state()

            def checked(run, state, region):
                current, end, _, _ = inner(run, state, own)
                flags, region = operating.flags(run, region, sample_time=sample_time)
                return current, end, {**flags, **self._standstill_flags(run), **_effort_outside(bounds, current)}, \
                    region

            return checked

        def step(run, state, region):
            current, end, flags, region = inner(run, state, region)
            return current, end, {**flags, **_effort_outside(bounds, current)}, region

        return step

    def _stream_step(self, sample_time: float):
        """``step(run, state, region) -> (current, state, flags, region)`` of checked chunks at ``sample_time``.

        The model and the step are checked here, once; ``step`` does not check its chunk. Models that
        check their parameters per simulation override it to check them once.
        """
        check_is_fitted(self)

        def step(run, state, region):
            current, end = self._effort(run, state, sample_time)
            flags, region = self._region_flags(run, region, sample_time)
            return current, end, flags, region

        return step

    def friction_chunk(self, log: AxisLog, state=None, *, sample_time: float | None = None):
        """Friction of one chunk of a run from a given state (no inertia, no offset) [A, or N].

        Parameters
        ----------
        log, state, sample_time
            As in :meth:`predict_chunk`.

        Returns
        -------
        friction : ndarray, shape (n,)
        state : object
            State after the chunk's last sample.
        """
        return self._simulate(*self._chunk_arguments(log, state, sample_time))

    def friction(self, logs: AxisLog | Iterable[AxisLog]) -> np.ndarray:
        """Friction part of the prediction (no inertia, no offset) [A, or N].

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs; the state of a dynamic model restarts at each run.

        Returns
        -------
        ndarray, shape (n_samples,)
        """
        runs = self._check_predict_runs(logs)
        return np.concatenate([self._simulate(run, self.initial_state(), run.sample_time)[0] for run in runs])

    def score(self, logs: AxisLog | Iterable[AxisLog], y=None) -> float:
        """Negative RMSE of the prediction [A, or N] (greater is better, as scikit-learn expects).

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs with their measured effort.
        y : ignored
            The measured effort is each run's ``effort``.

        Returns
        -------
        float
        """
        runs = self._check_predict_runs(logs)
        return -rmse(np.concatenate([run.effort for run in runs]), self.predict(runs))

    @property
    def n_params(self) -> int:
        """Number of identified parameters of the fitted model."""
        check_is_fitted(self)
        return self._n_params()

    def parameter_table(self) -> list[Parameter]:
        """The identified parameters with units and descriptions: the model's own, then ``J`` and ``offset``.

        Returns
        -------
        list of Parameter
            Units carry the effort unit the model was fitted on (A, N or Nm) and the
            length unit of its motion (mm, or deg for a rotary axis); rows carry their
            95 % intervals when the model holds them (:mod:`greybox.identify.intervals`).
        """
        check_is_fitted(self)
        rows = self._own_parameters() + [
            Parameter("J", self.J_, f"{EFFORT} s^2/{LENGTH}", "inertia (x 1000 = kg for force logs)"),
            Parameter("offset", self.offset_, EFFORT, "constant effort"),
        ]
        unit, length = self.effort_unit_, self.units_.length
        return with_intervals(self, [Parameter(p.name, p.value, p.unit.replace(EFFORT, unit).replace(LENGTH, length),
                                               p.description) for p in rows])

    def parameter_summary(self) -> str:
        """The identified scalar parameters as one line of text (``"s_0 = 1.8 mm, ..."``), for messages.

        Returns
        -------
        str
        """
        check_is_fitted(self)
        rows = self._own_parameters() + [Parameter("J", self.J_, f"{EFFORT} s^2/{LENGTH}", ""),
                                         Parameter("offset", self.offset_, EFFORT, "")]
        unit, length = self.effort_unit_, self.units_.length
        return ", ".join(f"{p.name} = {float(p.value):.4g} {p.unit.replace(EFFORT, unit).replace(LENGTH, length)}"
                         .rstrip(" -") for p in rows if np.ndim(p.value) == 0)

    @property
    def units_(self) -> Motion:
        """Units of the axis the model was fitted on (a model file without the record: a linear axis)."""
        check_is_fitted(self)
        return MOTIONS[getattr(self, "motion_", "linear")]

    def fit_summary(self) -> dict:
        """Figures of the fit itself rather than of the model: data fitted on and what the search reports.

        Returns
        -------
        dict
            ``n_samples``, ``sample_time_s`` and the model's own fit statistics
            (e.g. ``cost`` = NMSE / 100 of a least-squares search, ``cv_rmse``
            of a hyperparameter search), names ending in their unit where they have one.
        """
        check_is_fitted(self)
        return {"n_samples": self.n_samples_fit_, "sample_time_s": self.sample_time_, **self._fit_statistics()}

    # ---------------------------------------------------------------- shared parts
    def _effort(self, run: AxisLog, state, sample_time: float):
        friction, end = self._simulate(run, state, sample_time)
        return self.J_ * run.acceleration + friction + self.offset_, end

    def _chunk_arguments(self, log: AxisLog, state, sample_time: float | None):
        """The checked chunk, its start state (default: the start of a run) and its integration step [s]."""
        (run,) = self._check_predict_runs(log)
        step = run.sample_time if sample_time is None else float(sample_time)
        return run, self.initial_state() if state is None else state, step

    def _set_fit_info(self, runs: list[AxisLog]) -> None:
        vars(self).pop("parameter_intervals_", None)  # intervals of an earlier fit are not this fit's
        self.effort_unit_ = runs[0].effort_unit
        self.motion_ = runs[0].motion
        self.sample_time_ = float(np.median([run.sample_time for run in runs]))
        self.n_samples_fit_ = int(sum(len(run) for run in runs))
        for name, channel in {**_REGION_CHANNELS, _EFFORT_RANGE: "effort"}.items():
            values = np.concatenate([getattr(run, channel) for run in runs])
            setattr(self, name, [float(np.min(values)), float(np.max(values))])

    def _widen_region(self, other: "CurrentModel") -> None:
        """Widen the training region to cover the one of ``other`` (a fitted stage this model contains)."""
        for name in [*_REGION_CHANNELS, _EFFORT_RANGE]:
            theirs = getattr(other, name, None)  # None: a stage loaded from a file that predates the record
            if theirs is not None:
                ours = getattr(self, name)
                setattr(self, name, [min(ours[0], theirs[0]), max(ours[1], theirs[1])])

    def operating_region(self) -> OperatingRegion | None:
        """The operating region of the model's training record, the same for every kind of model.

        Returns
        -------
        OperatingRegion or None
            :class:`~greybox.data.operating.OperatingRegion` of ``training_record_``; None for a model
            without the record (fitted in Python without :func:`greybox.train.record_training`, or read
            from a file that predates it): then the model's own ranges define its region.
        """
        record = getattr(self, TRAINING_ATTRIBUTE, None)
        cached = vars(self).get("_operating_cache")
        if cached is None or cached[0] is not record:  # built once per record: chunks of a stream ask each time
            cached = (record, OperatingRegion.of(record))
            self._operating_cache = cached
        return cached[1]

    def outside_training(self, log: AxisLog) -> dict[str, np.ndarray]:
        """Samples of one prepared run outside the region the training runs covered.

        Parameters
        ----------
        log : AxisLog
            One prepared run.

        Returns
        -------
        dict of str to ndarray of bool
            With the operating region of the training record (:meth:`operating_region`), its flags
            (:meth:`~greybox.data.operating.OperatingRegion.flags`: position, velocity, acceleration,
            motion) and ``"effort"``, whatever the kind of model. Without it (a model fitted in Python, or
            an older file), the model's own:
            ``{"position": ..., "velocity": ...}``: True where the position [mm] or the velocity [mm/s]
            lies outside the range of the training runs (kernel models add ``"inputs"``, their input
            space). A memoryless model (:meth:`initial_state` None: Coulomb, Stribeck, SVR) adds
            ``"standstill"``: speeds below :data:`STANDSTILL_SHARE` of the largest training speed, where
            the drive holds a friction left by the last motion that such a model cannot know. ``"effort"``
            (:meth:`effort_flags`): where the prediction leaves the range of the efforts measured in the
            training runs. Empty for a model loaded from a file that predates the record of the ranges.
        """
        operating = self.operating_region()
        if operating is not None:
            flags, _ = operating.flags(log, operating.start(), sample_time=log.sample_time)
            flags.update(self._standstill_flags(log))
        else:
            flags = self._input_region(log)
        return {**flags, **self.effort_flags(self.predict(log))}

    def _input_region(self, log: AxisLog) -> dict[str, np.ndarray]:
        """The flags of :meth:`outside_training` that the run's inputs give (all but ``"effort"``)."""
        flags, _ = self.outside_training_chunk(log, self.region_state(), sample_time=log.sample_time)
        return flags

    def effort_flags(self, predicted: np.ndarray) -> dict[str, np.ndarray]:
        """Where a prediction leaves the range of the efforts measured in the training runs.

        A friction model that predicts an effort the drive never produced on its training runs extrapolates,
        whatever its inputs: this catches a prediction that runs away inside the ranges of position and speed.

        Parameters
        ----------
        predicted : ndarray, shape (n,)
            The model's prediction of a run or chunk [A, N or Nm].

        Returns
        -------
        dict of str to ndarray of bool
            ``{"effort": ...}``; empty for a model file that predates the record (``effort_range_``).

        Raises
        ------
        ParameterError
            If the record is not two finite numbers, the first not above the second (a corrupt model file).
        """
        return _effort_outside(self._effort_bounds(), predicted)

    def _effort_bounds(self) -> tuple[float, float] | None:
        """The range of the training efforts ``(low, high)`` [A, N or Nm], checked; None for a file without it."""
        bounds = getattr(self, _EFFORT_RANGE, None)
        if bounds is None:
            return None
        try:
            low, high = (float(value) for value in bounds)
        except (TypeError, ValueError):
            low = high = float("nan")
        if not (np.isfinite(low) and np.isfinite(high) and low <= high):
            raise ParameterError(f"{_EFFORT_RANGE} (the range of the training efforts) must be two finite numbers, "
                                 f"low then high, got {bounds!r}")
        return low, high

    def region_state(self):
        """State carried by :meth:`outside_training_chunk` from chunk to chunk of a run, at its start.

        With the operating region of the training record, its start (the trailing window of positions);
        else the model's own (:meth:`_own_region_state`).
        """
        operating = self.operating_region()
        return self._own_region_state() if operating is None else operating.start()

    def _own_region_state(self):
        """The state of the model's own region check at the start of a run.

        None here: whether a sample lies in the model's own region depends on that sample alone.
        Kernel models on the states of a dynamic model carry that model's state.
        """
        return None

    def outside_training_chunk(self, log: AxisLog, state, *, sample_time: float):
        """:meth:`outside_training` of one chunk of a run, from the state the previous chunk ended in.

        Parameters
        ----------
        log : AxisLog
            Prepared chunk: consecutive samples of one run.
        state : object
            :meth:`region_state` at the start of the run, else what the previous chunk returned.
        sample_time : float
            Step [s] of the whole run.

        Returns
        -------
        flags : dict of str to ndarray of bool
            As :meth:`outside_training` for the chunk's samples, but for ``"effort"``, which needs the
            prediction (:meth:`predict_flag_chunk` gives both).
        state : object
            The state after the chunk: the ``state`` of the next chunk.
        """
        check_is_fitted(self)
        operating = self.operating_region()
        if operating is not None:
            flags, state = operating.flags(log, state, sample_time=sample_time)
            return {**flags, **self._standstill_flags(log)}, state
        return self._region_flags(log, state, sample_time)

    def _region_flags(self, log: AxisLog, state, sample_time: float):
        """:meth:`outside_training_chunk` of a fitted model (not checked again)."""
        out = {}
        for name, channel in _REGION_CHANNELS.items():
            bounds = getattr(self, name, None)
            if bounds is not None:
                values = getattr(log, channel)
                out[channel] = (values < bounds[0]) | (values > bounds[1])
        return {**out, **self._standstill_flags(log)}, state

    def _standstill_flags(self, log: AxisLog) -> dict[str, np.ndarray]:
        """``{"standstill": ...}`` of a memoryless model (:meth:`initial_state` None), else empty.

        A memoryless model gives the friction of the velocity alone: at rest the drive holds whatever
        friction the last motion left (up to the breakaway level), which it cannot know.
        """
        speeds = getattr(self, "velocity_range_mm_s_", None)
        if self.initial_state() is not None or speeds is None:
            return {}
        return {"standstill": np.abs(log.velocity) < STANDSTILL_SHARE * max(abs(speeds[0]), abs(speeds[1]))}

    def _check_predict_runs(self, logs) -> list[AxisLog]:
        check_is_fitted(self)
        runs = check_runs(logs)
        for run in runs:
            if run.effort_unit != self.effort_unit_:
                raise LogError(run.source or None,
                               f"log carries effort in {run.effort_unit}, the model was fitted on {self.effort_unit_}")
            if run.motion != self.units_.name:
                raise LogError(run.source or None, f"log is of a {run.motion} axis ({run.units.length}), the model "
                                                   f"was fitted on a {self.units_.name} axis ({self.units_.length})")
        return runs

    def _check_flags(self, *names: str) -> None:
        """Raise :class:`ParameterError` unless each named hyperparameter is a bool (``"False"`` is not one)."""
        for name in names:
            value = getattr(self, name)
            if not isinstance(value, (bool, np.bool_)):
                raise ParameterError(Setting(name, assign=False), f" must be True or False, got {value!r}")

    # ---------------------------------------------------------------- hooks
    def _check_params(self) -> None:
        return None

    def _fit_runs(self, runs: list[AxisLog], progress) -> None:
        raise NotImplementedError

    def _simulate(self, run: AxisLog, state, sample_time: float):
        raise NotImplementedError

    def _n_params(self) -> int:
        raise NotImplementedError

    def _own_parameters(self) -> list[Parameter]:
        raise NotImplementedError

    def _fit_statistics(self) -> dict:
        return {}


class StreamView:
    """A fitted model for the chunks of one stream, checked once (:meth:`CurrentModel.stream_view`).

    It answers :meth:`initial_state`, :meth:`region_state` and :meth:`predict_flag_chunk` as the model does,
    so that :func:`greybox.predict.process.process_blocks` runs it as the model itself.

    Parameters
    ----------
    model : CurrentModel
        The model.
    step : callable
        Its ``step(run, state, region)`` at the stream's step (:meth:`CurrentModel._stream_step`).
    """

    def __init__(self, model: CurrentModel, step):
        self.model = model
        self._step = step

    def initial_state(self):
        """The model's state at the start of a run."""
        return self.model.initial_state()

    def region_state(self):
        """The state of the model's region check at the start of a run."""
        return self.model.region_state()

    def predict_flag_chunk(self, log: AxisLog, state, region, *, sample_time: float):
        """:meth:`CurrentModel.predict_flag_chunk` of a chunk of the stream, not checked again.

        Parameters
        ----------
        log : AxisLog
            Prepared chunk of at least two samples with finite values (checked as they arrived).
        state, region : object
            As in :meth:`CurrentModel.predict_flag_chunk`.
        sample_time : float
            Step [s]; that of the view (the argument is there for the model's signature).
        """
        return self._step(log, state, region)
