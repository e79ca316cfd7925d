"""Model choice by how each candidate predicts runs it was not fitted on.

A model's training error says how well it can follow the runs it saw; what
a user needs is how well it predicts the next run, at other feeds and
amplitudes. Here every candidate is fitted on all training runs but one
*group* (a log file: the runs of one recording share its conditions) and
scored on the group it did not see, once per group: leave-one-run-out
cross-validation, which is leave-one-speed-out where the logs differ in
speed. With a single group, each run is cut into ``n_blocks`` contiguous
stretches, and stretch ``j`` of every run is held out in fold ``j``; a held-out
stretch is predicted as a run of its own, from rest.

The score of a fold is the relative error ``RE = RMSE / mean |effort|`` [%]
of its held-out samples (:func:`greybox.metrics.relative_error`); a
candidate's score is the mean over the folds, with the standard error of that
mean. The choice follows the one-standard-error rule: among the candidates
whose mean lies within one standard error of the best mean, the one with the
fewest identified parameters wins (ties: the lower mean). Prediction error on
unseen runs is what is compared, so a candidate that fits the training runs
better by following their noise does not win.

This module knows no model kind: the caller gives the candidate models
(unfitted estimators with ``fit``, ``predict`` and ``n_params``).
"""

from __future__ import annotations

import math
import multiprocessing
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from functools import partial
from typing import Callable, Sequence

import numpy as np
from sklearn.base import clone
from threadpoolctl import threadpool_limits

from ..errors import GreyboxError, ParameterError
from ..json_values import jsonable
from ..metrics import relative_error, rmse

__all__ = ["Fold", "CandidateScore", "held_out_folds", "score_candidates", "choose", "selection_record",
           "check_selection_record", "speed_fold", "lead_fold", "shared_stages", "RULE", "EXPLODING_FACTOR",
           "SPEED_MARGIN", "RACE_FACTOR"]

#: A held-out RE above this multiple of the RE of predicting zero effort on the same fold disqualifies [-]:
#: predicting nothing is the floor every model must beat; twice its error is a prediction that ran away.
EXPLODING_FACTOR = 2.0

#: A candidate whose held-out RE on the lead fold (:func:`lead_fold`) exceeds this multiple of the best
#: candidate's there is raced out: not fitted on the other folds, not chosen [-]. To have had the lowest mean
#: over ``k`` folds it would have had to beat that best candidate on the other folds by ``(RACE_FACTOR - 1) /
#: (k - 1)`` times the best's lead-fold RE on average (half of it with 2 folds). A rule of thumb that saves the
#: other folds of the slow candidates, not a bound: ``race=False`` (:func:`score_candidates`) scores every fold.
RACE_FACTOR = 1.5

#: A fold tests speed when its held-out runs are faster than its training runs by this factor [-] (99th
#: percentiles of ``|v|``): a fifth beyond the fastest training speed is a regime the training runs did not show.
SPEED_MARGIN = 1.2

#: The choice rule, as recorded with the result.
RULE = ("lowest mean held-out RE; among candidates within one standard error of it, the fewest parameters; "
        f"a fold's RE beyond {EXPLODING_FACTOR:g} times that of predicting zero disqualifies; on the fold that "
        "holds out the fastest runs, no worse than the simplest candidate by more than its standard error; a "
        "candidate whose RE on the first fold scored (the fastest runs' if one tests speed) is beyond "
        f"{RACE_FACTOR:g} times the best there is not fitted on the others")

#: Samples a held-out stretch needs at least (one second at 2 ms), so that it holds motion and reversals.
MIN_FOLD_SAMPLES = 500


