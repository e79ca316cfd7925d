"""Validation of the discovery workflow on axes it was not developed on: the hysteresis family.

The axes come from :mod:`studies.hysteresis_axis`, a simulator written
apart from greybox's friction models and its synthetic twin: a Bouc-Wen
hysteresis with Stribeck weakening, its own trajectories and noise, and its
own implementation of every hidden effect. No library column is the hidden
current, and the base model (GMS by default) fits the friction law only
approximately, so every residual holds deterministic misfit: the normal case on
a real drive.

A case draws an axis from its seed, hides one effect (or none: a *null* axis)
at a given RMS relative to the noise, trains on two logs and tests on two
others (four independent trajectories). It is scored against an *oracle*: the
base model fitted to the training effort minus the true hidden current, and
predicting the test effort with the true hidden current added. Gap closure =
(test RMSE before - after) / (before - oracle). The base refinements of the
workflow (:data:`greybox.models.effects.REFINEMENTS`) fix part of the base's
own misfit, which the oracle does not, so this closure can exceed 1 without the
effect being found well; the *effect closure* compares like with like: before
= the base with the refinements the workflow kept, oracle = the same fitted to
the training effort minus the true hidden current, plus that current.

On a null axis the verdicts ``nothing_missing`` and ``base_misfit`` are right;
``named`` and ``unexplained_structure`` are false. On an effect axis a named
effect other than the hidden one is *spurious*.
"""

from __future__ import annotations

import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict

import numpy as np
from sklearn.base import clone

from greybox.atomic import write_text_atomic
from greybox.data.prepare import prepare
from greybox.discover.report import write_json
from greybox.discover.workflow import discover
from greybox.metrics import rmse
from greybox.models.augmented import AugmentedModel
from greybox.models.effects import REFINEMENTS
from greybox.models.friction import GMSModel
from studies.discovery import wilson_interval
from studies.hysteresis_axis import HIDDEN_EFFECTS, FamilyCase, family_logs

__all__ = ["ACCEPTED_NULL_VERDICTS", "PERIOD_TOLERANCE", "run_family_case", "summarise_family", "family_markdown",
           "run_family_study"]

#: Verdicts that are right on a null axis.
ACCEPTED_NULL_VERDICTS = ("nothing_missing", "base_misfit")
#: A named period within this relative distance of the true one counts as right.
PERIOD_TOLERANCE = 0.05


def _matches(case: FamilyCase, entry: dict, info: dict) -> bool:
    if entry["name"] != case.effect:
        return False
    period = entry["parameters"].get("period_mm")
    if period is None:
        return True
    return abs(period / info["effect_parameters"]["period_mm"] - 1.0) <= PERIOD_TOLERANCE


def run_family_case(case: FamilyCase, *, base=None, n_null: int = 99) -> dict:
    """Run the workflow on one case of the family and score it against the oracle.

    Parameters
    ----------
    case : FamilyCase
        Hidden effect (None: null axis), RMS ratio, seed and log length.
    base : CurrentModel, optional
        Unfitted base model (``GMSModel()`` by default).
    n_null : int, default 99
        Null replicates per step.

    Returns
    -------
    dict
        The case, ``verdict``, ``named``, ``base_misfit`` (detected),
        ``correct`` (the hidden effect named, a period within 5 %),
        ``first_correct``, ``spurious`` (named effects not hidden),
        ``false_positive`` (null axes: a verdict other than
        :data:`ACCEPTED_NULL_VERDICTS`), the test RMSE before, after and of
        the oracle [A], ``closure``, ``closure_effect`` (given the refinements
        kept) with ``rmse_oracle_refined``, each named effect's held-out gain, and ``seconds``.
    """
    started = time.perf_counter()
    base = GMSModel() if base is None else base
    train_raw, test_raw, info = family_logs(case)
    train, test = prepare(train_raw), prepare(test_raw)
    result = discover(base, train, test, n_null=n_null, seed=case.seed)
    named = [entry["name"] for entry in result.effects]
    row = {**asdict(case), "achieved_ratio": info["ratio_achieved"], "noise_rms_A": info["noise_rms_A"],
           "verdict": result.verdict, "named": named,
           "parameters": [entry["parameters"] for entry in result.effects],
           "held_out_gain": [entry["evidence"]["held_out"]["gain"] for entry in result.effects],
           "indistinguishable": [entry["evidence"]["indistinguishable_from"] for entry in result.effects],
           "base_misfit": bool(result.base_misfit and result.base_misfit["detected"]),
           "rejected": [entry["name"] for entry in result.rejected],
           "rmse_before": result.test["rmse_before"], "rmse_after": result.test["rmse_after"]}
    row["correct"] = case.effect is not None and any(_matches(case, e, info) for e in result.effects)
    row["first_correct"] = bool(result.effects) and case.effect is not None and _matches(case, result.effects[0],
                                                                                           info)
    row["spurious"] = [name for name in named if name != case.effect]
    row["false_positive"] = case.effect is None and result.verdict not in ACCEPTED_NULL_VERDICTS
    row["rmse_oracle"] = row["closure"] = row["closure_effect"] = None
    if case.effect is not None:
        row.update(_closures(base, result, train, test, info))
    row["seconds"] = time.perf_counter() - started
    return row


