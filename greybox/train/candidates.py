"""``greybox train --model auto``: the candidate models, and the one that predicts unseen runs best.

A candidate is written ``KIND[:OPTION,...]``: a registered model kind
(:data:`greybox.models.registry.MODEL_CLASSES`) and options of the model or of its
first stage (``gms:asymmetric``, ``gmssvr:asymmetric``), among them

- ``asymmetric``: friction of its own per direction of motion;
- ``offset``: a constant effort;
- ``elements=N``: Maxwell-slip elements of a GMS model;
- ``backlash``: the model behind a backlash of identified width;
- ``inertia=J``: a known inertia [effort s^2/length] (``inertia=0``: the effort is measured at the load).

:data:`DEFAULT_CANDIDATES` runs from the static curves to the grey-box
model, and :data:`GAP_CANDIDATES` (dynamic models behind a backlash) join
them when a static model behind a backlash shows a gap; :func:`choose_model` scores each by leave-one-run-out
cross-validation (:mod:`greybox.identify.selection`), refits the chosen one
on every run and keeps the table it chose from in ``selection_``. The folds fit each candidate with its
held-out search (:meth:`~greybox.models.estimator.CurrentModel.held_out_search`: the GMS search without
its perturbed starts, 10 instead of 25 Bayesian calls of an SVR stage): a fold's fit only scores the
candidate, and the chosen one is refitted with the full search.

Before any candidate is fitted the runs are checked for an inertia that
could only stand in for a spring (:mod:`greybox.identify.inertia`): when one
law ``a = -c x`` explains the runs' acceleration, held-out runs of the same
kind cannot tell the two apart either, so the candidates are fitted with no
inertia (``J = 0``, as for an effort measured at the load) unless the caller
gives one, and the record says so.
"""

from __future__ import annotations

from typing import Callable, Sequence

from ..errors import GreyboxError
from ..identify.inertia import SPRING_SHARE_LIMIT, spring_share
from ..identify.selection import (
    choose,
    held_out_folds,
    lead_fold,
    score_candidates,
    selection_record,
    speed_fold,
)
from ..models.friction.backlash import BacklashModel
from ..models.registry import MODEL_CLASSES

__all__ = ["DEFAULT_CANDIDATES", "GAP_CANDIDATES", "GAP_EVIDENCE", "build_candidate", "choose_model", "gap_shown"]

#: The candidates of ``--model auto``, simplest first: each kind's symmetric form with an offset and its
#: direction-dependent form, a static model behind a backlash, and the grey-box model.
DEFAULT_CANDIDATES = (
    "coulomb:offset",
    "coulomb:asymmetric",
    "stribeck:offset",
    "stribeck:asymmetric",
    "stribeck:asymmetric,backlash",
    "lugre:offset",
    "lugre:asymmetric",
    "gms:offset",
    "gms:asymmetric",
    "gmssvr:offset",
    "gmssvr:asymmetric",
)

#: Candidates tried only when the runs show a gap: when a static model behind an identified backlash
#: predicts the held-out runs better than the same model without it (:data:`GAP_EVIDENCE`). A dynamic model
#: behind a backlash is identified by one fit per trial width (11 in a fold, up to 19 in the
#: full fit; on block means of oversampled runs, :mod:`greybox.identify.coarse`), too slow to try on every axis.
GAP_CANDIDATES = ("gms:offset,backlash", "gms:asymmetric,backlash")

#: (model without a gap, the same behind a backlash): both among the candidates, the second better on the
#: held-out runs is the evidence of a gap that :data:`GAP_CANDIDATES` need.
GAP_EVIDENCE = ("stribeck:asymmetric", "stribeck:asymmetric,backlash")

#: Candidate options that are switches: option -> hyperparameter.
_SWITCHES = {"asymmetric": "asymmetric", "offset": "fit_offset"}
#: Candidate options with a value: option -> (hyperparameter, type).
_VALUES = {"elements": ("n_elements", int), "inertia": ("inertia", float)}


def _fail(spec: str, problem: str):
    raise GreyboxError(f"candidate {spec!r}: {problem}")


def build_candidate(spec: str, *, inertia: float | None = None):
    """The unfitted model a candidate specification names.

    Parameters
    ----------
    spec : str
        ``KIND[:OPTION,...]`` (see the module notes).
    inertia : float, optional
        Known inertia [effort s^2/length] for a candidate that does not give its own.

    Returns
    -------
    CurrentModel

    Raises
    ------
    GreyboxError
        Naming the candidate, for an unknown kind or option, a malformed value, or an option the kind
        does not take.
    """
    kind, _, text = str(spec).strip().partition(":")
    kind = kind.strip()
    if kind not in MODEL_CLASSES:
        _fail(spec, f"unknown model kind {kind!r}; known: {', '.join(sorted(MODEL_CLASSES))}")
    model = MODEL_CLASSES[kind]()
    params, backlash = {}, False
    if inertia is not None:
        params["inertia"] = float(inertia)
    for option in (part.strip() for part in text.split(",") if part.strip()):
        name, sep, value = option.partition("=")
        if name == "backlash" and not sep:
            backlash = True
        elif name in _SWITCHES and not sep:
            params[_SWITCHES[name]] = True
        elif name in _VALUES and sep:
            hyperparameter, kind_of = _VALUES[name]
            try:
                params[hyperparameter] = kind_of(value)
            except ValueError:
                _fail(spec, f"option {name} needs a number, got {value!r}")
        else:
            known = sorted([*_SWITCHES, "backlash", *(f"{v}=..." for v in _VALUES)])
            _fail(spec, f"unknown option {option!r}; options: {', '.join(known)}")
    accepted = model.get_params(deep=False)
    stage = model.first_stage()
    own = {name: value for name, value in params.items() if name in accepted}
    staged = {name: value for name, value in params.items() if name not in accepted}
    if staged:
        if stage is None or any(name not in stage.get_params(deep=False) for name in staged):
            _fail(spec, f"the {kind} model takes no {', '.join(sorted(staged))}")
        own[model.first_stage_param] = stage.set_params(**staged)
    model.set_params(**own)
    return BacklashModel(base=model) if backlash else model