@dataclass(frozen=True)
class Fold:
    """One split of the training runs.

    Attributes
    ----------
    name : str
        What is held out: a log's name, or ``"stretch 2 of 3"``.
    train : list of AxisLog
        Prepared runs the candidate is fitted on.
    test : list of AxisLog
        Prepared runs it predicts (each from rest).
    """

    name: str
    train: list
    test: list

    def speeds(self) -> tuple[float, float]:
        """The 99th percentile of ``|v|`` of the training and of the held-out runs [mm/s]."""
        return tuple(float(np.percentile(np.abs(np.concatenate([run.velocity for run in part])), 99))
                     for part in (self.train, self.test))

    def zero_re(self) -> float:
        """The held-out RE [%] of predicting zero effort: the floor a model must beat."""
        effort = np.concatenate([run.effort for run in self.test])
        return relative_error(effort, np.zeros_like(effort))


def speed_fold(folds: Sequence[Fold]) -> int | None:
    """Index of the fold whose held-out runs are fastest beyond its training runs' speed, if any.

    Parameters
    ----------
    folds : sequence of Fold
        From :func:`held_out_folds`.

    Returns
    -------
    int or None
        The fold with the highest held-out speed among those whose held-out speed exceeds
        :data:`SPEED_MARGIN` times its training speed (:meth:`Fold.speeds`); None when none does.
    """
    speeds = [fold.speeds() for fold in folds]
    faster = [i for i, (train, test) in enumerate(speeds) if test > SPEED_MARGIN * train]
    return max(faster, key=lambda i: speeds[i][1]) if faster else None


@dataclass
class CandidateScore:
    """The held-out figures of one candidate.

    Attributes
    ----------
    label : str
        The candidate's name.
    fold_re : list of float
        Held-out RE [%] per fold.
    fold_rmse : list of float
        Held-out RMSE per fold [effort unit].
    n_params : int
        Identified parameters (the median over the folds' fits).
    seconds : float
        Wall time of the fits and predictions [s].
    error : str or None
        Why the candidate could not be scored (a fit or prediction failed), else None.
    raced : bool
        Out by the racing rule (:data:`RACE_FACTOR`): ``fold_re`` holds its lead fold's RE only.
    """

    label: str
    fold_re: list = field(default_factory=list)
    fold_rmse: list = field(default_factory=list)
    n_params: int = 0
    seconds: float = 0.0
    error: str | None = None
    raced: bool = False

    @property
    def re(self) -> float:
        """Mean held-out RE over the folds [%] (NaN when not scored)."""
        return float(np.mean(self.fold_re)) if self.fold_re and self.error is None else math.nan

    @property
    def re_se(self) -> float:
        """Standard error of :attr:`re` [%] (the folds' sample standard deviation over sqrt(folds))."""
        if self.error is not None or len(self.fold_re) < 2:
            return math.nan
        return float(np.std(self.fold_re, ddof=1) / np.sqrt(len(self.fold_re)))

    @property
    def rmse(self) -> float:
        """Root mean of the folds' squared RMSE [effort unit] (NaN when not scored)."""
        return float(np.sqrt(np.mean(np.square(self.fold_rmse)))) if self.fold_rmse and self.error is None \
            else math.nan


def held_out_folds(runs: Sequence, groups: Sequence[str], *, n_blocks: int = 3) -> list[Fold]:
    """The folds of leave-one-group-out cross-validation (or of held-out stretches for one group).

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared training runs.
    groups : sequence of str
        The group of each run (its log file's name); runs of one group are held out together.
    n_blocks : int, default 3
        Stretches per run when all runs belong to one group.

    Returns
    -------
    list of Fold

    Raises
    ------
    GreyboxError
        If ``groups`` does not match ``runs``, or a single group's runs are too short to cut into
        ``n_blocks`` stretches of :data:`MIN_FOLD_SAMPLES` samples.
    """
    runs = list(runs)
    groups = [str(group) for group in groups]
    if len(groups) != len(runs) or not runs:
        raise GreyboxError(f"model choice needs one group per run, got {len(groups)} for {len(runs)} run(s)")
    names = list(dict.fromkeys(groups))
    if len(names) > 1:
        return [Fold(name, [run for run, group in zip(runs, groups) if group != name],
                     [run for run, group in zip(runs, groups) if group == name]) for name in names]
    if not (isinstance(n_blocks, int) and n_blocks >= 2):
        raise GreyboxError(f"n_blocks must be an integer of at least 2, got {n_blocks!r}")
    shortest = min(len(run) for run in runs)
    if shortest < n_blocks * MIN_FOLD_SAMPLES:
        raise GreyboxError(f"{names[0]}: a run of {shortest} samples is too short to hold out {n_blocks} stretches "
                           f"of {MIN_FOLD_SAMPLES} samples; give more training logs (each is held out in turn)")
    cuts = [np.linspace(0, len(run), n_blocks + 1).round().astype(int) for run in runs]
    pieces = [[run.select(slice(int(c[j]), int(c[j + 1]))) for j in range(n_blocks)] for run, c in zip(runs, cuts)]
    return [Fold(f"{names[0]}: stretch {j + 1} of {n_blocks}",
                 [piece for run_pieces in pieces for i, piece in enumerate(run_pieces) if i != j],
                 [run_pieces[j] for run_pieces in pieces]) for j in range(n_blocks)]


