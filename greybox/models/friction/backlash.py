"""Backlash (lost motion) between the measured motion and the friction contact, for any friction model.

A worn ball screw, or a device with a clearance, has a gap of width ``b`` in
the chain that carries the friction force to the motor: when the force
through the chain changes sign, the motor travels ``b`` before it loads the
other face. While the gap is open no force passes: the friction contact
behind it keeps its state (it is not moved), and the effort is what the model
gives at standstill in that state (at the moment the gap opened the force
crossed zero).

:class:`BacklashModel` wraps any current model (the *base*), which sees the
motion of the motor outside the gaps and standstill inside them:

- in contact, the base model runs on the logged motion, its state carried;
- when its friction changes sign after a load of at least ``threshold_``,
  the gap opens at the present motor position ``x``: it spans ``[x - b, x]``
  after a positive load, ``[x, x + b]`` after a negative one
  (:func:`greybox.models.friction.kernels.backlash_gap_kernel`);
- the motor leaving the span closes the contact, on either face;
- a run starts in the middle of a gap (the load's position in the gap is not logged).

Identification (``width=None``): for a trial width the gaps of the training
runs are found from the *measured* effort by the same rule, and the base
model is fitted on the runs with the motion set to standstill inside them;
the model then predicts the runs with its own gaps, and the width with the
least squared error wins: 0 and a log grid up to half the stroke of the runs,
refined by a bounded scalar search around the best. The search runs on block
means of the runs where they sample the pre-sliding transition finely enough
(:mod:`greybox.identify.coarse`: at least 10 samples within the pre-sliding
deflection at the top speed); each trial fits the base's held-out search
(:meth:`~greybox.models.estimator.CurrentModel.held_out_search`), and the
full fit (``refine``) fits the base with its own search once more, on the runs
themselves, at the width found. ``threshold_`` is 5 % of
the median absolute training effort, so that noise around zero does not open
a gap. ``width=0`` is the base model itself.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.optimize import minimize_scalar
from sklearn.base import clone
from sklearn.utils.validation import check_is_fitted

from ...base import EFFORT, LENGTH, Parameter
from ...data.log import AxisLog
from ...errors import ParameterError
from ...identify.coarse import block_means, coarse_block
from ...identify.progress import ProgressEvent
from ..estimator import CurrentModel
from .gms import GMSModel
from .kernels import backlash_gap_kernel

__all__ = ["BacklashModel", "BacklashState", "gaps_of", "stroke"]

#: Trial widths of the grid (besides 0), log-spaced from 1e-3 to 1 times the largest width tried.
_N_GRID = 10

#: Evaluations of the refinement of ``log b`` around the best grid width.
_N_REFINE = 8

#: Load that counts as one, as a fraction of the median absolute training effort.
_THRESHOLD_FRACTION = 0.05


class BacklashState(NamedTuple):
    """State of a backlash model between two chunks.

    Attributes
    ----------
    gap_low, gap_high : float
        Span of the open gap [mm]; NaN in contact. Both NaN at the start of a
        run mean a gap centred on the first position.
    loaded : int
        Sign of the last load through the gap (+1, -1, 0 for none yet).
    base : object
        State of the base model.
    run_start : bool
        True before the first sample of a run: the gap is then centred on the first position.
    """

    gap_low: float
    gap_high: float
    loaded: int
    base: object
    run_start: bool = False


def gaps_of(position, force, width: float, threshold: float, state: BacklashState):
    """Samples inside the gap for a given force through the backlash, and the gap state after them.

    Parameters
    ----------
    position : ndarray, shape (n,)
        Motor-side position [mm].
    force : ndarray, shape (n,)
        Force through the backlash [A or N].
    width, threshold : float
        Backlash [mm] and the force that counts as a load [A or N].
    state : BacklashState
        State before the first sample (its ``base`` is not used).

    Returns
    -------
    in_gap : ndarray of bool, shape (n,)
    gap_low, gap_high : float
    loaded : int
    """
    position = np.ascontiguousarray(position, dtype=float)
    in_gap = np.empty(position.size, dtype=np.bool_)
    low, high = _start_gap(position, width, state)
    low, high, loaded = backlash_gap_kernel(position, np.ascontiguousarray(force, dtype=float), float(width),
                                            float(threshold), low, high, int(state.loaded), in_gap)
    return in_gap, float(low), float(high), int(loaded)


def _start_gap(position, width, state) -> tuple[float, float]:
    """The gap span before the first sample: the state's, or centred on the first position at a run's start."""
    if state.run_start:
        return float(position[0]) - 0.5 * width, float(position[0]) + 0.5 * width
    return float(state.gap_low), float(state.gap_high)


def stroke(runs) -> float:
    """Median over the runs of the distance between the smallest and the largest position [mm].

    Parameters
    ----------
    runs : iterable of AxisLog
        Runs with at least one sample each.
    """
    return float(np.median([np.ptp(run.position) for run in runs]))


def _standstill(run: AxisLog) -> AxisLog:
    """The samples of ``run`` with the motion stopped (zero velocity and acceleration)."""
    return run.replace(velocity=np.zeros(len(run)), acceleration=np.zeros(len(run)))


class BacklashModel(CurrentModel):
    """A current model behind a backlash: no force passes while the gap is crossed.

    Parameters
    ----------
    base : CurrentModel, optional
        Settings of the model in contact (unfitted, cloned before fitting);
        ``GMSModel()`` by default.
    width : float, optional
        Backlash [mm] (the motor travel across the gap); identified from the data when None.
    refine : bool, default True
        Refine the best width of the grid by a bounded scalar search (up to 8 more trial fits), then fit the
        base with its full search on the runs themselves at the width found; False keeps the grid's best width
        and the base its trial fitted (on block means when :attr:`block_` > 1: :meth:`held_out_search`).

    Attributes
    ----------
    base_ : CurrentModel
        The fitted base model.
    width_ : float
        Backlash [mm].
    threshold_ : float
        Force that counts as a load through the gap [A, or N].
    J_ : float
        Inertia of the base model [A s^2/mm].
    offset_ : float
        Offset of the base model [A].
    cost_ : float
        Squared error of the training prediction over ``n var(effort)``.
    block_ : int
        Samples per block mean of the runs the width was searched on (:func:`greybox.identify.coarse.coarse_block`;
        1: the runs themselves).
    effort_unit_ : str
        "A" or "N".
    """

    def __init__(self, *, base=None, width: float | None = None, refine: bool = True):
        self.base = base
        self.width = width
        self.refine = refine

    # ---------------------------------------------------------------- fitting
    def _check_params(self) -> None:
        if self.base is not None and (not isinstance(self.base, CurrentModel) or isinstance(self.base, BacklashModel)):
            raise ParameterError(f"base must be a current model other than BacklashModel, got "
                                 f"{type(self.base).__name__}")
        self._check_flags("refine")
        width = self.width
        if width is not None and not (isinstance(width, (int, float, np.number)) and not isinstance(width, bool)
                                      and np.isfinite(width) and width >= 0.0):
            raise ParameterError(f"width must be a non-negative backlash in mm or None, got {width!r}")

    def held_out_search(self) -> "BacklashModel":
        """A copy that keeps the grid's best width unrefined and the base its trial fitted (a held-out search of
        the base, :meth:`CurrentModel.held_out_search`, on block means when the runs are oversampled): the grid
        tells a gap from none, which is what a fold scores.

        Returns
        -------
        BacklashModel
        """
        return clone(self).set_params(base=self._base_template().held_out_search(), refine=False)

    def _base_template(self):
        """Unfitted base model (a clone of ``base``, ``GMSModel()`` by default)."""
        return clone(GMSModel() if self.base is None else self.base)

    def _fit_runs(self, runs, progress) -> None:
        target = np.concatenate([run.effort for run in runs])
        self.threshold_ = _THRESHOLD_FRACTION * float(np.median(np.abs(target)))
        self.block_ = 1 if self.width is not None else coarse_block(runs)
        width, searched = (float(self.width), None) if self.width is not None else self._search_width(runs, progress)
        if searched is None or self.refine:
            self.base_ = self._base_template().fit(self._contact_runs(runs, width))
        else:  # a held-out search keeps the base its width search fitted (on block means): it only scores
            self.base_ = searched
        self.cost_ = self._cost(runs, width, self.base_)
        self.width_ = width
        self.J_, self.offset_ = float(self.base_.J_), float(self.base_.offset_)

    def _search_width(self, runs, progress):
        """The width of least cost and its base: 0 and the grid, refined when ``refine``; each trial fits the
        base's held-out search on the runs' block means (:attr:`block_`)."""
        coarse = [block_means(run, self.block_) for run in runs]
        widths = [0.0] + list(np.geomspace(1e-3, 1.0, _N_GRID) * 0.5 * stroke(runs))
        n_trials = len(widths) + _N_REFINE * int(self.refine)
        trials = {}

        def cost(width):
            if width not in trials:
                base = self._base_template().held_out_search().fit(self._contact_runs(coarse, width))
                trials[width] = (self._cost(coarse, width, base), base)
                if progress is not None:
                    best = min(trial[0] for trial in trials.values())
                    progress(ProgressEvent("backlash width", len(trials) - 1, n_trials, 1, trials[width][0],
                                           best, done=True))
            return trials[width][0]

        best = int(np.argmin([cost(w) for w in widths]))
        if best > 0 and self.refine:
            logs = np.log(widths[1:])
            low, high = logs[max(best - 2, 0)], logs[min(best, len(logs) - 1)]
            minimize_scalar(lambda x: cost(float(np.exp(x))), bounds=(low, high), method="bounded",
                            options={"xatol": 0.02, "maxiter": _N_REFINE})
        width = min(trials, key=lambda w: (trials[w][0], w))
        return float(width), trials[width][1]

    def _cost(self, runs, width, base) -> float:
        """Squared error over ``n var(effort)`` of ``base`` behind a backlash of ``width`` predicting ``runs``."""
        target = np.concatenate([run.effort for run in runs])
        prediction = np.concatenate([_through_gaps(base, width, self.threshold_, run, None, run.sample_time,
                                                   "_effort")[0] for run in runs])
        return float(np.sum((prediction - target) ** 2) / (target.size * max(float(np.var(target)),
                                                                             np.finfo(float).tiny)))

    def _contact_runs(self, runs, width: float) -> list[AxisLog]:
        """The runs as the base model is fitted on them: motion zeroed where the measured effort crosses the gap."""
        inputs = []
        for run in runs:
            start = BacklashState(np.nan, np.nan, 0, None, run_start=True)
            in_gap = gaps_of(run.position, run.effort, width, self.threshold_, start)[0] & (width > 0.0)
            inputs.append(run.replace(velocity=np.where(in_gap, 0.0, run.velocity),
                                      acceleration=np.where(in_gap, 0.0, run.acceleration)))
        return inputs

    def interval_stage(self, runs):
        """The base model, fitted on the runs with the gaps at standstill, identifies the parameters but the width.

        Parameters
        ----------
        runs : list of AxisLog
            The prepared runs the model was fitted on.
        """
        return self.base_, "base.", self._contact_runs(runs, self.width_)

    def interval_notes(self) -> dict[str, str]:
        """The width is chosen on a grid (the base's intervals hold for it); the threshold is set from the data."""
        return {"width": "chosen by a grid search (the base's intervals are for this width)",
                "threshold": "set from the median effort, not identified"}

    # ---------------------------------------------------------------- prediction
    def initial_state(self) -> BacklashState:
        """A gap centred on the first position, the base model at rest."""
        return BacklashState(np.nan, np.nan, 0, self.base_.initial_state(), run_start=True)

    def _effort(self, run: AxisLog, state, sample_time: float):
        return _through_gaps(self.base_, self.width_, self.threshold_, run, state, sample_time, "_effort")

    def _simulate(self, run: AxisLog, state, sample_time):
        return _through_gaps(self.base_, self.width_, self.threshold_, run, state, sample_time, "_simulate")

    def _n_params(self) -> int:
        return self.base_.n_params + int(self.width is None)

    def _fit_statistics(self) -> dict:
        return {"cost": self.cost_}

    def _own_parameters(self) -> list[Parameter]:
        check_is_fitted(self, "base_")
        own = [Parameter("width", self.width_, LENGTH, "backlash: motor travel across the gap"),
               Parameter("threshold", self.threshold_, EFFORT, "force that counts as a load through the gap")]
        return own + [Parameter(f"base.{p.name}", p.value, p.unit, f"base model: {p.description}")
                      for p in self.base_.parameter_table() if p.name not in ("J", "offset")]


def _through_gaps(base, width, threshold, run: AxisLog, state, sample_time, method: str):
    """Effort (``method="_effort"``) or friction (``"_simulate"``) of a chunk behind the backlash.

    Contact phases run the base model on the motion; from the sample where its
    friction opens the gap, the base model stands still until the motor
    leaves the gap. The base model's own hooks are called per phase (a phase
    may be a single sample).

    Returns
    -------
    ndarray, shape (n,)
    BacklashState
        The state after the last sample.
    """
    state = BacklashState(np.nan, np.nan, 0, base.initial_state(), run_start=True) if state is None \
        else BacklashState(*state)
    step_of = getattr(base, method)
    if width == 0.0:
        out, base_state = step_of(run, state.base, sample_time)
        return out, BacklashState(np.nan, np.nan, 0, base_state)
    n = len(run)
    out = np.empty(n)
    low, high = _start_gap(run.position, width, state)
    loaded, base_state = state.loaded, state.base
    i = 0
    while i < n:
        if not np.isnan(low):  # the gap is open: the base model stands still until the motor leaves it
            x = run.position[i:]
            outside = np.flatnonzero((x < low) | (x > high))
            stop = n if outside.size == 0 else i + int(outside[0])
            if stop > i:
                out[i:stop], base_state = step_of(_standstill(run.select(slice(i, stop))), base_state, sample_time)
            if stop < n:
                low = high = np.nan
                loaded = 0
            i = stop
            continue
        rest = run.select(slice(i, n))
        friction, _ = base._simulate(rest, base_state, sample_time)
        contact = BacklashState(np.nan, np.nan, loaded, None)
        opened = np.flatnonzero(gaps_of(rest.position, friction, width, threshold, contact)[0])
        stop = n if opened.size == 0 else i + int(opened[0])
        until = min(stop - i + 1, n - i)  # the gap state at its opening sample (or at the end)
        _, low, high, loaded = gaps_of(rest.position[:until], friction[:until], width, threshold, contact)
        if stop > i:
            out[i:stop], base_state = step_of(run.select(slice(i, stop)), base_state, sample_time)
        i = stop
    return out, BacklashState(low, high, loaded, base_state)
