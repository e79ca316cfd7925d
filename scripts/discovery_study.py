"""Validation study of the discovery workflow on the synthetic axis (a benchmark; see docs/discover.md).

Hides every library effect at several strengths in synthetic logs, runs
``greybox.discover.workflow.discover`` on each, and reports the false-positive
rate on null data, the naming accuracy and the test-gap closure against the
true term (``greybox.discover.study``). Two sections:

``coulomb``  Coulomb plant (the base model class is exactly right), Coulomb base model.
``twin``     the twin's truth plant, GMS base model (the plant's own structure
             may be found too: counted as background, not as false).
``emps``     the real EMPS benchmark (``--data`` directory): base fitted on
             DATA_EMPS, tested on DATA_EMPS_PULSES, Coulomb and GMS bases (both
             with an offset); errors also on the benchmark's decimated samples.

Example (the figures of docs/discover.md)::

    python scripts/discovery_study.py --section coulomb --json coulomb.json --markdown coulomb.md
    python scripts/discovery_study.py --section twin --json twin.json --markdown twin.md
    python scripts/discovery_study.py --section emps --data ../shared/data/real/EMPS --json emps.json --markdown emps.md

The JSON is rewritten after every case, so a long run can be followed (and
an interrupted one still holds its cases).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from scipy.signal import decimate

from greybox.data.io import read_log
from greybox.data.prepare import prepare
from greybox.discover.effects import EFFECT_NAMES
from greybox.atomic import write_text_atomic
from greybox.discover.report import write_json
from greybox.discover.study import ABSORBED, StudyCase, run_case, run_null, summarise
from greybox.discover.workflow import discover
from greybox.metrics import relerr
from greybox.friction import CoulombModel, GMSModel

#: The EMPS benchmark's figure of merit: relerr on the force decimated by 10 (zero-phase IIR), after
#: dropping the first 49 samples (Janot et al. 2019, ``Script_IDIM_LS.m``).
EMPS_DECIMATION, EMPS_BORDER = 10, 49

SECTIONS = {
    "coulomb": {"base": CoulombModel, "duration": 30.0, "seeds": 5, "null_seeds": 1000,
                "ratios": (0.25, 0.5, 1.0, 2.0)},
    "twin": {"base": GMSModel, "duration": 60.0, "seeds": 2, "null_seeds": 40, "ratios": (0.5, 1.0, 2.0)},
    "emps": {},
}


def parse_args(argv=None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--section", required=True, choices=sorted(SECTIONS))
    parser.add_argument("--json", required=True, metavar="OUT", help="all cases and the summary")
    parser.add_argument("--markdown", metavar="MD", help="the tables")
    parser.add_argument("--seeds", type=int, help="seeds per effect and ratio")
    parser.add_argument("--null-seeds", type=int, help="null data sets")
    parser.add_argument("--ratios", help="effect RMS over noise RMS, comma-separated")
    parser.add_argument("--duration", type=float, help="length of the training and test logs [s]")
    parser.add_argument("--effects", help="comma-separated hidden effects (default: the whole library)")
    parser.add_argument("--data", metavar="DIR", help="emps: directory of DATA_EMPS.mat and DATA_EMPS_PULSES.mat")
    return parser.parse_args(argv)


def benchmark_relerr(runs, prediction) -> float:
    """relerr [%] on the EMPS benchmark's decimated samples of one run."""
    (run,) = runs
    measured = decimate(run.effort[EMPS_BORDER:], EMPS_DECIMATION, ftype="iir", zero_phase=True)
    modelled = decimate(prediction[EMPS_BORDER:], EMPS_DECIMATION, ftype="iir", zero_phase=True)
    return relerr(measured, modelled)


def emps_section(args) -> int:
    """Discovery on EMPS with a Coulomb and a GMS base; findings and errors before and after."""
    if not args.data:
        raise SystemExit("--section emps needs --data DIR")
    train = prepare([read_log(Path(args.data) / "DATA_EMPS.mat")])
    test = prepare([read_log(Path(args.data) / "DATA_EMPS_PULSES.mat")])
    report, lines = {}, ["| base | named (in order) | train relerr % (decimated) | test relerr % (decimated) "
                         "| test RMSE N (1 kHz) | test RMSE constant feed N | s |", "|---|---|---|---|---|---|---|"]
    bases = (("coulomb --offset", CoulombModel(fit_offset=True)), ("gms --offset", GMSModel(fit_offset=True)))
    for label, base in bases:
        result = discover(base, train, test, progress=lambda text: print(f"{label}: {text}", flush=True))
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
    write_json(report, args.json)
    print(text)
    if args.markdown:
        write_text_atomic(args.markdown, text)
    return 0