def _same_settings(model, other) -> bool:
    """Whether two unfitted estimators are the same class with the same settings (their fits agree)."""
    if type(model) is not type(other):
        return False
    return repr(sorted(model.get_params(deep=True).items())) == repr(sorted(other.get_params(deep=True).items()))


def shared_stages(models: Sequence) -> list[int | None]:
    """For each candidate, the candidate whose fit is its first stage, if any.

    A two-stage candidate (``first_stage()`` not None) whose unfitted first stage has the settings of another
    candidate freezes that candidate's fit on each fold (``fit_staged(..., first_stage=...)``) instead of
    fitting the same stage again: the fit is deterministic, so the figures are the same.

    Parameters
    ----------
    models : sequence of estimator
        The unfitted candidates.

    Returns
    -------
    list of int or None
        Index of the candidate that is its first stage, or None.
    """
    out: list[int | None] = []
    for model in models:
        stage = getattr(model, "first_stage", lambda: None)()
        owner = None if stage is None else next(
            (i for i, other in enumerate(models) if getattr(other, "first_stage", lambda: None)() is None
             and _same_settings(stage, other)), None)
        out.append(owner)
    return out


def _figures(fitted, fold: Fold, started: float) -> tuple[float, float, int, float]:
    """Held-out RE [%], RMSE, parameters and seconds since ``started`` of a fitted candidate on ``fold``."""
    prediction = fitted.predict(fold.test)
    effort = np.concatenate([run.effort for run in fold.test])
    if not np.all(np.isfinite(prediction)):
        raise GreyboxError(f"the prediction of {fold.name} is not finite")
    return (relative_error(effort, prediction), rmse(effort, prediction), int(fitted.n_params),
            time.perf_counter() - started)


def _score_fold(model, fold: Fold, first_stage=None):
    """Fit a clone of ``model`` on the fold's training runs (its first stage frozen to ``first_stage`` if given).

    Returns the figures of :func:`_figures` and the fitted model.
    """
    started = time.perf_counter()
    fitted = clone(model).fit(fold.train) if first_stage is None else \
        clone(model).fit_staged(fold.train, first_stage=first_stage)
    return _figures(fitted, fold, started), fitted


def _guarded(call):
    """``(call(), None)``, or ``(None, the error's text)`` for a failure of one fit."""
    try:
        return call(), None
    except GreyboxError as error:
        return None, str(error)
    except (ValueError, FloatingPointError, np.linalg.LinAlgError) as error:  # a numerical failure of one fit
        return None, f"{type(error).__name__}: {error}"


