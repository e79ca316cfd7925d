"""``greybox synth``: write synthetic axis logs of the twin machine as MCAP files."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import GreyboxError
from ..twin.ageing import DRIFT_KINDS, Drift, synthesize_history
from ..twin.cutting import CuttingSpec
from ..twin.datasets import ESSENTIAL_TRUTH_CHANNELS, SAMPLE_TIME_S, dataset_motion, synthesize
from ..twin.effects import EFFECTS, effect_parameters
from ..twin.family import synthesize_family
from ..twin.laws import TRUTH_LAWS
from ..twin.noise import CurrentNoise
from ..twin.trajectories import DATASETS, DEFAULT_DATASETS, MIN_DURATION_S
from ._types import FINITE, MAX_SEED, NON_NEGATIVE, POSITIVE, POSITIVE_INT, SEED, SIGNED_FRACTION, positive


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "synth",
        description=(
            "Simulate the synthetic feed axis (24-element Maxwell-slip friction, position-dependent, "
            "motor cogging, inertia, AR(1) current noise) along the trajectories of Rüppel et al. (2024, Table 1) and "
            "write one MCAP file per dataset, DIR/<axis>_<dataset>.mcap. Datasets: "
            + "; ".join(f"{k}: {v}" for k, v in DATASETS.items()) + ". With --family N: N axes of the family of "
            "truth axes instead (friction laws " + ", ".join(TRUTH_LAWS) + " in turn, random parameters, "
            "position- and load-dependent friction, cogging, noise and quantisation drawn from documented ranges), "
            "written as DIR/member_NNN/<axis>_<dataset>.mcap with DIR/family.json describing every member."
        ),
    )
    parser.add_argument("--axis", nargs="+", metavar="AXIS",
                        help="axes: X, Y (feed axes, mm), C (rotary table, deg) or several (X Y C); required "
                        "without --family")
    parser.add_argument("--family", type=POSITIVE_INT, metavar="N",
                        help="write N random axes of the family of truth axes (each draws its own axis, noise "
                             "and sensors; --seed is the family seed)")
    parser.add_argument("--out", required=True, metavar="DIR",
                        help="output directory (created if missing; a non-empty one only with --force)")
    parser.add_argument("--seed", required=True, type=SEED, metavar="N",
                        help=f"master seed (an integer from 0 to {MAX_SEED})")
    parser.add_argument("--plan", metavar="PROGRAM",
                        help="run an NC program instead of the datasets (one-axis G-code, e.g. from 'greybox plan'): "
                        "the axis it moves, written as DIR/<axis>_<program name>.mcap")
    parser.add_argument("--datasets", nargs="+", default=list(DEFAULT_DATASETS), metavar="ID",
                        help=f"dataset ids from {', '.join(DATASETS)} (default: {' '.join(DEFAULT_DATASETS)})")
    parser.add_argument("--effect", metavar="NAME",
                        help=f"add one hidden effect, kept as truth_effect_A: {', '.join(EFFECTS)}")
    parser.add_argument("--strength", type=FINITE, metavar="A",
                        help="strength of the hidden effect [A] (default 0.2)")
    parser.add_argument("--effect-param", action="append", default=[], metavar="KEY=VALUE",
                        help="further effect parameter, e.g. period_mm=5 (repeatable)")
    parser.add_argument("--cutting", action="store_true",
                        help="inject a milling-like cutting load, kept as truth_process_A and as the force on the "
                        "table truth_process_force_N (with --family, each member's axis file is written beside "
                        "its logs as axis.toml)")
    parser.add_argument("--cutting-strength", type=NON_NEGATIVE, default=CuttingSpec.strength_A, metavar="A",
                        help="mean process current [A] at 1000 mm/min feed (default %(default)s)")
    parser.add_argument("--cutting-return-pass", type=SIGNED_FRACTION, default=CuttingSpec.return_pass, metavar="R",
                        help="process current on the return stroke relative to the cutting stroke's at the same feed, "
                        "in [-1, 1]: 0 an air cut (default), > 0 a force opposing the motion too, < 0 one pushing "
                        "the table along it (climb milling; the screw is back-driven)")
    parser.add_argument("--spindle-rpm", type=POSITIVE, default=CuttingSpec.spindle_rpm, metavar="RPM",
                        help="spindle speed [1/min] of the tooth-passing ripple (default %(default)s)")
    parser.add_argument("--teeth", type=POSITIVE_INT, default=CuttingSpec.teeth, metavar="Z",
                        help="number of cutter teeth (default %(default)s)")
    parser.add_argument("--duration", type=positive("seconds"), metavar="S",
                        help="length [s] of the random datasets A, C (default 120, at least 2; approximate: they "
                             "end at rest after the move that crosses it) and P (default 60, at least 10; rounded "
                             "up to whole 10 s envelope periods); B and D always cross the travel once back and "
                             "forth per speed")
    parser.add_argument("--noise-std", type=NON_NEGATIVE, default=CurrentNoise.std_A, metavar="A",
                        help="standard deviation [A] of the AR(1) current noise (default %(default)s)")
    parser.add_argument("--truth", choices=("all", "essential"), default="all",
                        help="truth channels to write: all, or only noise-free current and injected "
                             "components (compact files; default %(default)s)")
    parser.add_argument("--one-file", choices=("csv", "parquet", "mcap"), metavar="FORMAT",
                        help="write each dataset of all axes to one file DIR/<dataset>.FORMAT (csv, parquet or "
                        "mcap), as a machine logs its axes together (columns X_position_mm, Y_current_A, ...; "
                        "MCAP: a channel per axis), every axis cut to the shortest")
    parser.add_argument("--history", type=POSITIVE_INT, metavar="DAYS",
                        help="write an ageing machine instead: one short air-move log per axis and day, "
                             "DIR/<axis>_<YYYY-MM-DD>.mcap, with a day-to-day spread and the --drift given "
                             "(for greybox monitor); with --cutting production days: the strokes in the cutting "
                             "direction cut, and the log has a spindle_load_pct column")
    parser.add_argument("--drift", action="append", default=[], metavar="KIND:START:RATE",
                        help="with --history: a drift of every axis from day START (counted from 0) at RATE per "
                             "day; KIND: " + "; ".join(DRIFT_KINDS.values())
                             + " (repeatable)")
    parser.add_argument("--start-date", metavar="YYYY-MM-DD", default="2026-01-01",
                        help="with --history: the date of day 0 (default %(default)s)")
    parser.add_argument("--machine", metavar="NAME", default="twin",
                        help="with --history: the machine name written to the logs (default %(default)s)")
    parser.add_argument("--force", action="store_true",
                        help="write into a non-empty DIR, overwriting files of the same name")
    parser.set_defaults(run=run)


def _parse_value(text: str):
    lowered = text.strip().lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    try:
        return float(text)
    except ValueError:
        raise GreyboxError(f"effect parameter value {text!r} is not a number (or true/false)") from None


def _effect_options(args: argparse.Namespace) -> dict:
    if args.effect is None:
        if args.strength is not None or args.effect_param:
            raise GreyboxError("--strength and --effect-param need --effect NAME")
        return {}
    if args.effect not in EFFECTS:
        raise GreyboxError(f"unknown hidden effect {args.effect!r}; choose from {', '.join(EFFECTS)}")
    params = {}
    for item in args.effect_param:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise GreyboxError(f"--effect-param {item!r}: expected KEY=VALUE")
        key = key.strip()
        if key not in effect_parameters(args.effect):
            known = ", ".join(effect_parameters(args.effect)) or "none"
            raise GreyboxError(f"effect {args.effect!r} has no parameter {key!r}; its parameters: {known}")
        params[key] = _parse_value(value)
    options = {"effect": args.effect, "effect_params": params}
    if args.strength is not None:
        options["effect_strength"] = args.strength
    return options


def _check_out_dir(args: argparse.Namespace) -> None:
    """Refuse before any work: DIR is a file, or it holds anything and --force is not given."""
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise GreyboxError(f"{out}: is a file, not a directory")
    if out.is_dir() and not args.force:
        present = sorted(entry.name for entry in out.iterdir())
        if present:
            more = f" and {len(present) - 1} more exist" if len(present) > 1 else " exists"
            raise GreyboxError(f"{out}: directory is not empty ({present[0]}{more}); nothing was written. "
                               "Choose another directory or pass --force to write into it")


#: Why a dataset needs MIN_DURATION_S, by dataset id.
_MINIMUM_REASONS = {
    "A": "0.5 s at rest at each end around at least one move",
    "C": "0.5 s at rest at each end around at least one move",
    "P": "it runs whole 10 s envelope periods",
}
#: Why a dataset's length differs from --duration, by dataset id.
_DURATION_REASONS = {
    "A": "A and C end at rest after the move that crosses it",
    "C": "A and C end at rest after the move that crosses it",
    "P": "P runs whole 10 s envelope periods",
}


def _check_duration(args: argparse.Namespace, axes, datasets) -> None:
    """Refuse a --duration below a dataset's minimum; say which logs will be longer or shorter than asked.

    Raises
    ------
    GreyboxError
        If ``--duration`` is below :data:`~greybox.twin.trajectories.MIN_DURATION_S` of a requested dataset.
    """
    duration = args.duration
    if duration is None or not duration > 0:  # non-positive values are refused where they are used
        return
    for key in datasets:
        minimum = MIN_DURATION_S.get(key)
        if minimum is not None and duration < minimum:
            raise GreyboxError(f"--duration {duration:g}: dataset {key} needs at least {minimum:g} s "
                               f"({_MINIMUM_REASONS[key]}); give --duration {minimum:g} or more, or leave {key} "
                               "out of --datasets")
    differ, reasons = [], []
    for axis in axes:
        for key in datasets:
            if key not in MIN_DURATION_S:
                continue
            length_s = SAMPLE_TIME_S * int(dataset_motion(axis, key, args.seed, duration).duration_s / SAMPLE_TIME_S
                                           + 1e-9)
            if abs(length_s - duration) > 0.5:
                differ.append(f"{axis}_{key} {length_s:.1f} s")
                reasons.append(_DURATION_REASONS[key])
    if differ:
        print(f"note: --duration {duration:g} s gives {', '.join(differ)} ({'; '.join(dict.fromkeys(reasons))})",
              file=sys.stderr)
    fixed = [key for key in datasets if key in DATASETS and key not in MIN_DURATION_S]
    if fixed:
        print(f"note: --duration does not apply to {', '.join(fixed)} (once back and forth over the travel per speed)",
              file=sys.stderr)


def _run_plan(args: argparse.Namespace, cutting) -> int:
    """``synth --plan PROGRAM``: the twin axis the program moves runs it; one log."""
    from ..twin.nc_run import synthesize_program

    given = [flag for flag, value in (("--family", args.family), ("--axis", args.axis), ("--duration", args.duration),
                                      ("--one-file", args.one_file)) if value is not None]
    if given:
        raise GreyboxError(f"--plan runs the program's own axis and motion; {', '.join(given)} does not apply")
    options = _effect_options(args)
    if cutting is not None:
        options["cutting"] = cutting
    ran = synthesize_program(args.plan, args.seed, args.out, force=args.force,
                             truth_channels=ESSENTIAL_TRUTH_CHANNELS if args.truth == "essential" else None,
                             noise=CurrentNoise(std_A=args.noise_std), **options)
    lowered = ran.trajectory.description["feeds_lowered"]
    print(f"{Path(args.plan).name}: axis {ran.log.axis}, {len(ran.program.blocks)} moves and dwells, "
          f"{ran.log.duration:.1f} s, {len(ran.log)} samples -> {ran.path}")
    if lowered:
        print(f"note: {Path(args.plan).name}: the twin's acceleration limit lowered the feeds of {len(lowered)} "
              f"stroke(s) (first at line {lowered[0]['line']}, to {100 * lowered[0]['factor']:.0f} %)",
              file=sys.stderr)
    return 0


def _run_family(args: argparse.Namespace, datasets, cutting) -> int:
    given = [flag for flag, value in (("--axis", args.axis), ("--effect", args.effect),
                                      ("--strength", args.strength), ("--effect-param", args.effect_param))
             if value]
    if args.noise_std != CurrentNoise.std_A:
        given.append("--noise-std")
    if given:
        raise GreyboxError(f"--family draws each axis, its noise and sensors; {', '.join(given)} does not apply")
    _check_out_dir(args)
    for key in datasets:
        minimum = MIN_DURATION_S.get(key)
        if args.duration is not None and minimum is not None and args.duration < minimum:
            raise GreyboxError(f"--duration {args.duration:g}: dataset {key} needs at least {minimum:g} s "
                               f"({_MINIMUM_REASONS[key]})")
    options = {"cutting": cutting} if cutting is not None else {}
    synthesize_family(args.family, args.seed, args.out, datasets, force=args.force,
                      truth_channels=ESSENTIAL_TRUTH_CHANNELS if args.truth == "essential" else None,
                      progress=print, duration_s=args.duration, **options)
    print(f"family of {args.family} axes (seed {args.seed}) -> {args.out}; members described in "
          f"{Path(args.out) / 'family.json'}")
    return 0


def _run_history(args: argparse.Namespace) -> int:
    """``synth --history DAYS``: the ageing twin's daily air-move logs."""
    import datetime as dt

    given = [flag for flag, value in (("--family", args.family), ("--plan", args.plan), ("--effect", args.effect),
                                      ("--duration", args.duration),
                                      ("--one-file", args.one_file)) if value]
    if given:
        raise GreyboxError(f"--history writes the daily air moves of the ageing twin; {', '.join(given)} "
                           "does not apply")
    if not args.axis:
        raise GreyboxError("--history needs the axes (--axis X, Y, C or several)")
    try:
        start = dt.date.fromisoformat(args.start_date)
    except ValueError:
        raise GreyboxError(f"--start-date {args.start_date!r}: expected a day YYYY-MM-DD") from None
    drifts = [Drift.parse(text) for text in args.drift]
    axes = list(dict.fromkeys(a.strip().upper() for a in args.axis if a.strip()))
    _check_out_dir(args)
    cutting = None
    if args.cutting:  # production days: the strokes in the cutting direction cut, with a spindle-load column
        cutting = CuttingSpec(strength_A=args.cutting_strength, spindle_rpm=args.spindle_rpm, teeth=args.teeth,
                              return_pass=args.cutting_return_pass)
    synthesize_history(axes, args.history, args.seed, args.out, drifts, start_date=start, machine=args.machine,
                       truth_channels=ESSENTIAL_TRUTH_CHANNELS if args.truth == "essential" else None,
                       cutting=cutting, progress=print)
    return 0