def _closures(base, result, train, test, info) -> dict:
    """Gap closures against the oracle: with the base alone, and given the base refinements kept."""
    measured = np.concatenate([run.effort for run in test])
    hidden_train, hidden_test = info["hidden_A"][:2], info["hidden_A"][2:]
    shifted = [run.replace(effort=run.effort - hidden) for run, hidden in zip(train, hidden_train)]
    oracle = clone(base).fit(shifted)
    after = result.test["rmse_after"]
    refinements = [(entry["name"], None) for entry in result.model.effects_ if entry["name"] in REFINEMENTS]
    refined_before, refined_oracle = result.base_model, oracle
    if refinements:
        refined_before = AugmentedModel(base=base, effects=refinements).fit_terms(train, base=result.base_model)
        refined_oracle = AugmentedModel(base=base, effects=refinements).fit_terms(shifted, base=oracle)
    out = {}
    for key, before_model, oracle_model in (("closure", result.base_model, oracle),
                                            ("closure_effect", refined_before, refined_oracle)):
        before = rmse(measured, np.concatenate([before_model.predict(run) for run in test]))
        best = rmse(measured, np.concatenate([oracle_model.predict(run) + hidden
                                              for run, hidden in zip(test, hidden_test)]))
        out["rmse_oracle" if key == "closure" else "rmse_oracle_refined"] = best
        out[key] = (before - after) / (before - best) if before - best > 0.01 * before else None
    return out


def _rate(count: int, n: int) -> dict:
    return {"count": count, "n": n, "rate": count / n if n else None, "interval_95": wilson_interval(count, n)}


def summarise_family(rows: list[dict], *, min_ratio: float = 0.5) -> dict:
    """The study's figures against the targets of docs/discover.md.

    Parameters
    ----------
    rows : list of dict
        Rows of :func:`run_family_case`, null and effect cases together.
    min_ratio : float, default 0.5
        Smallest hidden-effect RMS over noise RMS of the effect cases counted in ``first_correct`` and the closures.

    Returns
    -------
    dict
        ``null_right`` (share of null axes with an accepted verdict),
        ``spurious`` (share of all cases naming an effect that was not
        hidden), ``first_correct`` (share of effect cases at RMS ratio >=
        ``min_ratio`` naming the hidden effect first), ``closure`` and
        ``closure_effect`` (share of those cases with a closure >= 0.8, and the median) and
        ``by_effect`` (per effect and ratio: cases, named first, named, median closure).
    """
    nulls = [row for row in rows if row["effect"] is None]
    effects = [row for row in rows if row["effect"] is not None and row["ratio"] >= min_ratio]
    closures = [row["closure"] for row in effects if row["closure"] is not None]
    effect_closures = [row.get("closure_effect") for row in effects if row.get("closure_effect") is not None]
    by_effect = {}
    for row in rows:
        cell = by_effect.setdefault(str(row["effect"]), {}).setdefault(f"{row['ratio']:g}", [])
        cell.append(row)
    return {
        "null_right": _rate(sum(not row["false_positive"] for row in nulls), len(nulls)),
        "null_base_misfit": _rate(sum(row["verdict"] == "base_misfit" for row in nulls), len(nulls)),
        "spurious": _rate(sum(bool(row["spurious"]) for row in rows), len(rows)),
        "first_correct": _rate(sum(row["first_correct"] for row in effects), len(effects)),
        "closure": {**_rate(sum(c >= 0.8 for c in closures), len(effects)),
                    "median": float(np.median(closures)) if closures else None},
        "closure_effect": {**_rate(sum(c >= 0.8 for c in effect_closures), len(effects)),
                           "median": float(np.median(effect_closures)) if effect_closures else None},
        "min_ratio": min_ratio,
        "by_effect": {name: {ratio: {"n": len(cell), "first": sum(r["first_correct"] for r in cell),
                                     "named": sum(r["correct"] for r in cell),
                                     "verdicts": sorted({r["verdict"] for r in cell}),
                                     "median_closure": (float(np.median([r["closure"] for r in cell
                                                                         if r["closure"] is not None]))
                                                        if any(r["closure"] is not None for r in cell) else None),
                                     "median_effect_closure": (
                                         float(np.median([r["closure_effect"] for r in cell
                                                          if r.get("closure_effect") is not None]))
                                         if any(r.get("closure_effect") is not None for r in cell) else None),
                                     "spurious": sorted({name for r in cell for name in r["spurious"]})}
                             for ratio, cell in cells.items()}
                      for name, cells in by_effect.items()},
    }