def _job(arguments):
    """One fold of one candidate and of the candidates that freeze its fit as their first stage.

    ``arguments``: the owner's model, the dependants' models and the fold. Returns one outcome per model,
    owner first: the figures, or the error's text. In a worker process the linear algebra runs on one thread
    (the workers already fill the cores).
    """
    model, dependants, fold = arguments
    with threadpool_limits(limits=1, user_api="blas"):
        outcome, error = _guarded(partial(_score_fold, model, fold))
        outcomes = [(None if outcome is None else outcome[0], error)]
        for dependant in dependants:
            if outcome is None:
                outcomes.append((None, error))
            else:
                scored, own_error = _guarded(partial(_score_fold, dependant, fold, first_stage=outcome[1]))
                outcomes.append((None if scored is None else scored[0], own_error))
    return outcomes


def lead_fold(folds: Sequence[Fold]) -> int:
    """The fold every candidate is scored on first: the one that tests speed (:func:`speed_fold`), else the first.

    Parameters
    ----------
    folds : sequence of Fold
        From :func:`held_out_folds`.

    Returns
    -------
    int
    """
    speed = speed_fold(folds)
    return 0 if speed is None else speed


def score_candidates(candidates: Sequence[tuple[str, object]], folds: Sequence[Fold], *, workers: int = 1,
                     progress: Callable[[str], None] | None = None, race: bool = True,
                     rivals: Sequence[CandidateScore] = ()) -> list[CandidateScore]:
    """Fit every candidate on every fold's training runs and score it on the runs held out.

    Every candidate is first scored on the lead fold (:func:`lead_fold`). A candidate whose fit failed or
    exploded there (:data:`EXPLODING_FACTOR`) is out; with ``race``, so is one whose held-out RE there
    exceeds :data:`RACE_FACTOR` times the best candidate's (of these and of ``rivals``): it is not fitted
    on the other folds (:data:`RACE_FACTOR` says what that costs). A two-stage candidate whose first stage
    is another candidate (:func:`shared_stages`) freezes that candidate's fit of each fold.

    Parameters
    ----------
    candidates : sequence of (str, estimator)
        Label and unfitted model of each candidate.
    folds : sequence of Fold
        From :func:`held_out_folds`.
    workers : int, default 1
        Processes fitting in parallel (1: in this process).
    progress : callable, optional
        Called with one line of text per finished fit.
    race : bool, default True
        Drop candidates far behind the best on the lead fold before fitting them on the others.
    rivals : sequence of CandidateScore, optional
        Candidates scored before on the same folds, whose lead-fold RE counts for the best.

    Returns
    -------
    list of CandidateScore
        In the order of ``candidates``; a candidate one of whose fits failed carries the error, one that
        exploded or was raced out its held-out RE so far and why it is out.
    """
    models = [model for _, model in candidates]
    owners = shared_stages(models)
    dependants = {c: [d for d, owner in enumerate(owners) if owner == c] for c in range(len(models))}
    roots = [c for c, owner in enumerate(owners) if owner is None]
    scores = [CandidateScore(label) for label, _ in candidates]
    figures: list[dict[int, tuple]] = [{} for _ in candidates]
    errors: list[dict[int, str]] = [{} for _ in candidates]
    floors = [fold.zero_re() for fold in folds]
    lead = lead_fold(folds)

    def record(c: int, f: int, outcome) -> None:
        values, error = outcome
        if error is not None:
            errors[c][f] = error
        else:
            figures[c][f] = values
        if progress is not None:
            figure = f"RE {values[0]:.2f} % ({values[3]:.1f} s)" if error is None else "failed"
            progress(f"{candidates[c][0]} without {folds[f].name}: {figure}")

    def run(jobs) -> None:
        """Fit the jobs ``(owner, fold, members)``, the most complex owners first (the list runs simplest first)."""
        jobs = sorted(jobs, key=lambda job: (-job[0], job[1]))
        arguments = [(models[c], [models[d] for d in members if d != c], folds[f]) for c, f, members in jobs]
        if workers <= 1 or len(jobs) <= 1:
            outcomes = map(_job, arguments)
            for (c, f, members), outcome in zip(jobs, outcomes):
                for member, result in zip([c] + [d for d in members if d != c], outcome):
                    if member in members:
                        record(member, f, result)
            return
        # fresh interpreters, not forks: a fork of a process whose compiled kernels run threads may deadlock
        context = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(max_workers=min(workers, len(jobs)), mp_context=context) as pool:
            futures = {pool.submit(_job, argument): job for job, argument in zip(jobs, arguments)}
            for future in as_completed(futures):
                c, f, members = futures[future]
                for member, result in zip([c] + [d for d in members if d != c], future.result()):
                    if member in members:
                        record(member, f, result)

    run([(c, lead, [c] + dependants[c]) for c in roots])
    alive = [c for c in range(len(models)) if lead in figures[c]
             and figures[c][lead][0] <= EXPLODING_FACTOR * floors[lead]]
    leads = [figures[c][lead][0] for c in alive] + [s.fold_re[lead] for s in rivals
                                                      if s.error is None and len(s.fold_re) == len(folds)]
    best = min(leads, default=math.inf)
    raced = set()
    if race:
        raced = {c for c in alive if figures[c][lead][0] > RACE_FACTOR * best}
        alive = [c for c in alive if c not in raced]
    rest = [f for f in range(len(folds)) if f != lead]
    run([(c, f, [m for m in [c] + dependants[c] if m in alive]) for c in roots for f in rest
         if any(m in alive for m in [c] + dependants[c])])

    for c, score in enumerate(scores):
        done = sorted(figures[c])
        score.fold_re = [figures[c][f][0] for f in done]
        score.fold_rmse = [figures[c][f][1] for f in done]
        score.seconds = float(sum(figures[c][f][3] for f in done))
        score.n_params = int(np.median([figures[c][f][2] for f in done])) if done else 0
        if errors[c]:
            f = min(errors[c])
            score.error = f"{folds[f].name}: {errors[c][f]}"
            score.fold_re, score.fold_rmse = [], []
            continue
        for f in done:
            if not figures[c][f][0] <= EXPLODING_FACTOR * floors[f]:
                score.error = (f"{folds[f].name}: held-out RE {figures[c][f][0]:.4g} % exploded (beyond "
                               f"{EXPLODING_FACTOR:g} times the {floors[f]:.4g} % of predicting zero)")
                break
        if score.error is None and c in raced:
            score.raced = True
            score.error = (f"{folds[lead].name}: held-out RE {figures[c][lead][0]:.4g} % beyond {RACE_FACTOR:g} times "
                           f"the best candidate's {best:.4g} % there: raced out, not fitted on the other folds")
    return scores


