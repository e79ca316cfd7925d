"""``greybox discover``: find what a friction model misses, name it, add it, show the gap shrink."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from ..atomic import check_output_path
from ..discover.heldout import DEFAULT_BLOCKS, DEFAULT_MIN_GAIN
from ..discover.report import REPORT_FILES, write_json, write_report
from ..discover.workflow import discover
from ..errors import GreyboxError, ModelFileError
from ..identify.progress import ProgressPrinter
from ..models.effects import EFFECT_NAMES, effect
from ..models.files import save_verified
from ..models.registry import MODEL_CLASSES
from ._build import CommandLineError, add_model_arguments, build_model
from ._options import add_log_arguments, read_logs, read_options
from ._types import FRACTION, NON_NEGATIVE_INT, POSITIVE_INT, SEED


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "discover",
        description="Fit the base model on the training logs, locate where its residual lies (by regime), "
        "score a library of named effects against a null calibrated on simulated data with nothing missing, "
        "add the winning effect and refit jointly (at most --max-effects times), and report the error on the "
        "test logs before and after. Effects: " + ", ".join(EFFECT_NAMES) + ".",
    )
    parser.add_argument("--model", required=True, choices=sorted(MODEL_CLASSES), metavar="KIND",
                        help="kind of the base model: " + ", ".join(sorted(MODEL_CLASSES)) + " (its linear "
                        "parameters are refitted with the effects; svr and gmssvr have none and refit slowly)")
    parser.add_argument("--train", required=True, nargs="+", metavar="LOG",
                        help="training logs (CSV, Parquet, MCAP, TDMS or MATLAB .mat), each a separate run")
    parser.add_argument("--test", required=True, nargs="+", metavar="LOG", help="test logs, each a separate run")
    parser.add_argument("--json", required=True, metavar="OUT", help="JSON file of the findings to write")
    parser.add_argument("--out", metavar="DIR", help="also write a report into DIR: the JSON and residual plots")
    parser.add_argument("--save-model", metavar="MODEL", help="save the augmented model to this file (.gbm)")
    parser.add_argument("--force", action="store_true",
                        help="overwrite OUT, MODEL and the report's files if they exist")
    workflow = parser.add_argument_group("discovery options")
    workflow.add_argument("--effects", nargs="+", metavar="NAME",
                          help="effects to consider (default: the whole library)")
    workflow.add_argument("--max-effects", type=NON_NEGATIVE_INT, default=3, metavar="N",
                          help="most effects to add (default 3)")
    workflow.add_argument("--alpha", type=FRACTION, default=0.05,
                          help="chance of naming an effect when nothing is missing (default 0.05)")
    workflow.add_argument("--null-replicates", type=POSITIVE_INT, default=99, metavar="B",
                          help="simulated null data sets per step (default 99)")
    workflow.add_argument("--seed", type=SEED, default=0, metavar="N", help="seed of the null simulations (default 0)")
    workflow.add_argument("--no-refit-base", action="store_true",
                          help="keep the base model's nonlinear shape when effects are added (faster)")
    workflow.add_argument("--no-refine-base", action="store_true",
                          help="do not refine the base model (a friction curve along the speed, friction held at rest "
                          "and pre-sliding transients) before naming effects (then stribeck and viscous_friction "
                          "are candidates; see docs/discover.md)")
    workflow.add_argument("--held-out-blocks", type=POSITIVE_INT, default=DEFAULT_BLOCKS, metavar="K",
                          help=f"blocks of training time for the held-out test, at least 2 (default {DEFAULT_BLOCKS})")
    workflow.add_argument("--min-gain", type=FRACTION, default=DEFAULT_MIN_GAIN, metavar="F",
                          help="smallest share of the held-out residual's sum of squares an effect must remove to "
                          f"be named (default {DEFAULT_MIN_GAIN:g})")
    add_model_arguments(parser, title="base model options", settings=False)
    parser.add_argument("--quiet", action="store_true", help="no progress display")
    add_log_arguments(parser)
    parser.set_defaults(run=run)


def _check_outputs(args) -> None:
    """Refuse before any fitting when an output would overwrite an input, or a file without --force."""
    inputs = list(args.train) + list(args.test)
    check_output_path(args.json, overwrite=args.force, protect=inputs, inputs_name="one of the input logs")
    if args.save_model:
        check_output_path(args.save_model, overwrite=args.force, protect=inputs, error=ModelFileError,
                          inputs_name="one of the input logs")
    if args.out:
        directory = Path(args.out)
        if directory.exists() and not directory.is_dir():
            raise GreyboxError(f"{directory}: exists and is not a directory")
        for name in REPORT_FILES:
            if (directory / name).exists():
                check_output_path(directory / name, overwrite=args.force, protect=inputs,
                                  inputs_name="one of the input logs")


def _candidates(names: list[str] | None) -> tuple[str, ...]:
    if not names:
        return EFFECT_NAMES
    unknown = [name for name in names if name not in EFFECT_NAMES]
    if unknown:
        raise GreyboxError(f"unknown effect {', '.join(unknown)} (--effects); choose from {', '.join(EFFECT_NAMES)}")
    return tuple(dict.fromkeys(names))


def _format_parameters(parameters: dict) -> str:
    return ", ".join(f"{key} = {value:.5g}" if isinstance(value, float) else f"{key} = {value}"
                     for key, value in parameters.items())


def _print_summary(result) -> None:
    unit, relabel = result.unit, result.units.relabel
    print(f"verdict: {result.verdict}")
    for index, entry in enumerate(result.effects, 1):
        evidence = entry["evidence"]
        print(f"  {index}. {entry['name']}: {relabel(_format_parameters(entry['parameters']))}")
        print(f"     explains {100 * evidence['explained_fraction']:.2f} % of the residual at step "
              f"{evidence['step']} (passes beyond {100 * (evidence['threshold_fraction'] or np.inf):.3f} %, "
              f"p = {evidence['p_value']:.3f}); the joint refit {100 * evidence['refit_explained_fraction']:.2f} %")
        held = evidence["held_out"]
        print(f"     on held-out blocks of the training time it removes {100 * held['gain']:.2f} +- "
              f"{100 * held['uncertainty']:.2f} % of the residual's sum of squares "
              f"(needed: {100 * held['margin']:.2f} %)")
        if evidence["indistinguishable_from"]:
            print(f"     the data cannot tell it apart from: {', '.join(evidence['indistinguishable_from'])}")
    misfit = result.base_misfit
    if misfit and misfit["detected"]:
        kept = {name: entry for name, entry in misfit["refinements"].items() if entry["kept"]}
        for name, entry in kept.items():
            held = entry["held_out"]
            print(f"  base misfit: {name} ({effect(name).summary}) removes {100 * held['gain']:.2f} +- "
                  f"{100 * held['uncertainty']:.2f} % of the held-out residual and is kept "
                  f"({relabel(_format_parameters(entry['parameters']))})")
        if not kept:
            print("  base misfit: the structure left lies along the velocity or the time since the motion changed "
                  "(or does not hold on held-out blocks): the base model's own friction law misfits")
    last = result.steps[-1]
    if last.structure.passes:
        where = sorted(last.families.items(), key=lambda item: -item[1]["explained_fraction"])
        print("  structure no library effect explains remains (strongest along: "
              + ", ".join(f"{name} {100 * value['explained_fraction']:.2f} %" for name, value in where[:3]
                          if value["p_value"] <= last.alpha) + ")")
    for rejected in result.rejected:
        if rejected["reason"] == "held_out":
            print(f"  {rejected['name']} passed the null test but not the held-out test "
                  f"({'; '.join(rejected['held_out']['reasons'])}): not named")
        else:
            print(f"  {rejected['name']} passed but its joint refit explained no more than chance: dropped")
    for label, gap in (("train", result.train), ("test", result.test)):
        if not gap:
            continue
        change = 100 * (gap["rmse_after"] - gap["rmse_before"]) / gap["rmse_before"]
        print(f"{label} RMSE {gap['rmse_before']:.5g} -> {gap['rmse_after']:.5g} {unit} ({change:+.1f} %), "
              f"RE {gap['re_before']:.3f} -> {gap['re_after']:.3f} %")
    print(f"  {'test regime':<16} {'n':>8} {'RMSE before':>12} {'after':>10}")
    for name, row in result.test["regimes"].items():
        if row["n"]:
            print(f"  {name:<16} {row['n']:>8d} {row['rmse_before']:>12.5g} {row['rmse_after']:>10.5g}")
    print("  (RE = RMSE / mean |effort|; before: base model alone; after: with the named effects)")


def run(args: argparse.Namespace) -> int:
    if int(args.alpha * (args.null_replicates + 1)) < 1:  # the workflow's own condition, checked before any work
        least = int(np.ceil(1.0 / args.alpha)) - 1
        raise CommandLineError(f"--alpha {args.alpha:g} with --null-replicates {args.null_replicates} can never name "
                               f"an effect: give --null-replicates {least} or more, or a larger --alpha")
    if args.held_out_blocks < 2:
        raise CommandLineError(f"--held-out-blocks must be at least 2, got {args.held_out_blocks}")
    _check_outputs(args)
    names = _candidates(args.effects)
    base = build_model(args.model, args)
    started = getattr(args, "started_s", None) or time.perf_counter()  # from the process's start when known

    def say(text: str) -> None:
        if not args.quiet:
            print(f"[{time.perf_counter() - started:6.1f} s] {text}", file=sys.stderr, flush=True)

    say(f"reading {len(args.train)} training and {len(args.test)} test log(s)")
    train = read_logs(args, args.train)
    test = read_logs(args, args.test)
    result = discover(base, train, test, candidates=names, max_effects=args.max_effects, alpha=args.alpha,
                      n_null=args.null_replicates, seed=args.seed, refit_base=not args.no_refit_base,
                      refine_base=not args.no_refine_base, held_out_blocks=args.held_out_blocks,
                      min_gain=args.min_gain,
                      progress=say, fit_progress=None if args.quiet else ProgressPrinter(interval=5.0),
                      read=read_options(args))
    document = result.to_dict()
    document["logs"] = {"train": [str(p) for p in args.train], "test": [str(p) for p in args.test]}
    _print_summary(result)
    print(f"wrote {write_json(document, args.json)}")
    if args.out:
        for path in write_report(result, args.out, document):
            print(f"wrote {path}")
    if args.save_model:
        save_verified(result.model, args.save_model, [test], overwrite=args.force)
        print(f"wrote {args.save_model}")
    startup = ", start-up included" if getattr(args, "startup_counted", False) else ""
    print(f"done in {time.perf_counter() - started:.1f} s wall{startup}")
    return 0
