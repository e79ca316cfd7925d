"""The discrepancy workflow: fit a base model, find what it misses, add it, measure the gain.

:func:`discover` runs

1. the base model's own fit on the training runs;
2. up to ``max_effects`` steps: score the library effects against the
   present model's residual with a null-calibrated test
   (:func:`greybox.discover.evidence.score_step`); add the winning effect to
   an :class:`~greybox.models.augmented.AugmentedModel` and refit it jointly;
   stop when nothing passes. A term whose joint refit explains no more than
   chance (the base's own refit absorbed it) is dropped and not tried again;
3. the gap on the test runs: the base model alone against the augmented
   model (RMSE, RE and per regime), and the residual by regime before and after.

Before any effect is named, the base model is *refined* (``refine_base``): a
flexible friction curve along the speed, and the friction held at rest with
pre-sliding transients (:data:`greybox.models.effects.REFINEMENTS`), join its
linear columns in every test, so that a base whose friction law is only
approximately right (another Stribeck curve, another pre-sliding shape) does
not make effects look missing; velocity-only effects (``stribeck``,
``viscous_friction``) are then not candidates. Each refinement that lowers the
error on held-out blocks of the training runs is kept in the model and
reported as *base misfit*. Every winner of a step must also pass the held-out
test (:mod:`greybox.discover.heldout`): fitted on four fifths of the training
time, it must lower the error on the fifth, beyond a margin calibrated for
its flexibility; a periodic one must also carry over from one direction of
travel to the other.

Verdicts: ``"named"`` (at least one effect added), ``"base_misfit"`` (nothing
named, but the base model's own law is what misfits: a refinement
lowers the held-out error, or the structure left lies along the velocity or
the time since the motion changed only, or does not hold on held-out blocks),
``"unexplained_structure"`` (nothing from the library passes, but structure
along the position or the acceleration remains that also holds on held-out
blocks beyond the margin: the model misses something
the library does not name) and ``"nothing_missing"``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import Callable, Mapping, Sequence

import numpy as np
from sklearn.base import clone

from ..data.log import AxisLog, split_runs
from ..data.quantities import MOTIONS
from ..errors import GreyboxError
from ..evaluate.regimes import RegimeThresholds, metrics_by_regime
from ..json_values import jsonable
from ..metrics import metrics_table
from ..models.augmented import AugmentedModel
from ..models.effects import EFFECT_NAMES, REFINEMENTS, VELOCITY_ONLY, effect
from ..models.estimator import check_runs
from ..provenance import provenance
from ..train.logs import read_training_logs
from ..train.record import record_training
from .evidence import StepEvidence, score_step
from .heldout import DEFAULT_BLOCKS, DEFAULT_MIN_GAIN, HeldOutTest
from .locate import residual_by_regime, residual_profiles, structure_basis

__all__ = ["VERDICTS", "DiscoveryResult", "discover"]

#: Possible verdicts.
VERDICTS = ("named", "base_misfit", "nothing_missing", "unexplained_structure")

#: Structure families outside what the base model's physics (friction along the velocity and the motion's
#: history, inertia linear in the acceleration) can express, and that blocks of time can test (bins of the
#: time since the start cannot be fitted on one stretch of time and checked on another): structure along
#: them that holds on held-out blocks is unexplained.
_FOREIGN_FAMILIES = ("position_direction", "acceleration")


@dataclass
class DiscoveryResult:
    """What :func:`discover` found.

    Attributes
    ----------
    verdict : str
        One of :data:`VERDICTS`.
    effects : list of dict
        Named effects in the order they were added: ``name``, ``parameters``
        (physical values, names ending in their unit) and ``evidence``.
    base_model : CurrentModel
        The base model fitted alone on the training runs.
    model : AugmentedModel
        The base plus the named effects, refitted jointly.
    steps : list of StepEvidence
        The evidence of every step (the last one found nothing more, or hit ``max_effects``).
    rejected : list of dict
        Winners dropped because their joint refit explained no more than chance
        or because they failed the held-out test (``reason``).
    base_misfit : dict or None
        The base refinements (None without ``refine_base``): ``detected``
        and per refinement (``refinements``, by name) whether it was
        ``kept``, its ``held_out`` evidence and, when kept, its
        ``parameters``; and the held-out evidence of the structure families
        (``structure``) when structure remains.
    train, test : dict
        Metrics before (base alone) and after (augmented) on the training and
        test runs: ``rmse``/``re`` before and after, per-regime metrics and the
        residual by regime (:func:`greybox.discover.locate.residual_by_regime`).
    settings : dict
        Settings of the run.
    seconds : float
        Wall time of the workflow [s].
    unit : str
        Effort unit, "A", "N" or "Nm".
    motion : str
        Kind of axis of the runs, "linear" or "rotary": lengths are in mm or deg (names of effect
        parameters keep their ``_mm`` in the document; ``length_unit`` tells the unit).
    residuals : dict
        ``"train"`` and ``"test"``: ``time`` [s, running on across runs],
        residual ``before`` and ``after`` and their binned
        :func:`~greybox.discover.locate.residual_profiles`, for plots.
    """

    verdict: str
    effects: list
    base_model: object
    model: AugmentedModel
    steps: list
    rejected: list
    train: dict
    test: dict
    settings: dict
    seconds: float
    unit: str = "A"
    motion: str = "linear"
    base_misfit: dict | None = None
    residuals: dict = field(default_factory=dict, repr=False)

    @property
    def units(self):
        """Units of the runs' axis (:class:`greybox.data.quantities.Motion`)."""
        return MOTIONS[self.motion]

    def to_dict(self) -> dict:
        """The JSON document of ``greybox discover --json``."""
        last = self.steps[-1]
        return {
            "verdict": self.verdict,
            "effects": self.effects,
            "effort_unit": self.unit,
            "motion": self.motion,
            "length_unit": MOTIONS[self.motion].length,
            "test_rmse_before": self.test.get("rmse_before"),
            "test_rmse_after": self.test.get("rmse_after"),
            "test_re_before": self.test.get("re_before"),
            "test_re_after": self.test.get("re_after"),
            "train_rmse_before": self.train["rmse_before"],
            "train_rmse_after": self.train["rmse_after"],
            "remaining_structure": {"passes": last.structure.passes, "p_value": last.structure.p_value,
                                    "explained_fraction": last.structure.explained_fraction,
                                    "families": last.families},
            "more_effects_pass": bool(last.winner is not None),
            "base_misfit": self.base_misfit,
            "rejected": self.rejected,
            "train": self.train,
            "test": self.test,
            "steps": [step.to_dict() for step in self.steps],
            "model": {"base": type(self.base_model).__name__, "effects": self.model.effects_},
            "settings": self.settings,
            "seconds": self.seconds,
            "provenance": provenance(),
            "notes": {"re": "RE = RMSE / mean |effort| in %",
                      "before": "base model alone, fitted on the training logs",
                      "after": "base model plus the named effects, refitted jointly on the training logs"},
        }