def choose(scores: Sequence[CandidateScore], speed: int | None = None) -> int:
    """Index of the chosen candidate by the one-standard-error rule (:data:`RULE`).

    Parameters
    ----------
    scores : sequence of CandidateScore
        Scored candidates; failed (or exploded) ones are never chosen.
    speed : int, optional
        Index of the fold that tests speed (:func:`speed_fold`): candidates that predict it worse than the
        simplest candidate (fewest parameters, then the first; scored or raced out) by more than that one's
        standard error are not chosen. A raced-out simplest candidate sets no ceiling: the speed fold is then
        the lead fold, where every candidate left predicted better than it.

    Returns
    -------
    int

    Raises
    ------
    GreyboxError
        If no candidate could be scored.
    """
    scored = [i for i, score in enumerate(scores) if score.error is None and score.fold_re]
    if not scored:
        reasons = "; ".join(f"{score.label}: {score.error}" for score in scores)
        raise GreyboxError(f"no candidate model could be scored on the held-out runs ({reasons})")
    if speed is not None:
        # the simplest among those scored and those raced out: a raced-out simplest candidate was out on the
        # speed fold (the lead fold), beyond the factor of the best, and every candidate left beats it there
        reference = [i for i, score in enumerate(scores) if i in scored or score.raced]
        simplest = scores[min(reference, key=lambda i: scores[i].n_params)]
        if not simplest.raced:
            spread = simplest.re_se
            ceiling = simplest.fold_re[speed] + (spread if math.isfinite(spread) else 0.0)
            scored = [i for i in scored if scores[i].fold_re[speed] <= ceiling]
    best = min(scored, key=lambda i: scores[i].re)
    spread = scores[best].re_se
    limit = scores[best].re + (spread if math.isfinite(spread) else 0.0)
    within = [i for i in scored if scores[i].re <= limit]
    return min(within, key=lambda i: (scores[i].n_params, scores[i].re))


