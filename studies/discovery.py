"""Validation of the discovery workflow on the synthetic axis: hidden effects, null data, gap closure.

A *case* hides one library effect, scaled so that its RMS current is a given
multiple of the noise RMS, in a training log (dataset A) and a test log
(dataset C) of the synthetic axis, runs :func:`~greybox.discover.workflow.discover`
and compares with an *oracle*: the base model plus the true term at its true
shape, fitted jointly. Two plants:

``"coulomb"``
    The effort is a Coulomb + viscous + inertia current plus the hidden
    effect, both computed from the logged motion (position, and velocity and
    acceleration as prepared), plus the twin's measurement noise: the base
    model class (Coulomb) is exactly right and the effects are exactly the
    twin's functions of the motion the models see, so any naming beyond the
    hidden effect is a false one.
``"twin"``
    The twin's own truth plant (24-element Maxwell-slip friction with lagged
    Stribeck curve, preload profile along the travel, lead ripple) plus the
    hidden effect. A base model may then legitimately find the plant's own
    structure (the lead ripple as ``position_periodic_friction``, say): such
    *background* effects are those named on the same log without a hidden
    effect, and they are not counted as false.

On the twin plant, its effects (:data:`greybox.twin.EFFECTS`) are hidden as
the twin computes them from the true motion; ``stribeck`` and
``load_dependent_friction``, which the twin does not have, are hidden as the
library's own terms. *Null* data are the base model fitted to a log without a
hidden effect, simulated on that log's motion, plus noise like its residual
(:class:`~greybox.discover.noise.ResidualNoise`): nothing is missing from
the model by construction, so any verdict but ``nothing_missing`` is a false
positive.

:func:`run_section` runs a whole section of the study (many cases, nulls and
the summary, or the workflow on the real EMPS benchmark) and writes its
files; ``scripts/discovery_study.py`` is its command (docs/discover.md).
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from sklearn.base import clone

from greybox.atomic import write_text_atomic
from greybox.data.io import read_log
from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.discover.noise import ResidualNoise
from greybox.discover.report import write_json
from greybox.discover.workflow import discover
from greybox.metrics import relerr, rmse
from greybox.models.augmented import AugmentedModel
from greybox.models.effects import EFFECT_NAMES, VELOCITY_ONLY, EffectContext, effect
from greybox.models.friction import CoulombModel, GMSModel
from greybox.twin import EFFECTS as TWIN_EFFECTS
from greybox.twin import CurrentNoise, EffectInputs, axis_geometry, default_plant_parameters, make_dataset
from greybox.twin import effect_current as twin_effect_current
from studies.emps import BORDER as EMPS_BORDER
from studies.emps import decimate_benchmark

__all__ = ["PLANTS", "TRUE_SHAPES", "wilson_interval", "HIDDEN_LIBRARY_TERMS", "ABSORBED", "SECTIONS", "StudyCase",
           "case_logs", "null_logs", "run_case", "run_null", "summarise", "benchmark_relerr", "emps_section",
           "markdown", "run_section"]

#: Plants a case may use.
PLANTS = ("coulomb", "twin")

#: Shape of every hidden effect that has one (the twin's defaults, and the hidden library terms').
TRUE_SHAPES = {"position_periodic_force": 2.5, "position_periodic_friction": 20.0, "thermal_drift": 60.0,
               "stribeck": 2.0}

#: Library effects the twin lacks, hidden as the library's own term (coefficient 1 A before scaling).
HIDDEN_LIBRARY_TERMS = ("stribeck", "load_dependent_friction")

#: Effects a base model with an inertia and a viscous coefficient absorbs: nothing is missing.
ABSORBED = ("inertia_mismatch", "viscous_friction")

#: A named period within this relative distance of the true one counts as right.
PERIOD_TOLERANCE = 0.05

_NOISE_STD_A = CurrentNoise().std_A


@dataclass(frozen=True)
class StudyCase:
    """One hidden effect at one strength on one seed.

    Parameters
    ----------
    effect : str or None
        Hidden effect (None: plain log).
    ratio : float
        RMS of the hidden current on the training log over the noise RMS (0.065 A).
    seed : int
        Seed of the logs (trajectories and noise).
    plant : {"coulomb", "twin"}
        See the module notes.
    duration_s : float
        Length of the training and test logs [s].
    """

    effect: str | None
    ratio: float
    seed: int
    plant: str = "coulomb"
    duration_s: float = 30.0


def _coulomb_current(run: AxisLog) -> np.ndarray:
    plant = default_plant_parameters("X")
    coulomb = plant.static_friction_A * plant.coulomb_ratio
    return plant.inertia_A_s2_mm * run.acceleration + coulomb * np.sign(run.velocity) \
        + plant.viscous_A_s_mm * run.velocity


def _library_current(name: str, run: AxisLog, context: EffectContext) -> np.ndarray:
    term = effect(name)
    return term.current(run, context, np.ones(term.n_columns), TRUE_SHAPES.get(name))


def case_logs(case: StudyCase) -> tuple[AxisLog, AxisLog, dict]:
    """Prepared training (dataset A) and test (dataset C) logs of a case, and what was hidden.

    Parameters
    ----------
    case : StudyCase
        Hidden effect, its strength, seed, plant and log length.

    Returns
    -------
    train, test : AxisLog
        Prepared logs; effort in A.
    info : dict
        ``strength`` (factor of the unit effect), ``effect_rms_A`` on the
        training log, ``noise_rms_A``.
    """
    if case.plant not in PLANTS:
        raise ValueError(f"unknown plant {case.plant!r}; choose from {PLANTS}")
    twin_effect = case.effect if case.effect in TWIN_EFFECTS else None
    raw = [make_dataset("X", dataset, case.seed, effect=twin_effect, effect_strength=1.0,
                        duration_s=case.duration_s) for dataset in ("A", "C")]
    runs = prepare(raw)
    context = EffectContext.from_runs(runs[:1])
    unit_effects = []
    for log, run in zip(raw, runs):
        if case.effect is None:
            unit_effects.append(np.zeros(len(run)))
        elif twin_effect is not None and case.plant == "twin":
            unit_effects.append(log.extras["truth_effect_A"])
        elif twin_effect is not None:
            inputs = EffectInputs(run.time - run.time[0], run.position, run.velocity, run.acceleration,
                                  axis_geometry("X").travel_mm)
            unit_effects.append(twin_effect_current(twin_effect, inputs, 1.0))
        else:
            unit_effects.append(_library_current(case.effect, run, context))
    unit_rms = float(np.sqrt(np.mean(unit_effects[0] ** 2)))
    strength = case.ratio * _NOISE_STD_A / unit_rms if case.effect is not None else 0.0
    out = []
    for log, run, unit in zip(raw, runs, unit_effects):
        if case.plant == "coulomb":
            effort = _coulomb_current(run) + log.extras["truth_noise_A"] + strength * unit
        else:
            injected = log.extras.get("truth_effect_A", 0.0)
            effort = log.effort - injected + strength * unit
        out.append(run.replace(effort=effort))
    info = {"strength": strength, "effect_rms_A": strength * unit_rms,
            "noise_rms_A": float(np.std(raw[0].extras["truth_noise_A"]))}
    return out[0], out[1], info


def null_logs(base, train: AxisLog, test: AxisLog, seed: int) -> tuple[AxisLog, AxisLog]:
    """Data with nothing missing: ``base`` fitted on ``train``, simulated on both logs' motion plus noise.

    The noise is :class:`ResidualNoise` fitted to the base's residual on the
    training log (AR with the residual's autocorrelation and local level),
    drawn independently for each log.

    Parameters
    ----------
    base : CurrentModel
        Unfitted base model (cloned before fitting).
    train : AxisLog
        Prepared training log; the base is fitted on it and its residual gives the noise.
    test : AxisLog
        Prepared test log; its noise has the training residual's RMS as a constant level.
    seed : int
        Seed of the noise draws.
    """
    model = clone(base).fit(train)
    rng = np.random.default_rng([seed, 7919])
    residual = train.effort - model.predict(train)
    noise = ResidualNoise.fit([residual], [train.sample_time])
    train_noise = noise.simulate(1, rng)[0][:, 0]
    test_noise = ResidualNoise(noise.ar, noise.innovation_std, (np.full(len(test), noise.describe()["rms"]),))
    return (train.replace(effort=model.predict(train) + train_noise),
            test.replace(effort=model.predict(test) + test_noise.simulate(1, rng)[0][:, 0]))


def _curve_kept(result) -> bool:
    """The base refinement found base misfit and kept its velocity curve."""
    return bool(result.base_misfit and result.base_misfit["refinements"]["velocity_curve"]["kept"])


def _correct(case: StudyCase, entry: dict) -> bool:
    if entry["name"] != case.effect:
        return False
    period = entry["parameters"].get("period_mm")
    return period is None or abs(period / TRUE_SHAPES[case.effect] - 1.0) <= PERIOD_TOLERANCE


def run_case(base, case: StudyCase, *, background: frozenset = frozenset(), n_null: int = 99,
             refit_base: bool = True) -> dict:
    """Run the workflow on one case and score it against the oracle.

    Parameters
    ----------
    base : CurrentModel
        Unfitted base model.
    case : StudyCase
        The case.
    background : frozenset of str
        Effects named on the same plant and seed without a hidden effect.
    n_null : int, default 99
        Null replicates per step.
    refit_base : bool, default True
        See :func:`discover`.

    Returns
    -------
    dict
        The case, ``verdict``, ``named`` (names), ``correct`` (the hidden
        effect is named, a period within 5 %), ``first_correct``,
        ``spurious`` (named effects neither hidden nor background),
        ``rmse_before``/``rmse_after``/``rmse_oracle`` on the test log [A],
        ``closure`` ((before - after) / (before - oracle), None when the
        oracle closes less than 1 % of the RMSE) and ``seconds``.
    """
    started = time.perf_counter()
    train, test, info = case_logs(case)
    result = discover(base, train, test, n_null=n_null, seed=case.seed, refit_base=refit_base)
    named = [entry["name"] for entry in result.effects]
    row = {"effect": case.effect, "ratio": case.ratio, "seed": case.seed, "plant": case.plant, **info,
           "verdict": result.verdict, "named": named,
           "parameters": [entry["parameters"] for entry in result.effects],
           "correct": any(_correct(case, entry) for entry in result.effects),
           "first_correct": bool(result.effects) and _correct(case, result.effects[0]),
           "base_misfit": bool(result.base_misfit and result.base_misfit["detected"]),
           "spurious": [name for name in named if name != case.effect and name not in background],
           "rmse_before": result.test["rmse_before"], "rmse_after": result.test["rmse_after"]}
    if case.effect in VELOCITY_ONLY and case.effect not in ABSORBED:  # the velocity curve spans it: base misfit
        row["correct"] = row["first_correct"] = _curve_kept(result)
    row["rmse_oracle"] = row["closure"] = None
    if case.effect is not None:
        oracle = AugmentedModel(base=base, effects=[(case.effect, TRUE_SHAPES.get(case.effect))],
                                refine_shapes=False, refit_base=refit_base).fit_terms(train, result.base_model)
        row["rmse_oracle"] = rmse(test.effort, oracle.predict(test))
        gain = row["rmse_before"] - row["rmse_oracle"]
        if gain > 0.01 * row["rmse_before"]:
            row["closure"] = (row["rmse_before"] - row["rmse_after"]) / gain
    row["seconds"] = time.perf_counter() - started
    return row


def run_null(base, seed: int, *, plant: str = "coulomb", duration_s: float = 30.0, n_null: int = 99,
             refit_base: bool = True) -> dict:
    """Run the workflow on null data (:func:`null_logs`) of a plain log; return its verdict and names.

    Parameters
    ----------
    base : CurrentModel
        Unfitted base model.
    seed : int
        Seed of the logs and of the null noise; the workflow runs with ``seed + 1000``.
    plant : {"coulomb", "twin"}, default "coulomb"
        Plant of the plain log (see the module notes).
    duration_s : float, default 30.0
        Length of the training and test logs [s].
    n_null : int, default 99
        Null replicates per step of the workflow.
    refit_base : bool, default True
        See :func:`discover`.
    """
    started = time.perf_counter()
    train, test, _ = case_logs(StudyCase(None, 0.0, seed, plant, duration_s))
    null_train, null_test = null_logs(base, train, test, seed)
    result = discover(base, null_train, null_test, n_null=n_null, seed=seed + 1000, refit_base=refit_base)
    return {"seed": seed, "plant": plant, "verdict": result.verdict,
            "named": [entry["name"] for entry in result.effects], "seconds": time.perf_counter() - started}


def wilson_interval(successes: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """95 % Wilson score interval of a proportion.

    Parameters
    ----------
    successes : int
        Number of successes.
    n : int
        Number of trials; 0 gives ``(nan, nan)``.
    z : float, default 1.96
        Quantile of the standard normal distribution; 1.96 gives the 95 % interval.
    """
    if n == 0:
        return float("nan"), float("nan")
    p = successes / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(float(centre - half), 0.0), min(float(centre + half), 1.0)


def summarise(cases: list[dict], nulls: list[dict], *, min_ratio: float = 0.5) -> dict:
    """The study's figures.

    Parameters
    ----------
    cases : list of dict
        Rows of :func:`run_case`.
    nulls : list of dict
        Rows of :func:`run_null`.
    min_ratio : float, default 0.5
        Smallest effect RMS over noise RMS of the cases counted in ``accuracy``, ``spurious_rate`` and ``closure``.

    Returns
    -------
    dict
        ``false_positive``: rate of verdicts other than ``nothing_missing``
        on null data with its 95 % interval; ``accuracy``: share of cases
        with a hidden, not absorbed effect of RMS ratio >= ``min_ratio`` in
        which it was named (and per effect); ``closure``: median and share
        >= 0.8 of the gap closure over the cases where the effect was named;
        ``by_effect_ratio``: accuracy per effect and ratio.
    """
    false = sum(row["verdict"] != "nothing_missing" for row in nulls)
    eligible = [row for row in cases if row["effect"] is not None and row["effect"] not in ABSORBED
                and row["ratio"] >= min_ratio]
    named = sum(row["correct"] for row in eligible)
    closures = [row["closure"] for row in eligible if row["correct"] and row["closure"] is not None]
    by_effect = {}
    for row in cases:
        if row["effect"] is None:
            continue
        cell = by_effect.setdefault(row["effect"], {}).setdefault(f"{row['ratio']:g}", [])
        cell.append(row)
    return {
        "false_positive": {"rate": false / len(nulls) if nulls else None, "n": len(nulls), "count": false,
                           "interval_95": wilson_interval(false, len(nulls))},
        "accuracy": {"rate": named / len(eligible) if eligible else None, "n": len(eligible), "count": named,
                     "interval_95": wilson_interval(named, len(eligible)), "min_ratio": min_ratio},
        "spurious_rate": (sum(bool(row["spurious"]) for row in eligible) / len(eligible)) if eligible else None,
        "closure": {"median": float(np.median(closures)) if closures else None, "n": len(closures),
                    "share_at_least_0.8": (float(np.mean(np.asarray(closures) >= 0.8)) if closures else None)},
        "by_effect_ratio": {name: {ratio: {"n": len(rows), "named": sum(r["correct"] for r in rows),
                                           "nothing_missing": sum(r["verdict"] == "nothing_missing" for r in rows),
                                           "median_closure": (float(np.median([r["closure"] for r in rows
                                                                               if r["closure"] is not None]))
                                                              if any(r["closure"] is not None for r in rows)
                                                              else None)}
                                   for ratio, rows in cells.items()}
                            for name, cells in by_effect.items()},
    }


# ---------------------------------------------------------------- the study's sections
#: Sections of the study and their default settings: the base model, log length [s], seeds per effect and
#: ratio, null data sets and effect RMS / noise RMS ratios. ``emps`` runs on the real EMPS benchmark.
SECTIONS = {
    "coulomb": {"base": CoulombModel, "duration": 30.0, "seeds": 5, "null_seeds": 1000,
                "ratios": (0.25, 0.5, 1.0, 2.0)},
    "twin": {"base": GMSModel, "duration": 60.0, "seeds": 2, "null_seeds": 40, "ratios": (0.5, 1.0, 2.0)},
    "emps": {},
}


def benchmark_relerr(runs, prediction) -> float:
    """relerr [%] on the EMPS benchmark's decimated samples of one run (:mod:`studies.emps`).

    Parameters
    ----------
    runs : sequence of AxisLog
        Exactly one prepared EMPS run, the measured force [N].
    prediction : ndarray, shape (n,)
        Modelled force over that run [N].
    """
    (run,) = runs
    measured = decimate_benchmark(run.effort[EMPS_BORDER:])
    modelled = decimate_benchmark(prediction[EMPS_BORDER:])
    return relerr(measured, modelled)


def emps_section(data: str | os.PathLike, json_path: str | os.PathLike, *, markdown_path=None,
                 progress=None) -> str:
    """Discovery on EMPS with a Coulomb and a GMS base; findings and errors before and after.

    Parameters
    ----------
    data : path-like
        Directory of ``DATA_EMPS.mat`` (training) and ``DATA_EMPS_PULSES.mat`` (test).
    json_path : path-like
        Every base's discovery document and benchmark errors.
    markdown_path : path-like, optional
        The table.
    progress : callable, optional
        Receives the workflow's progress lines, prefixed with the base.

    Returns
    -------
    str
        The table (Markdown).
    """
    say = progress or (lambda line: None)
    train = prepare([read_log(Path(data) / "DATA_EMPS.mat")])
    test = prepare([read_log(Path(data) / "DATA_EMPS_PULSES.mat")])
    report, lines = {}, ["| base | named (in order) | train relerr % (decimated) | test relerr % (decimated) "
                         "| test RMSE N (1 kHz) | test RMSE constant feed N | s |", "|---|---|---|---|---|---|---|"]
    bases = (("coulomb --offset", CoulombModel(fit_offset=True)), ("gms --offset", GMSModel(fit_offset=True)))
    for label, base in bases:
        result = discover(base, train, test, progress=lambda text, label=label: say(f"{label}: {text}"))
        before = {name: result.base_model.predict(runs) for name, runs in (("train", train), ("test", test))}
        after = {name: result.model.predict(runs) for name, runs in (("train", train), ("test", test))}
        figures = {f"{name}_relerr_{when}": benchmark_relerr(runs, values[name])
                   for name, runs in (("train", train), ("test", test))
                   for when, values in (("before", before), ("after", after))}
        feed = result.test["regimes"]["constant_feed"]
        report[label] = {"document": result.to_dict(), "benchmark": figures}
        named = "; ".join(f"{e['name']} ({', '.join(f'{k} {v:.4g}' for k, v in e['parameters'].items())})"
                          for e in result.effects) or "-"
        lines.append(f"| {label} | {named} "
                     f"| {figures['train_relerr_before']:.2f} -> {figures['train_relerr_after']:.2f} "
                     f"| {figures['test_relerr_before']:.2f} -> {figures['test_relerr_after']:.2f} "
                     f"| {result.test['rmse_before']:.3f} -> {result.test['rmse_after']:.3f} "
                     f"| {feed['rmse_before']:.3f} -> {feed['rmse_after']:.3f} | {result.seconds:.0f} |")
    text = "\n".join(lines) + "\n"
    write_json(report, json_path)
    if markdown_path:
        write_text_atomic(markdown_path, text)
    return text


def _fmt(value, spec=".2f") -> str:
    return "-" if value is None else format(value, spec)


def _percent(share) -> str:
    """A share as a percentage with one decimal; "-" when there is none (no runs of that kind)."""
    return "-" if share is None or not np.isfinite(share) else f"{100 * share:.1f}"


def markdown(section: str, settings: dict, summary: dict, cases: list, nulls: list, seconds: float) -> str:
    """The tables of a synthetic section: the study's figures against their targets, and per effect and ratio.

    Parameters
    ----------
    section : str
        Name of the section (a key of :data:`SECTIONS`).
    settings : dict
        The section's settings as :func:`run_section` stores them (``description``, ``base``, ``duration``,
        ``seeds``, ``null_seeds``, ``ratios``, optionally ``background``).
    summary : dict
        :func:`summarise` of ``cases`` and ``nulls``.
    cases : list of dict
        Rows of :func:`run_case`; only their number is shown.
    nulls : list of dict
        Rows of :func:`run_null`; only their number is shown.
    seconds : float
        Wall time of the section [s].
    """
    fp, acc, closure = summary["false_positive"], summary["accuracy"], summary["closure"]
    lines = [
        f"### Section `{section}`: {settings['description']}",
        "",
        f"Base model {settings['base']}, logs of {settings['duration']:g} s (train: dataset A, test: dataset C), "
        f"{settings['seeds']} seed(s) per cell, {settings['null_seeds']} null data sets; "
        f"{len(cases) + len(nulls)} workflow runs in {seconds / 60:.1f} min.",
        "",
        "| figure | measured | target |",
        "|---|---|---|",
        f"| false positives on null data (verdict other than nothing_missing) | {fp['count']}/{fp['n']} = "
        f"{_percent(fp['rate'])} % (95 % CI {_percent(fp['interval_95'][0])}-{_percent(fp['interval_95'][1])} %) "
        f"| <= 5 % |",
        f"| naming accuracy, effect RMS >= {acc['min_ratio']:g} x noise RMS (absorbed effects excluded) | "
        f"{acc['count']}/{acc['n']} = {_percent(acc['rate'])} % (95 % CI {_percent(acc['interval_95'][0])}-"
        f"{_percent(acc['interval_95'][1])} %) | >= 90 % |",
        f"| gap closure vs the true term, median over named cases | {_fmt(closure['median'], '.3f')} "
        f"({closure['n']} cases; {_fmt(100 * closure['share_at_least_0.8'] if closure['n'] else None, '.0f')} % "
        f"of them >= 0.8) | >= 0.8 |",
        f"| cases naming an effect neither hidden nor background | {_percent(summary['spurious_rate'])} % "
        f"| - |",
        "",
        "Named (hidden effect found, period within 5 %) / cases, and the median gap closure, per effect and "
        "effect RMS / noise RMS:",
        "",
        "| effect | " + " | ".join(f"{r:g}" for r in settings["ratios"]) + " |",
        "|---|" + "---|" * len(settings["ratios"]),
    ]
    for name, cells in summary["by_effect_ratio"].items():
        row = []
        for ratio in settings["ratios"]:
            cell = cells.get(f"{ratio:g}")
            if cell is None:
                row.append("-")
                continue
            text = f"{cell['named']}/{cell['n']}"
            if cell["median_closure"] is not None:
                text += f", closure {cell['median_closure']:.2f}"
            elif name in ABSORBED:
                text += f" ({cell['nothing_missing']} nothing_missing)"
            row.append(text)
        label = " (absorbed)" if name in ABSORBED else " (found as base misfit)" if name in VELOCITY_ONLY else ""
        lines.append(f"| {name}{label} | " + " | ".join(row) + " |")
    if settings.get("background"):
        lines += ["", "Background (named on the plain logs, the plant's own structure): "
                  + "; ".join(f"seed {seed}: {', '.join(names) or 'none'}"
                              for seed, names in settings["background"].items())]
    return "\n".join(lines) + "\n"


def run_section(section: str, json_path: str | os.PathLike, *, markdown_path=None, seeds: int | None = None,
                null_seeds: int | None = None, ratios=None, duration_s: float | None = None, effects=None,
                data: str | os.PathLike | None = None, progress=None) -> str:
    """Run one section of the study and write its files; the JSON is rewritten after every case.

    Parameters
    ----------
    section : {"coulomb", "twin", "emps"}
        See :data:`SECTIONS`; ``emps`` is :func:`emps_section`.
    json_path : path-like
        Settings, summary, cases and nulls (rewritten as the run goes, so that
        a long run can be followed and an interrupted one still holds its cases).
    markdown_path : path-like, optional
        The tables (:func:`markdown`).
    seeds, null_seeds : int, optional
        Seeds per effect and ratio, and null data sets; the section's defaults if None.
    ratios : sequence of float, optional
        Effect RMS over noise RMS.
    duration_s : float, optional
        Length of the training and test logs [s].
    effects : sequence of str, optional
        Hidden effects (default: the whole library).
    data : path-like, optional
        ``emps`` only: directory of the benchmark files.
    progress : callable, optional
        Receives one line of text per workflow run.

    Returns
    -------
    str
        The tables (Markdown).
    """
    say = progress or (lambda line: None)
    if section == "emps":
        return emps_section(data, json_path, markdown_path=markdown_path, progress=progress)
    defaults = SECTIONS[section]
    seeds = seeds if seeds is not None else defaults["seeds"]
    null_seeds = null_seeds if null_seeds is not None else defaults["null_seeds"]
    ratios = tuple(ratios) if ratios else defaults["ratios"]
    duration = duration_s or defaults["duration"]
    effects = tuple(effects) if effects else EFFECT_NAMES
    base = defaults["base"]()
    settings = {"section": section, "base": type(base).__name__, "duration": duration, "seeds": seeds,
                "null_seeds": null_seeds, "ratios": list(ratios), "effects": list(effects),
                "description": ("Coulomb plant, Coulomb base model: the base class is exactly right"
                                if section == "coulomb" else
                                "the twin's truth plant (Maxwell-slip, lagged Stribeck, preload profile, lead "
                                "ripple), GMS base model")}
    started = time.perf_counter()
    cases, nulls, background = [], [], {}

    def save():
        summary = summarise(cases, nulls)
        write_json({"settings": settings, "summary": summary, "cases": cases, "nulls": nulls,
                    "seconds": time.perf_counter() - started}, json_path)
        return summary

    if section == "twin":
        for seed in range(seeds):
            row = run_case(base, StudyCase(None, 0.0, seed, "twin", duration))
            background[str(seed)] = row["named"]
            say(f"background seed {seed}: {row['verdict']} {row['named']} ({row['seconds']:.0f} s)")
        settings["background"] = background
    for seed in range(null_seeds):
        row = run_null(base, seed, plant=section, duration_s=duration)
        nulls.append(row)
        say(f"null {seed}: {row['verdict']} {row['named']} ({row['seconds']:.1f} s)")
        if seed % 10 == 9:
            save()
    for name in effects:
        for ratio in ratios:
            for seed in range(seeds):
                case = StudyCase(name, ratio, seed, section, duration)
                row = run_case(base, case, background=frozenset(background.get(str(seed), ())))
                cases.append(row)
                closure = "-" if row["closure"] is None else f"{row['closure']:.3f}"
                say(f"{name} x{ratio:g} seed {seed}: {row['verdict']} {row['named']} correct={row['correct']} "
                    f"closure={closure} ({row['seconds']:.1f} s)")
                save()
    summary = save()
    text = markdown(section, settings, summary, cases, nulls, time.perf_counter() - started)
    if markdown_path:
        write_text_atomic(markdown_path, text)
    return text