def _rss(model, runs, target) -> float:
    residual = target - model.predict(runs)
    return float(residual @ residual)


def _residuals(runs, before, after) -> dict:
    """Residuals before and after, their profiles and a time axis running on across the runs [s]."""
    measured = np.concatenate([run.effort for run in runs])
    offsets = np.cumsum([0.0] + [run.time[-1] - run.time[0] + run.sample_time for run in runs[:-1]])
    time = np.concatenate([run.time - run.time[0] + offset for run, offset in zip(runs, offsets)])
    thresholds = RegimeThresholds.from_logs(runs)
    return {"time": time, "before": measured - before, "after": measured - after,
            "profiles_before": residual_profiles(runs, measured - before, thresholds),
            "profiles_after": residual_profiles(runs, measured - after, thresholds)}


def _gap(runs, before, after) -> dict:
    thresholds = RegimeThresholds.from_logs(runs)
    measured = np.concatenate([run.effort for run in runs])
    table_before, table_after = metrics_table(measured, before), metrics_table(measured, after)
    regimes_before = metrics_by_regime(runs, before, thresholds)
    regimes_after = metrics_by_regime(runs, after, thresholds)
    return {
        "rmse_before": table_before["rmse"], "rmse_after": table_after["rmse"],
        "re_before": table_before["re"], "re_after": table_after["re"],
        "relerr_before": table_before["relerr"], "relerr_after": table_after["relerr"],
        "n_samples": int(measured.size),
        "regimes": {name: {"n": regimes_before[name]["n"], "rmse_before": regimes_before[name]["rmse"],
                           "rmse_after": regimes_after[name]["rmse"]} for name in regimes_before},
        "residual_before": residual_by_regime(runs, measured - before, thresholds),
        "residual_after": residual_by_regime(runs, measured - after, thresholds),
    }