def selection_record(scores: Sequence[CandidateScore], folds: Sequence[Fold], chosen: int, notes=()) -> dict:
    """The record of a model choice that a model file keeps (plain values only).

    Parameters
    ----------
    scores : sequence of CandidateScore
        Every candidate's figures.
    folds : sequence of Fold
        The folds they were scored on.
    chosen : int
        Index of the chosen candidate.
    notes : sequence of str, optional
        What the choice decided besides the scores (e.g. an inertia refused).

    Returns
    -------
    dict
        ``rule``, ``metric``, ``folds`` (names), ``chosen`` (label), ``notes`` and ``candidates``: one
        object per candidate with ``label``, ``re``, ``re_se``, ``rmse``, ``n_params``, ``fold_re`` and
        ``error`` (None when scored).
    """
    return {
        "rule": RULE,
        "metric": "RE = RMSE / mean |effort| of the held-out runs [%], mean over the folds",
        "folds": [fold.name for fold in folds],
        "chosen": scores[chosen].label,
        "notes": [str(note) for note in notes],
        "candidates": [{"label": s.label, "re": jsonable(s.re), "re_se": jsonable(s.re_se), "rmse": jsonable(s.rmse),
                        "n_params": int(s.n_params), "fold_re": [float(v) for v in s.fold_re], "error": s.error}
                       for s in scores],
    }


def _text(value, limit: int = 2000) -> bool:
    return isinstance(value, str) and len(value) <= limit


def _number(value) -> bool:
    return value is None or (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
                             and value >= 0.0)


def check_selection_record(record) -> None:
    """Raise :class:`GreyboxError` unless ``record`` has the shape :func:`selection_record` gives.

    Parameters
    ----------
    record : object
        The ``selection_`` attribute read from a model file.
    """
    def fail(problem: str):
        raise ParameterError(f"selection_ (the record of the model choice) {problem}")

    if not isinstance(record, dict) or set(record) != {"rule", "metric", "folds", "chosen", "notes", "candidates"}:
        fail("must be an object with rule, metric, folds, chosen, notes and candidates")
    if not all(_text(record[name]) for name in ("rule", "metric", "chosen")):
        fail("has a rule, metric or chosen label that is not short text")
    for name in ("folds", "notes"):
        if not (isinstance(record[name], list) and len(record[name]) <= 1000 and all(map(_text, record[name]))):
            fail(f"has {name} that are not a list of short texts")
    candidates = record["candidates"]
    if not (isinstance(candidates, list) and 0 < len(candidates) <= 1000):
        fail("must list between 1 and 1000 candidates")
    keys = {"label", "re", "re_se", "rmse", "n_params", "fold_re", "error"}
    for entry in candidates:
        if not isinstance(entry, dict) or set(entry) != keys:
            fail(f"has a candidate that is not an object with {', '.join(sorted(keys))}")
        if not (_text(entry["label"]) and all(_number(entry[name]) for name in ("re", "re_se", "rmse"))
                and isinstance(entry["n_params"], int) and not isinstance(entry["n_params"], bool)
                and entry["n_params"] >= 0 and isinstance(entry["fold_re"], list)
                and len(entry["fold_re"]) <= len(record["folds"])
                and all(_number(v) and v is not None for v in entry["fold_re"])
                and (entry["error"] is None or _text(entry["error"]))):
            fail(f"has a malformed candidate {str(entry.get('label'))[:80]!r}")
    if record["chosen"] not in [entry["label"] for entry in candidates]:
        fail(f"names a chosen candidate {record['chosen'][:80]!r} that is not among its candidates")