def gap_shown(without, behind, lead: int):
    """Whether the model behind a backlash predicts the held-out runs better than the same model without it.

    Parameters
    ----------
    without, behind : CandidateScore
        The scores of the two candidates of :data:`GAP_EVIDENCE`.
    lead : int
        The lead fold (:func:`~greybox.identify.selection.lead_fold`).

    Returns
    -------
    tuple or None
        ``(RE without, RE behind, what was compared)`` [%] when ``behind`` is better: their mean RE when both
        were scored on every fold, their lead fold's when either was raced out there; None otherwise (or
        when either failed).
    """
    def lead_re(score):
        if score.raced:
            return score.fold_re[0]
        return score.fold_re[lead] if score.error is None and score.fold_re else None

    if without.error is None and behind.error is None:
        pair, what = (without.re, behind.re), ""
    else:
        pair, what = (lead_re(without), lead_re(behind)), " on the lead fold"
    if None in pair or not pair[1] < pair[0]:
        return None
    return pair[0], pair[1], what


def _screened(models):
    """The candidates as the folds fit them: each one's held-out search (``held_out_search``: fewer starts or
    Bayesian calls); the chosen one is refitted with its full search."""
    return [(spec, model.held_out_search()) for spec, model in models]


def choose_model(runs: Sequence, groups: Sequence[str], *, candidates: Sequence[str] = DEFAULT_CANDIDATES,
                 gap_candidates: Sequence[str] = GAP_CANDIDATES, inertia: float | None = None, n_blocks: int = 3,
                 workers: int = 1, progress: Callable[[str], None] | None = None):
    """Score the candidates on held-out runs, refit the chosen one on all runs and return it.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared training runs.
    groups : sequence of str
        The log file of each run; a file's runs are held out together.
    candidates : sequence of str, default :data:`DEFAULT_CANDIDATES`
        Candidate specifications (``KIND[:OPTION,...]``).
    gap_candidates : sequence of str, default :data:`GAP_CANDIDATES`
        Candidates scored too when both of :data:`GAP_EVIDENCE` are among ``candidates`` and the second
        predicts the held-out runs better (and not already among them).
    inertia : float, optional
        Known inertia [effort s^2/length] of every candidate (0: the effort is measured at the load);
        identified by each candidate when None, unless the runs cannot tell it from a spring force.
    n_blocks : int, default 3
        Held-out stretches per run when all runs come from one file.
    workers : int, default 1
        Processes fitting in parallel.
    progress : callable, optional
        Called with one line of text per finished fit.

    Returns
    -------
    CurrentModel
        The chosen model fitted on all runs, with ``selection_``: the record of the choice
        (:func:`greybox.identify.selection.selection_record`).

    Raises
    ------
    GreyboxError
        For a malformed candidate, too few samples to hold any out, or no candidate that could be scored.
    """
    if not candidates:
        raise GreyboxError("no candidate models to choose from")
    if len(set(candidates)) != len(candidates):
        raise GreyboxError("a candidate is named twice")
    notes = []
    if inertia is None:
        share = spring_share(runs)
        if share >= SPRING_SHARE_LIMIT:
            inertia = 0.0
            notes.append(f"inertia refused: one law a = -c x explains {100 * share:.1f} % of the runs' acceleration, "
                         "so an inertia cannot be told from a spring force (nor by held-out runs of the same kind); "
                         "every candidate was fitted with J = 0 (give the drive's inertia with --inertia J if the "
                         "effort is a motor's)")
    models = [(spec, build_candidate(spec, inertia=inertia)) for spec in candidates]
    folds = held_out_folds(runs, groups, n_blocks=n_blocks)
    scores = score_candidates(_screened(models), folds, workers=workers, progress=progress)
    labels = [score.label for score in scores]
    gap_tried = [spec for spec in gap_candidates if spec not in labels]
    if gap_tried and all(spec in labels for spec in GAP_EVIDENCE):
        without, behind = (scores[labels.index(spec)] for spec in GAP_EVIDENCE)
        shown = gap_shown(without, behind, lead_fold(folds))
        if shown is not None:
            notes.append(f"a gap: {GAP_EVIDENCE[1]} predicts the held-out runs better than {GAP_EVIDENCE[0]} "
                         f"(RE {shown[1]:.2f} against {shown[0]:.2f} %{shown[2]}), so {', '.join(gap_tried)} were "
                         "tried too")
            extra = [(spec, build_candidate(spec, inertia=inertia)) for spec in gap_tried]
            models += extra
            scores += score_candidates(_screened(extra), folds, workers=workers, progress=progress, rivals=scores)
    notes += [f"{score.label} disqualified: {score.error}" for score in scores
              if score.error is not None and score.fold_re]
    speed = speed_fold(folds)
    chosen = choose(scores, speed)
    if speed is not None:
        trained, held = folds[speed].speeds()
        notes.append(f"{folds[speed].name} holds out runs faster than those it trains on (99th percentile of |v| "
                     f"{held:.4g} against {trained:.4g}): a candidate predicting it worse than the simplest one by "
                     "more than that one's standard error was not chosen")
    model = models[chosen][1].fit(list(runs))
    model.selection_ = selection_record(scores, folds, chosen, notes)
    return model
