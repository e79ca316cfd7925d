"""The discrepancy workflow: fit a base model, find what it misses, add it, measure the gain.

:func:`discover` runs

1. the base model's own fit on the training runs;
2. up to ``max_effects`` steps: score the library effects against the
   present model's residual with a null-calibrated test
   (:func:`greybox.discover.evidence.score_step`); add the winning effect to
   an :class:`~greybox.discover.augment.AugmentedModel` and refit it jointly;
   stop when nothing passes. A term whose joint refit explains no more than
   chance (the base's own refit absorbed it) is dropped and not tried again;
3. the gap on the test runs: the base model alone against the augmented
   model (RMSE, RE and per regime), and the residual by regime before and after.

Verdicts: ``"named"`` (at least one effect added), ``"unexplained_structure"``
(nothing from the library passes, but the generic structure test does: the
model misses something the library does not name) and ``"nothing_missing"``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
from sklearn.base import clone

from ..data.log import AxisLog
from ..errors import GreyboxError
from ..estimator import check_runs
from ..evaluate.regimes import RegimeThresholds, metrics_by_regime
from ..metrics import metrics_table
from ..provenance import provenance
from .augment import AugmentedModel
from .effects import EFFECT_NAMES, effect
from .evidence import StepEvidence, score_step
from .locate import residual_by_regime, residual_profiles

__all__ = ["VERDICTS", "DiscoveryResult", "discover"]

#: Possible verdicts.
VERDICTS = ("named", "nothing_missing", "unexplained_structure")


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
        Winners dropped because their joint refit explained no more than chance.
    train, test : dict
        Metrics before (base alone) and after (augmented) on the training and
        test runs: ``rmse``/``re`` before and after, per-regime metrics and the
        residual by regime (:func:`greybox.discover.locate.residual_by_regime`).
    settings : dict
        Settings of the run.
    seconds : float
        Wall time of the workflow [s].
    unit : str
        Effort unit, "A" or "N".
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
    residuals: dict = field(default_factory=dict, repr=False)

    def to_dict(self) -> dict:
        """The JSON document of ``greybox discover --json``."""
        last = self.steps[-1]
        return {
            "verdict": self.verdict,
            "effects": self.effects,
            "effort_unit": self.unit,
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


def _evidence_entry(step_index: int, step: StepEvidence, name: str, gain: float) -> dict:
    score = step.candidates[name]
    entry = {"step": step_index + 1, **score.to_dict(), "refit_explained_fraction": gain,
             "indistinguishable_from": list(step.indistinguishable),
             "comparisons": step.comparisons}
    return entry


def discover(base, train: AxisLog | Sequence[AxisLog], test: AxisLog | Sequence[AxisLog] | None = None, *,
             candidates: Sequence[str] = EFFECT_NAMES, max_effects: int = 3, alpha: float = 0.05,
             n_null: int = 99, seed: int = 0, refit_base: bool = True,
             progress: Callable[[str], None] | None = None, fit_progress=None) -> DiscoveryResult:
    """Find the effects a base model misses, add them, and measure the gap before and after.

    Parameters
    ----------
    base : CurrentModel
        Unfitted base model (e.g. ``GMSModel()``; cloned before fitting).
    train : AxisLog or list of AxisLog
        Prepared training runs.
    test : AxisLog or list of AxisLog, optional
        Prepared test runs, for the gap before and after.
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
    progress : callable, optional
        Receives one line of text per stage.
    fit_progress : None, bool or callable, optional
        Progress of the base model's identifications (see ``CurrentModel.fit``).

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
    rng = np.random.default_rng(seed)
    n_samples = sum(len(run) for run in train)
    say(f"fitting the base model {type(base).__name__} on {len(train)} run(s), {n_samples} samples")
    base_model = clone(base).fit(train, progress=fit_progress)
    model = AugmentedModel(base=base, refit_base=refit_base).fit_terms(train, base=base_model)
    target = np.concatenate([run.effort for run in train])
    rss = _rss(model, train, target)
    named, steps, rejected = [], [], []
    remaining = list(names)
    while True:
        say(f"step {len(steps) + 1}: scoring {len(remaining)} effects against {n_null} null replicates")
        periods = {}
        for entry in model.effects_:
            if effect(entry["name"]).shape is not None and effect(entry["name"]).shape.scale == "frequency":
                periods.setdefault(entry["name"], []).append(entry["shape"])
        step = score_step(train, model.linear_part(train), model.context, remaining, rng=rng, n_null=n_null,
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
        pairs = [(e["name"], e["shape"]) for e in model.effects_] + [(winner.name, winner.shape)]
        say(f"  {winner.name} passes (explains {100 * winner.explained_fraction:.2f} % of the residual, "
            f"p = {winner.p_value:.3f}); refitting jointly")
        trial = AugmentedModel(base=base, effects=pairs, refit_base=refit_base).fit_terms(
            train, base=base_model, progress=fit_progress)
        trial_rss = _rss(trial, train, target)
        gain = (rss - trial_rss) / rss
        if not gain > winner.null_q95:
            say(f"  {winner.name} dropped: the joint refit explains {100 * gain:.3f} % only")
            rejected.append({"name": winner.name, "step": len(steps), "refit_explained_fraction": gain,
                             "null_q95": winner.null_q95})
            remaining.remove(winner.name)
            continue
        model, rss = trial, trial_rss
        entry = model.effects_[-1]
        named.append({"name": entry["name"], "parameters": entry["parameters"],
                      "evidence": _evidence_entry(len(steps) - 1, step, winner.name, gain)})
        if effect(winner.name).shape is None or effect(winner.name).shape.scale != "frequency":
            remaining.remove(winner.name)
    if named:
        verdict = "named"
    elif steps[-1].structure.passes:
        verdict = "unexplained_structure"
    else:
        verdict = "nothing_missing"
    say(f"verdict: {verdict}" + (": " + ", ".join(e["name"] for e in named) if named else ""))

    train_gap, residuals = _gap(train, base_model.predict(train), model.predict(train)), {}
    residuals["train"] = _residuals(train, base_model.predict(train), model.predict(train))
    test_gap = {}
    if test:
        before, after = base_model.predict(test), model.predict(test)
        test_gap = _gap(test, before, after)
        residuals["test"] = _residuals(test, before, after)
    settings = {"base": type(base).__name__, "base_params": {k: _jsonable(v) for k, v in
                                                             base.get_params(deep=False).items()},
                "candidates": names, "max_effects": max_effects, "alpha": alpha, "n_null": n_null, "seed": seed,
                "refit_base": refit_base, "train_samples": n_samples,
                "test_samples": int(sum(len(run) for run in test))}
    return DiscoveryResult(verdict=verdict, effects=named, base_model=base_model, model=model, steps=steps,
                           rejected=rejected, train=train_gap, test=test_gap, settings=settings,
                           seconds=time.perf_counter() - started, unit=train[0].effort_unit,
                           residuals=residuals)


def _jsonable(value):
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return repr(value)