def _fmt(value, spec=".2f") -> str:
    return "-" if value is None else format(value, spec)


def markdown(section: str, settings: dict, summary: dict, cases: list, nulls: list, seconds: float) -> str:
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
        f"{100 * fp['rate']:.1f} % (95 % CI {100 * fp['interval_95'][0]:.1f}-{100 * fp['interval_95'][1]:.1f} %) "
        f"| <= 5 % |",
        f"| naming accuracy, effect RMS >= {acc['min_ratio']:g} x noise RMS (absorbed effects excluded) | "
        f"{acc['count']}/{acc['n']} = {100 * acc['rate']:.1f} % (95 % CI {100 * acc['interval_95'][0]:.1f}-"
        f"{100 * acc['interval_95'][1]:.1f} %) | >= 90 % |",
        f"| gap closure vs the true term, median over named cases | {_fmt(closure['median'], '.3f')} "
        f"({closure['n']} cases; {_fmt(100 * closure['share_at_least_0.8'] if closure['n'] else None, '.0f')} % "
        f"of them >= 0.8) | >= 0.8 |",
        f"| cases naming an effect neither hidden nor background | {_fmt(100 * summary['spurious_rate'], '.1f')} % "
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
        lines.append(f"| {name}{' (absorbed)' if name in ABSORBED else ''} | " + " | ".join(row) + " |")
    if settings.get("background"):
        lines += ["", "Background (named on the plain logs, the plant's own structure): "
                  + "; ".join(f"seed {seed}: {', '.join(names) or 'none'}"
                              for seed, names in settings["background"].items())]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    args = parse_args(argv)
    if args.section == "emps":
        return emps_section(args)
    defaults = SECTIONS[args.section]
    seeds = args.seeds if args.seeds is not None else defaults["seeds"]
    null_seeds = args.null_seeds if args.null_seeds is not None else defaults["null_seeds"]
    ratios = tuple(float(r) for r in args.ratios.split(",")) if args.ratios else defaults["ratios"]
    duration = args.duration or defaults["duration"]
    effects = tuple(args.effects.split(",")) if args.effects else EFFECT_NAMES
    base = defaults["base"]()
    settings = {"section": args.section, "base": type(base).__name__, "duration": duration, "seeds": seeds,
                "null_seeds": null_seeds, "ratios": list(ratios), "effects": list(effects),
                "description": ("Coulomb plant, Coulomb base model: the base class is exactly right"
                                if args.section == "coulomb" else
                                "the twin's truth plant (Maxwell-slip, lagged Stribeck, preload profile, lead "
                                "ripple), GMS base model")}
    started = time.perf_counter()
    cases, nulls, background = [], [], {}

    def save():
        summary = summarise(cases, nulls)
        write_json({"settings": settings, "summary": summary, "cases": cases, "nulls": nulls,
                    "seconds": time.perf_counter() - started}, args.json)
        return summary

    if args.section == "twin":
        for seed in range(seeds):
            row = run_case(base, StudyCase(None, 0.0, seed, "twin", duration))
            background[str(seed)] = row["named"]
            print(f"background seed {seed}: {row['verdict']} {row['named']} ({row['seconds']:.0f} s)", flush=True)
        settings["background"] = background
    for seed in range(null_seeds):
        row = run_null(base, seed, plant=args.section, duration_s=duration)
        nulls.append(row)
        print(f"null {seed}: {row['verdict']} {row['named']} ({row['seconds']:.1f} s)", flush=True)
        if seed % 10 == 9:
            save()
    for name in effects:
        for ratio in ratios:
            for seed in range(seeds):
                case = StudyCase(name, ratio, seed, args.section, duration)
                row = run_case(base, case, background=frozenset(background.get(str(seed), ())))
                cases.append(row)
                closure = "-" if row["closure"] is None else f"{row['closure']:.3f}"
                print(f"{name} x{ratio:g} seed {seed}: {row['verdict']} {row['named']} correct={row['correct']} "
                      f"closure={closure} ({row['seconds']:.1f} s)", flush=True)
                save()
    summary = save()
    text = markdown(args.section, settings, summary, cases, nulls, time.perf_counter() - started)
    print(text)
    if args.markdown:
        write_text_atomic(args.markdown, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