def _percent(rate: dict) -> str:
    low, high = rate["interval_95"]
    return (f"{rate['count']}/{rate['n']} = {100 * rate['rate']:.1f} % (95 % CI {100 * low:.1f}-{100 * high:.1f} %)"
            if rate["n"] else "-")


def _median(rate: dict) -> str:
    return "-" if rate.get("median") is None else format(rate["median"], ".2f")


def _axis_table(rows: list[dict], seed: int, ratio: float) -> list[str]:
    """One axis, case by case: what was named and the test RMSE before and after, beside the noise."""
    lines = [f"Axis {seed}, case by case (hidden effect at {ratio:g} x the noise RMS):", "",
             "| hidden | verdict | named, in order | test RMSE before -> after (oracle) [A] | noise [A] |",
             "|---|---|---|---|---|"]
    for row in rows:
        if row["seed"] != seed or (row["effect"] is not None and row["ratio"] != ratio):
            continue
        oracle = "" if row["rmse_oracle"] is None else f" ({row['rmse_oracle']:.4f})"
        lines.append(f"| {row['effect'] or 'nothing'} | {row['verdict']} | {', '.join(row['named']) or '-'} | "
                     f"{row['rmse_before']:.4f} -> {row['rmse_after']:.4f}{oracle} | {row['noise_rms_A']:.4f} |")
    return lines