def run(args: argparse.Namespace) -> int:
    if args.history is not None:
        return _run_history(args)
    given = [flag for flag, value in (("--drift", args.drift), ("--start-date", args.start_date != "2026-01-01"),
                                      ("--machine", args.machine != "twin")) if value]
    if given:
        raise GreyboxError(f"{', '.join(given)} needs --history DAYS")
    datasets = list(dict.fromkeys(d.strip().upper() for d in args.datasets if d.strip()))
    cutting = None
    if args.cutting:
        cutting = CuttingSpec(strength_A=args.cutting_strength, spindle_rpm=args.spindle_rpm, teeth=args.teeth,
                              return_pass=args.cutting_return_pass)
    if args.plan is not None:
        return _run_plan(args, cutting)
    if args.family is not None:
        if not datasets:
            raise GreyboxError("give at least one dataset (--datasets)")
        return _run_family(args, datasets, cutting)
    if not args.axis:
        raise GreyboxError("give the axes to simulate (--axis X, Y, C or several) or --family N")
    axes = list(dict.fromkeys(a.strip().upper() for a in args.axis if a.strip()))
    if not axes or not datasets:
        raise GreyboxError("give at least one axis (--axis) and one dataset (--datasets)")
    options = _effect_options(args)
    _check_out_dir(args)
    _check_duration(args, axes, datasets)
    if cutting is not None:
        options["cutting"] = cutting
    synthesize(
        axes, args.seed, args.out, datasets,
        force=args.force,
        truth_channels=ESSENTIAL_TRUTH_CHANNELS if args.truth == "essential" else None,
        progress=print,
        one_file=args.one_file,
        duration_s=args.duration,
        noise=CurrentNoise(std_A=args.noise_std),
        **options,
    )
    return 0
