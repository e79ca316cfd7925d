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
from ..twin.part_series import PART_WORKPIECE_MM, PartSeriesSpec, ToolEvents, WarmUp
from ..twin.trajectories import DATASETS, DEFAULT_DATASETS, MIN_DURATION_S
from ._types import (
    FINITE,
    MAX_SEED,
    NON_NEGATIVE,
    NON_NEGATIVE_INT,
    POSITIVE,
    POSITIVE_INT,
    SEED,
    SIGNED_FRACTION,
    NumberRange,
    positive,
)

#: A friction drop of the warm-up, in [0, 1).
DROP = NumberRange(float, low=0, high=1, high_open=True, description="a fraction in [0, 1)")


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
    parts = parser.add_argument_group(
        "part series", "with --parts N: the same NC program (the built-in part, or --plan PROGRAM) cut N times "
        "over a shift through the machine's warm-up, with tool events; writes DIR/<axis>_partNNN.mcap and/or "
        "DIR/<axis>_series.mcap (with a 'part' counter column), the truth DIR/<axis>_parts.json and the "
        "program DIR/<axis>_part.mpf (docs/process.md)")
    parts.add_argument("--parts", type=POSITIVE_INT, metavar="N", help="write a part series of N parts")
    parts.add_argument("--part-layout", choices=("parts", "series", "both"), default="both",
                       help="one log per part, one long log, or both (default %(default)s)")
    parts.add_argument("--warmup-drop", type=DROP, default=WarmUp.drop, metavar="F",
                       help="share by which the friction falls on a fully warm machine (default %(default)s)")
    parts.add_argument("--warmup-time", type=positive("seconds"), default=WarmUp.time_constant_s, metavar="S",
                       help="time constant [s] of the warming while the machine runs (default %(default)s)")
    parts.add_argument("--cooling-time", type=positive("seconds"), default=WarmUp.cooling_time_constant_s,
                       metavar="S", help="time constant [s] of the cooling during a pause (default %(default)s)")
    parts.add_argument("--pause", action="append", default=[], metavar="PART:SECONDS",
                       help="a pause before PART during which the machine cools (repeatable)")
    parts.add_argument("--wear", type=NON_NEGATIVE, default=0.0, metavar="PCT",
                       help="tool wear: the cutting load rises by PCT %% per part after --wear-start")
    parts.add_argument("--wear-start", type=NON_NEGATIVE_INT, default=1, metavar="PART",
                       help="last part of the sharp tool (default %(default)s)")
    parts.add_argument("--breakage", metavar="PART:SECONDS",
                       help="the tool breaks in PART at SECONDS after the start of the part's log; no load after")
    parts.add_argument("--missing-blank", type=POSITIVE_INT, action="append", metavar="PART",
                       help="a part without blank: no cutting load (repeatable)")
    parts.add_argument("--oversized-blank", type=POSITIVE_INT, action="append", metavar="PART",
                       help="a part with an oversized blank: the load times --oversize-factor (repeatable)")
    parts.add_argument("--oversize-factor", type=POSITIVE, default=ToolEvents.oversize_factor, metavar="F",
                       help="load factor of an oversized blank, above 1 (default %(default)s)")
    parts.add_argument("--loading", type=NON_NEGATIVE, default=PartSeriesSpec.loading_s, metavar="S",
                       help="wait [s] at rest before each part (default %(default)s)")
    parts.add_argument("--jitter", type=NON_NEGATIVE, default=PartSeriesSpec.jitter_s, metavar="S",
                       help="largest random extra wait [s] before each part (default %(default)s)")
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


def _part_and_seconds(text: str, option: str) -> tuple[int, float]:
    part, sep, seconds = str(text).partition(":")
    try:
        value = (int(part), float(seconds))
    except ValueError:
        value = None
    if not sep or value is None or value[0] < 1 or not value[1] >= 0:
        raise GreyboxError(f"{option} {text!r}: expected PART:SECONDS, a part from 1 and a non-negative time")
    return value


def _run_parts(args: argparse.Namespace) -> int:
    """``synth --parts N``: a part series through the warm-up (:mod:`greybox.twin.part_series`)."""
    from ..nc.gcode import read_program
    from ..twin.part_series import synthesize_part_series

    given = [flag for flag, value in (("--family", args.family), ("--history", args.history),
                                      ("--effect", args.effect), ("--duration", args.duration),
                                      ("--one-file", args.one_file)) if value is not None]
    if given:
        raise GreyboxError(f"--parts writes a part series; {', '.join(given)} does not apply")
    program = read_program(args.plan) if args.plan else None
    axes = list(dict.fromkeys(a.strip().upper() for a in (args.axis or []) if a.strip()))
    if len(axes) > 1 or (program is not None and axes and axes != [program.axis]):
        raise GreyboxError("--parts runs one axis: give one --axis (or none with --plan: the program's)")
    axis = program.axis if program is not None else (axes[0] if axes else "X")
    breakage = _part_and_seconds(args.breakage, "--breakage") if args.breakage else (None, None)
    events = ToolEvents(wear_pct_per_part=args.wear, wear_start_part=args.wear_start, breakage_part=breakage[0],
                        breakage_time_s=breakage[1], missing_blank=tuple(args.missing_blank or ()),
                        oversized_blank=tuple(args.oversized_blank or ()), oversize_factor=args.oversize_factor)
    cutting = CuttingSpec(strength_A=args.cutting_strength, spindle_rpm=args.spindle_rpm, teeth=args.teeth,
                          return_pass=args.cutting_return_pass,
                          workpiece_mm=None if program is not None else PART_WORKPIECE_MM)
    spec = PartSeriesSpec(parts=args.parts, axis=axis, program=program, cutting=cutting,
                          warm_up=WarmUp(args.warmup_drop, args.warmup_time, args.cooling_time), events=events,
                          loading_s=args.loading, jitter_s=args.jitter,
                          pauses=tuple(_part_and_seconds(text, "--pause") for text in args.pause),
                          noise=CurrentNoise(std_A=args.noise_std))
    written = synthesize_part_series(spec, args.seed, args.out, layout=args.part_layout, force=args.force,
                                     truth_channels=ESSENTIAL_TRUTH_CHANNELS if args.truth == "essential" else None,
                                     progress=print)
    print(f"part series of {args.parts} parts on {axis} (seed {args.seed}) -> {args.out}; truth in {written[-1]}")
    return 0


def run(args: argparse.Namespace) -> int:
    if args.parts is not None:
        return _run_parts(args)
    part_options = [flag for flag, value in (("--pause", args.pause), ("--wear", args.wear),
                                             ("--breakage", args.breakage), ("--missing-blank", args.missing_blank),
                                             ("--oversized-blank", args.oversized_blank)) if value]
    if part_options:
        raise GreyboxError(f"{', '.join(part_options)} needs --parts N")
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