def _evidence_entry(step_index: int, step: StepEvidence, name: str, gain: float, held_out) -> dict:
    score = step.candidates[name]
    entry = {"step": step_index + 1, **score.to_dict(), "refit_explained_fraction": gain,
             "held_out": held_out.to_dict(), "indistinguishable_from": list(step.indistinguishable),
             "comparisons": step.comparisons}
    return entry


def _scoring_part(model: AugmentedModel, runs, refine_base: bool):
    """The model's linear part, with the columns of the refinements not in it added when refining."""
    part = model.linear_part(runs)
    if not refine_base:
        return part
    kept = {entry["name"] for entry in model.effects_}
    for name in REFINEMENTS:
        if name in kept:
            continue
        columns = np.concatenate([effect(name).columns(run, model.context) for run in runs])
        part = replace(part, columns=np.hstack((part.columns, columns)),
                       names=part.names + tuple(f"{name}.{column}" for column in effect(name).column_names),
                       lower=np.concatenate((part.lower, np.full(columns.shape[1], -np.inf))),
                       upper=np.concatenate((part.upper, np.full(columns.shape[1], np.inf))))
    return part


def _refine(model, base, base_model, train, target, settings, rng, refit_base, say, fit_progress):
    """Test each base refinement on held-out blocks in turn; keep those that pass. Returns ``(model, misfit)``."""
    misfit, kept = {"detected": False, "refinements": {}}, []
    for name in REFINEMENTS:
        held_out = _held_out(train, model.linear_part(train), target, model.context, settings, rng).evaluate(
            effect(name))
        entry = {"kept": held_out.passes, "held_out": held_out.to_dict(), "parameters": None}
        say(f"base refinement {name} ({effect(name).summary}): held-out gain {100 * held_out.gain:.2f} +- "
            f"{100 * held_out.uncertainty:.2f} % " + ("(kept: base misfit)" if held_out.passes else "(not kept)"))
        if held_out.passes:
            kept.append((name, None))
            model = AugmentedModel(base=base, effects=kept, refit_base=refit_base).fit_terms(
                train, base=base_model, progress=fit_progress)
            entry["parameters"] = model.effects_[-1]["parameters"]
        misfit["refinements"][name] = entry
    misfit["detected"] = bool(kept)
    return model, misfit


def _held_out(runs, part, target, context, settings, rng) -> HeldOutTest:
    return HeldOutTest(runs, part.columns, target - part.fixed, context, n_blocks=settings["held_out_blocks"],
                       min_gain=settings["min_gain"], rng=rng)


