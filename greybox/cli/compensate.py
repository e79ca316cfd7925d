"""``greybox compensate``: compare friction models by the tracking error of a position loop with feed-forward."""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from ..errors import GreyboxError
from ._types import FINITE, NON_NEGATIVE, POSITIVE, SEED, WordOrNumber, positive

__all__ = ["add_parser", "run"]

#: Plants given by name rather than by a model file.
TWIN_PLANTS = {"twin-x": "X", "twin-y": "Y", "twin-c": "C"}

#: Generated references.
STROKE_REFERENCES = ("low", "high")


def add_parser(subparsers) -> None:
    """Add the ``compensate`` sub-command and its options.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-command registry of the ``greybox`` parser (from ``add_subparsers``).
    """
    from ..control.references import STROKES_MM
    from ..models.registry import MODEL_CLASSES

    parser = subparsers.add_parser(
        "compensate",
        description="Simulate a PID position loop around a plant (the synthetic axis, or an identified GMS/LuGre "
        "model) with feed-forward of the inertia plus each friction model, one set of PID gains for all, on a "
        "low-stroke and a high-stroke filtered random reference (or references given as logs), and write a table "
        "of RMS and peak tracking error per model and reference (Tjahjowidodo et al. 2005, Tables 2 and 3) with "
        "plots of the tracking error.",
    )
    parser.add_argument("--plant", required=True, metavar="PLANT",
                        help="twin-X, twin-Y, twin-C (the synthetic axes' truth plants; C is the rotary table, in deg) "
                        "or a gms/lugre model file")
    parser.add_argument("--model-file", nargs="+", default=[], metavar="MODEL", dest="model_files",
                        help="feed-forward model files (.gbm)")
    parser.add_argument("--model", nargs="+", metavar="KIND", dest="kinds",
                        help=f"fit models of these kinds for feed-forward ({', '.join(MODEL_CLASSES)}) on --train "
                        "logs or, for a twin plant, on its synthetic datasets A and P")
    parser.add_argument("--train", nargs="+", metavar="LOG", help="training logs of the --model kinds")
    parser.add_argument("--train-duration", type=positive("seconds"), default=60.0, metavar="S",
                        help="length [s] of each synthetic training dataset of a twin plant (default 60)")
    parser.add_argument("--out", required=True, metavar="DIR", help="output directory")
    parser.add_argument("--force", action="store_true", help="overwrite existing report files in DIR")
    group = parser.add_argument_group("references")
    group.add_argument("--reference", nargs="+", default=list(STROKE_REFERENCES), metavar="REF",
                       help=f"low ({STROKES_MM['low']:g} mm stroke; deg on a rotary plant), high "
                       f"({STROKES_MM['high']:g} mm stroke) or a "
                       "log whose position is the reference (default: low high)")
    group.add_argument("--duration", type=positive("seconds"), default=60.0, metavar="S",
                       help="length [s] of the generated references (default 60)")
    group.add_argument("--seed", type=SEED, default=0, metavar="N",
                       help="seed of the references, the synthetic training data and the disturbance (default 0)")
    group.add_argument("--start", type=FINITE, metavar="POS",
                       help="start position [mm, or deg on a rotary plant] of the generated references (default: the "
                       "middle of the twin's "
                       "measurement window, 0 for a model plant)")
    group.add_argument("--reference-step", type=positive("seconds"), metavar="S",
                       help="step [s] of the generated references (default: the feed-forward models' sample time, "
                       "else 0.002)")
    group = parser.add_argument_group("loop")
    group.add_argument("--inertia", default="plant", metavar="J",
                       type=WordOrNumber(("plant", "model"), NON_NEGATIVE),
                       help="inertia of the feed-forward: 'plant' (the plant's, for every row; default), 'model' "
                       "(each model's own) or a value [A s^2/mm, or A s^2/deg]")
    group.add_argument("--bandwidth", type=POSITIVE, metavar="HZ",
                       help="closed-loop bandwidth [Hz] of the PID pole placement (default 0.1 / (2 pi T))")
    group.add_argument("--controller-period", type=positive("seconds"), metavar="S",
                       help="controller period [s], a divisor of the reference step (default: at most 0.25 ms)")
    group.add_argument("--current-limit", type=POSITIVE, default=10.0, metavar="A",
                       help="saturation of the motor current [A] (default 10)")
    group.add_argument("--resolution", type=NON_NEGATIVE, default=1e-4, metavar="MM",
                       help="encoder resolution [mm, or deg on a rotary plant] (default 0.0001)")
    group.add_argument("--disturbance-std", type=NON_NEGATIVE, default=0.0, metavar="A",
                       help="standard deviation [A] of an AR(1) disturbance current (default 0: none)")
    parser.add_argument("--quiet", action="store_true", help="no progress messages")
    from ._options import add_log_arguments

    add_log_arguments(parser)
    parser.set_defaults(run=run)


def _say(args, text: str) -> None:
    if not args.quiet:
        print(text, flush=True)


def _plant(args):
    from ..control.plants import ModelPlant, TwinPlant
    from ..models.files import load_model

    key = args.plant.strip().lower()
    if key in TWIN_PLANTS:
        return TwinPlant.for_axis(TWIN_PLANTS[key])
    if key.startswith("twin-"):
        twins = ", ".join(f"twin-{axis}" for axis in TWIN_PLANTS.values())
        raise GreyboxError(f"{args.plant}: no such twin; the twin plants are {twins} (--plant)")
    if not os.path.isfile(args.plant):
        raise GreyboxError(f"{args.plant}: no such model file; the plant is twin-X, twin-Y, twin-C or a gms/lugre "
                           "model file (--plant)")
    model = load_model(args.plant)  # its errors name the file already
    try:
        return ModelPlant(model, name=Path(args.plant).stem)
    except GreyboxError as error:
        raise GreyboxError(f"{args.plant}: {error}") from None