def family_markdown(settings: dict, summary: dict, seconds: float, rows: list[dict] | None = None) -> str:
    """The study's tables: figures against targets, per hidden effect and ratio, and (with ``rows``) the
    first axis case by case at the largest ratio.

    Parameters
    ----------
    settings : dict
        The study's settings as :func:`run_family_study` stores them (``seeds``, ``first_seed``, ``base``,
        ``duration``, ``n_cases``, ``workers``, ``ratios`` are read).
    summary : dict
        :func:`summarise_family` of the rows.
    seconds : float
        Wall time of the study [s].
    rows : list of dict, optional
        Rows of :func:`run_family_case`; given, the first axis's cases are tabulated one by one.
    """
    lines = [
        f"Hysteresis family ({settings['seeds']} axes, seeds {settings['first_seed']}-"
        f"{settings['first_seed'] + settings['seeds'] - 1}), base model {settings['base']}, two training and two "
        f"test logs of {settings['duration']:g} s each; {settings['n_cases']} workflow runs in {seconds / 60:.1f} min "
        f"on {settings['workers']} process(es).",
        "",
        "| figure | measured | target |",
        "|---|---|---|",
        f"| null axes: verdict nothing_missing or base_misfit | {_percent(summary['null_right'])} | >= 95 % |",
        f"| cases naming an effect that was not hidden | {_percent(summary['spurious'])} | <= 10 % |",
        f"| hidden effect named first, RMS >= {summary['min_ratio']:g} x noise | {_percent(summary['first_correct'])} "
        f"| >= 90 % |",
        f"| gap closure vs the true term >= 0.8, same cases | {_percent(summary['closure'])}; median "
        f"{'-' if summary['closure']['median'] is None else format(summary['closure']['median'], '.2f')} | >= 90 % |",
        f"| the same, given the base refinements kept | {_percent(summary['closure_effect'])}; median "
        f"{_median(summary['closure_effect'])} | >= 90 % |",
        "",
        "| hidden effect | RMS / noise | cases | named first | verdicts | median closure (effect closure) "
        "| spurious names |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, cells in summary["by_effect"].items():
        for ratio, cell in cells.items():
            closure = "-" if cell["median_closure"] is None else f"{cell['median_closure']:.2f}"
            if cell.get("median_effect_closure") is not None:
                closure += f" ({cell['median_effect_closure']:.2f})"
            lines.append(f"| {name if name != 'None' else 'none (null axis)'} | {ratio} | {cell['n']} | "
                         f"{cell['first']} | {', '.join(cell['verdicts'])} | {closure} | "
                         f"{', '.join(cell['spurious']) or '-'} |")
    if rows:
        lines += [""] + _axis_table(rows, settings["first_seed"], max(settings["ratios"]))
    return "\n".join(lines) + "\n"


def _run(arguments):
    case, n_null = arguments
    return run_family_case(case, n_null=n_null)


def run_family_study(json_path: str | os.PathLike, *, markdown_path=None, seeds: int = 4, first_seed: int = 0,
                     ratios=(0.5, 1.0), effects=HIDDEN_EFFECTS, null_seeds: int | None = None,
                     duration_s: float = 30.0, n_null: int = 99, workers: int = 1, progress=None) -> str:
    """Run the family study and write its files; the JSON is rewritten after every case.

    Parameters
    ----------
    json_path : path-like
        Settings, summary and every case.
    markdown_path : path-like, optional
        The tables (:func:`family_markdown`).
    seeds : int, default 4
        Axes (seeds ``first_seed ...``) per hidden effect and ratio.
    first_seed : int, default 0
        First seed.
    ratios : sequence of float, default (0.5, 1.0)
        Hidden-effect RMS over noise RMS.
    effects : sequence of str
        Hidden effects.
    null_seeds : int, optional
        Null axes (default: ``5 * seeds``, seeds from ``first_seed``).
    duration_s : float, default 30
        Length of every log [s].
    n_null : int, default 99
        Null replicates per step of the workflow.
    workers : int, default 1
        Processes running cases side by side.
    progress : callable, optional
        Receives one line per finished case.

    Returns
    -------
    str
        The tables (Markdown).
    """
    say = progress or (lambda line: None)
    null_seeds = 5 * seeds if null_seeds is None else null_seeds
    cases = [FamilyCase(None, 0.0, first_seed + s, duration_s) for s in range(null_seeds)]
    cases += [FamilyCase(name, ratio, first_seed + s, duration_s)
              for name in effects for ratio in ratios for s in range(seeds)]
    settings = {"base": "GMSModel", "seeds": seeds, "first_seed": first_seed, "ratios": list(ratios),
                "effects": list(effects), "null_seeds": null_seeds, "duration": duration_s, "n_null": n_null,
                "workers": workers, "n_cases": len(cases)}
    started, rows = time.perf_counter(), []

    def save():
        summary = summarise_family(rows)
        write_json({"settings": settings, "summary": summary, "cases": rows,
                    "seconds": time.perf_counter() - started}, json_path)
        return summary

    with ProcessPoolExecutor(max_workers=workers) as pool:
        for row in pool.map(_run, [(case, n_null) for case in cases]):
            rows.append(row)
            closure = "-" if row["closure"] is None else f"{row['closure']:.2f}"
            say(f"{row['effect']} x{row['ratio']:g} seed {row['seed']}: {row['verdict']} {row['named']} "
                f"first_correct={row['first_correct']} closure={closure} ({row['seconds']:.0f} s)")
            save()
    summary = save()
    text = family_markdown(settings, summary, time.perf_counter() - started, rows)
    if markdown_path:
        write_text_atomic(markdown_path, text)
    return text