def discover(base, train: AxisLog | Sequence[AxisLog], test: AxisLog | Sequence[AxisLog] | None = None, *,
             candidates: Sequence[str] = EFFECT_NAMES, max_effects: int = 3, alpha: float = 0.05,
             n_null: int = 99, seed: int = 0, refit_base: bool = True, refine_base: bool = True,
             held_out_blocks: int = DEFAULT_BLOCKS, min_gain: float = DEFAULT_MIN_GAIN,
             progress: Callable[[str], None] | None = None, fit_progress=None,
             read: Mapping | None = None) -> DiscoveryResult:
    """Find the effects a base model misses, add them, and measure the gap before and after.

    Parameters
    ----------
    base : CurrentModel
        Unfitted base model (e.g. ``GMSModel()``; cloned before fitting).
    train : AxisLog or list of AxisLog
        Prepared training runs.
    test : AxisLog or list of AxisLog, optional
        Prepared test runs, for the gap before and after (never used to decide anything).
    candidates : sequence of str, default all library effects
        Effects to consider.
    max_effects : int, default 3
        Most effects to add.
    alpha : float, default 0.05
        Level of each step's family-wise test: on data with nothing missing,
        the chance of naming anything is at most ``alpha``.
    n_null : int, default 99
        Null replicates per step.
    seed : int, default 0
        Seed of the null replicates.
    refit_base : bool, default True
        Identify the base's nonlinear shape again with every added effect
        (see :class:`AugmentedModel`).
    refine_base : bool, default True
        Refine the base with a flexible friction curve along the speed and
        pre-sliding hysteresis states before naming anything (module notes);
        velocity-only library effects are then not candidates (the curve spans them).
    held_out_blocks : int, default 5
        Contiguous blocks of training time for the held-out test (at least 2).
    min_gain : float, default 0.02
        Smallest held-out gain worth a name: fraction of the held-out
        residual's sum of squares a term must remove (in [0, 1)).
    progress : callable, optional
        Receives one line of text per stage.
    fit_progress : None, bool or callable, optional
        Progress of the base model's identifications (see ``CurrentModel.fit``).
    read : mapping, optional
        Options the runs were read and prepared with (:func:`greybox.data.reading.read_prepared`), for the
        training record the returned model keeps (:func:`greybox.train.record_training`).

    Returns
    -------
    DiscoveryResult
    """
    started = time.perf_counter()
    say = progress or (lambda text: None)
    train = check_runs(train)
    test = check_runs(test) if test is not None else []
    if test and test[0].effort_unit != train[0].effort_unit:
        raise GreyboxError(f"training logs carry effort in {train[0].effort_unit}, test logs in "
                           f"{test[0].effort_unit}")
    names = [effect(name).name for name in candidates]
    if not isinstance(max_effects, int) or max_effects < 0:
        raise GreyboxError(f"max_effects must be a non-negative integer, got {max_effects!r}")
    if not 0.0 < alpha < 1.0 or n_null < 1 or int(np.floor(alpha * (n_null + 1))) < 1:
        raise GreyboxError(f"alpha = {alpha} with {n_null} null replicates can never pass: "
                           "use at least 1 / alpha - 1 replicates")
    if not (isinstance(min_gain, (int, float)) and 0.0 <= min_gain < 1.0):
        raise GreyboxError(f"min_gain must be a fraction in [0, 1), got {min_gain!r}")
    held_out_settings = {"held_out_blocks": held_out_blocks, "min_gain": float(min_gain)}
    rng = np.random.default_rng(seed)
    n_samples = sum(len(run) for run in train)
    say(f"fitting the base model {type(base).__name__} on {len(train)} run(s), {n_samples} samples")
    base_model = clone(base).fit(train, progress=fit_progress)
    model = AugmentedModel(base=base, refit_base=refit_base).fit_terms(train, base=base_model)
    target = np.concatenate([run.effort for run in train])
    base_misfit = None
    if refine_base:
        names = [name for name in names if name not in VELOCITY_ONLY]
        model, base_misfit = _refine(model, base, base_model, train, target, held_out_settings, rng, refit_base,
                                     say, fit_progress)
    rss = _rss(model, train, target)
    named, steps, rejected = [], [], []
    remaining = list(names)
    while True:
        say(f"step {len(steps) + 1}: scoring {len(remaining)} effects against {n_null} null replicates")
        periods = {}
        for entry in model.effects_:
            if effect(entry["name"]).shape is not None and effect(entry["name"]).shape.scale == "frequency":
                periods.setdefault(entry["name"], []).append(entry["shape"])
        part = _scoring_part(model, train, refine_base)
        carried = model.with_base_friction(train)
        step = score_step(carried, part, model.context, remaining, rng=rng, n_null=n_null,
                          alpha=alpha, excluded_periods=periods)
        steps.append(step)
        if step.winner is None:
            say("  nothing passes" + (" (structure remains that no library effect explains)"
                                      if step.structure.passes else ""))
            break
        if len(named) == max_effects:
            say(f"  {step.winner} also passes, but {max_effects} effects were added already")
            break
        winner = step.candidates[step.winner]
        held_out = _held_out(carried, part, target, model.context, held_out_settings, rng).evaluate(
            effect(winner.name), winner.shape, excluded_periods=periods.get(winner.name, ()))
        if not held_out.passes:
            say(f"  {winner.name} passes the null test (explains {100 * winner.explained_fraction:.2f} %) but not "
                f"the held-out test: {'; '.join(held_out.reasons)}")
            rejected.append({"name": winner.name, "step": len(steps), "reason": "held_out",
                             "explained_fraction": winner.explained_fraction, "held_out": held_out.to_dict()})
            remaining.remove(winner.name)
            continue
        pairs = [(e["name"], e["shape"]) for e in model.effects_] + [(winner.name, winner.shape)]
        say(f"  {winner.name} passes (explains {100 * winner.explained_fraction:.2f} % of the residual, "
            f"p = {winner.p_value:.3f}; held-out gain {100 * held_out.gain:.2f} +- {100 * held_out.uncertainty:.2f} "
            f"%); refitting jointly")
        trial = AugmentedModel(base=base, effects=pairs, refit_base=refit_base).fit_terms(
            train, base=base_model, progress=fit_progress)
        trial_rss = _rss(trial, train, target)
        gain = (rss - trial_rss) / rss
        if not gain > winner.null_q95:
            say(f"  {winner.name} dropped: the joint refit explains {100 * gain:.3f} % only")
            rejected.append({"name": winner.name, "step": len(steps), "reason": "refit",
                             "refit_explained_fraction": gain, "null_q95": winner.null_q95})
            remaining.remove(winner.name)
            continue
        model, rss = trial, trial_rss
        entry = model.effects_[-1]
        named.append({"name": entry["name"], "parameters": entry["parameters"],
                      "evidence": _evidence_entry(len(steps) - 1, step, winner.name, gain, held_out)})
        if effect(winner.name).shape is None or effect(winner.name).shape.scale != "frequency":
            remaining.remove(winner.name)
    verdict = "named" if named else None
    if steps[-1].structure.passes and not named:
        part = _scoring_part(model, train, refine_base)
        families = structure_basis(train)
        tester = _held_out(train, part, target, model.context, held_out_settings, rng)
        foreign = {name: tester.evaluate(None, columns=families[name].toarray())
                   for name in _FOREIGN_FAMILIES if name in families}
        base_misfit = base_misfit or {"detected": False, "refinements": {}}
        base_misfit["structure"] = {name: value.to_dict() for name, value in foreign.items()}
        if any(value.passes for value in foreign.values()):
            verdict = "unexplained_structure"
        else:
            base_misfit["detected"] = True
    if verdict is None:
        verdict = "base_misfit" if base_misfit and base_misfit["detected"] else "nothing_missing"
    say(f"verdict: {verdict}" + (": " + ", ".join(e["name"] for e in named) if named else ""))

    fitted = model.predict(train)
    train_gap, residuals = _gap(train, base_model.predict(train), fitted), {}
    residuals["train"] = _residuals(train, base_model.predict(train), fitted)
    _, run_labels, files = read_training_logs(train)
    record_training(model, train, split_runs(train, fitted), names=run_labels, files=files, read=read)
    test_gap = {}
    if test:
        before, after = base_model.predict(test), model.predict(test)
        test_gap = _gap(test, before, after)
        residuals["test"] = _residuals(test, before, after)
    settings = {"base": type(base).__name__, "base_params": jsonable(base.get_params(deep=False), other=repr),
                "candidates": names, "max_effects": max_effects, "alpha": alpha, "n_null": n_null, "seed": seed,
                "refit_base": refit_base, "refine_base": refine_base, **held_out_settings,
                "train_samples": n_samples, "test_samples": int(sum(len(run) for run in test))}
    return DiscoveryResult(verdict=verdict, effects=named, base_model=base_model, model=model, steps=steps,
                           rejected=rejected, train=train_gap, test=test_gap, settings=settings,
                           seconds=time.perf_counter() - started, unit=train[0].effort_unit,
                           motion=train[0].motion, residuals=residuals, base_misfit=base_misfit)