def _fit_kinds(args) -> list[str]:
    from ..models.registry import MODEL_CLASSES

    if not args.kinds:
        if args.train:
            raise GreyboxError("--train needs --model KIND...")
        return []
    kinds = [kind.strip().lower() for kind in args.kinds]
    unknown = [kind for kind in kinds if kind not in MODEL_CLASSES]
    if unknown or not kinds:
        raise GreyboxError(f"unknown model kind {', '.join(unknown)} (--model); "
                           f"choose from {', '.join(MODEL_CLASSES)}")
    return list(dict.fromkeys(kinds))


def _models(args, plant) -> dict:
    """The feed-forward models of --model-file and --model (:func:`greybox.control.workflow.feedforward_models`)."""
    from ..control.workflow import check_axis_kind, feedforward_models, synthesises_training
    from ._build import build_model
    from ._options import read_logs

    kinds = _fit_kinds(args)
    if not kinds and not args.model_files:
        raise GreyboxError("no feed-forward model: give --model KIND... or --model-file FILE...")
    if kinds and not args.train and not synthesises_training(plant):
        raise GreyboxError("--model with a model plant needs training logs: give --train LOG ...")
    runs = None
    if kinds and args.train:
        runs = read_logs(args, args.train)
        for run in runs:
            check_axis_kind(run.source or "--train", run.motion, plant)
    return feedforward_models(plant, model_files=args.model_files, kinds=kinds,
                              build=lambda kind: build_model(kind, args), train_runs=runs, seed=args.seed,
                              train_duration_s=args.train_duration, progress=lambda text: _say(args, text))


def _inertia(args):
    choice = args.inertia.strip().lower()
    if choice in ("plant", "model"):
        return choice
    try:
        return float(choice)
    except ValueError:
        raise GreyboxError(f"--inertia must be 'plant', 'model' or a number [A s^2/mm], got {args.inertia!r}"
                           ) from None


def _references(args, plant) -> list:
    from ..control.workflow import check_axis_kind
    from ._options import read_logs

    references = []
    for value in args.reference:
        if value in STROKE_REFERENCES:
            references.append(value)
            continue
        if not os.path.isfile(value):
            raise GreyboxError(f"{value}: no such log; --reference takes low, high or log files")
        for run in read_logs(args, [value]):
            check_axis_kind(value, run.motion, plant)
            references.append(run)
    return references


def _reference_names(args) -> list[str]:
    return [f"{value}-stroke" if value in STROKE_REFERENCES else Path(value).stem for value in args.reference]


def _check_output(args) -> None:
    """Refuse before any work when the report must not or cannot be written."""
    from ..control.report import report_paths

    for value in args.reference:
        if value not in STROKE_REFERENCES and not os.path.isfile(value):
            raise GreyboxError(f"{value}: no such log; --reference takes low, high or log files")
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise GreyboxError(f"{out}: exists and is not a directory")
    targets = report_paths(_reference_names(args), out)
    inputs = [p for p in [args.plant, *args.model_files, *(args.train or ()), *args.reference] if os.path.exists(p)]
    for target in targets:
        if target.exists() and any(os.path.samefile(target, source) for source in inputs):
            raise GreyboxError(f"{target}: is one of the inputs; refusing to overwrite it")
    existing = [str(path) for path in targets if path.exists()]
    if existing and not args.force:
        raise GreyboxError(f"{existing[0]}: file exists ({len(existing)} of {len(targets)} report files exist); "
                           "nothing was written. Choose another directory or pass --force to overwrite")


def run(args: argparse.Namespace) -> int:
    """Run ``greybox compensate``: simulate the loop with each feed-forward, print the table, write the report.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of the sub-command.

    Returns
    -------
    int
        The exit status, 0.
    """
    from ..control.report import comparison_rows, write_report
    from ..control.workflow import compensation_study

    _check_output(args)
    plant = _plant(args)
    models = _models(args, plant)
    started = time.perf_counter()
    study = compensation_study(plant, models, references=_references(args, plant), duration_s=args.duration,
                               seed=args.seed, start_mm=args.start, reference_step_s=args.reference_step,
                               inertia=_inertia(args), bandwidth_hz=args.bandwidth,
                               controller_period_s=args.controller_period, current_limit_A=args.current_limit,
                               resolution_mm=args.resolution, disturbance_std_A=args.disturbance_std,
                               progress=lambda text: _say(args, text))
    _say(args, f"simulated {len(study.results)} closed-loop runs in {time.perf_counter() - started:.1f} s")
    units = study.results[0].units
    fine, rms, peak = units.fine_unit, units.relabel("rms_error_mm"), units.relabel("peak_error_mm")
    print(f"  {'reference':<16} {'feed-forward':<16} {'RMS ' + fine:>10} {'max ' + fine:>10} {'vs none %':>10}")
    for row in comparison_rows(study.results):
        relative = f"{100.0 * row['rms_vs_none']:.1f}" if row["rms_vs_none"] == row["rms_vs_none"] else ""
        print(f"  {row['reference'][:16]:<16} {row['feedforward'][:16]:<16} {1e3 * row[rms]:>10.4g} "
              f"{1e3 * row[peak]:>10.4g} {relative:>10}")
    settings = {**study.settings, "model_files": list(args.model_files), "fitted": list(args.kinds or ()),
                "training_logs": list(args.train or ())}
    written = write_report(study.results, args.out, settings=settings, force=args.force)
    for path in written:
        _say(args, f"wrote {path}")
    return 0
