"""``greybox train``: fit a current model to logs and save it to a model file."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from ..atomic import check_output_path
from ..errors import GreyboxError, ModelFileError
from ..metrics import metrics_table
from ..persistence import load_model, save_model
from ..registry import MODEL_CLASSES
from ._build import add_model_arguments, build_model
from ._options import add_log_arguments, read_logs


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "train",
        help="fit a current model to logs and save it",
        description="Read and prepare every training log as a separate run, fit the model to all runs, "
        "print the training error and the identified parameters, and save the model file.",
    )
    parser.add_argument("--model", required=True, choices=sorted(MODEL_CLASSES), help="model kind")
    parser.add_argument(
        "--train", required=True, nargs="+", metavar="LOG",
        help="training logs (CSV, Parquet, MCAP, TDMS or MATLAB .mat)"
    )
    parser.add_argument(
        "--stage2",
        nargs="+",
        metavar="LOG",
        help="gmssvr only: logs for the SVR stage; the GMS stage is then fitted on --train alone",
    )
    parser.add_argument("--out", required=True, metavar="MODEL", help="model file to write (.gbm)")
    parser.add_argument("--force", action="store_true", help="overwrite MODEL if it exists")
    add_model_arguments(parser, backlash=True)
    parser.add_argument("--quiet", action="store_true", help="no progress display during the identification")
    add_log_arguments(parser)
    parser.set_defaults(run=run)


#: Arrays and lists longer than this are summarised by their shape, not printed.
_MAX_PRINTED = 12


def _format_value(value) -> str:
    if isinstance(value, np.ndarray):
        if value.size > _MAX_PRINTED:
            return f"<array of shape {value.shape}>"
        return "[" + ", ".join(f"{v:.6g}" for v in value.ravel()) + "]"
    if isinstance(value, (list, tuple, dict)) and len(value) > _MAX_PRINTED:
        return f"<{type(value).__name__} of {len(value)} items>"
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def describe_parameters(model) -> list[str]:
    """Lines ``name = value unit`` of the model's parameter table (see ``parameter_table``)."""
    return [f"  {row.name:<14} = {_format_value(row.value)} {row.unit if row.unit != '-' else ''}".rstrip()
            for row in model.parameter_table()]


def _fit(model, args: argparse.Namespace):
    """Fit ``model`` as the options say; return the paths and runs it was fitted on."""
    progress = None if args.quiet else True
    if args.stage2 and model.first_stage() is None:
        raise GreyboxError(f"option --stage2 does not apply to the {args.model} model: it has one stage")
    runs = read_logs(args, args.train)
    if not args.stage2:
        model.fit(runs, progress=progress)
        return list(args.train), runs
    second = read_logs(args, args.stage2)
    model.fit_staged(runs, second, progress=progress)
    return list(args.train) + list(args.stage2), runs + second


def run(args: argparse.Namespace) -> int:
    out = Path(args.out)
    check_output_path(out, overwrite=args.force, protect=list(args.train) + list(args.stage2 or ()),
                      error=ModelFileError, inputs_name="one of the training logs")
    model = build_model(args.model, args)
    started = time.perf_counter()
    paths, runs = _fit(model, args)
    elapsed = time.perf_counter() - started
    unit = runs[0].effort_unit
    print(f"trained {args.model} on {len(runs)} run(s), {sum(len(r) for r in runs)} samples, "
          f"effort in {unit}, in {elapsed:.1f} s")
    print(f"  {'run':<32} {'samples':>8} {'RMSE ' + unit:>10} {'RE %':>7}")
    predictions = [model.predict(run) for run in runs]
    for path, run, prediction in zip(paths, runs, predictions):
        table = metrics_table(run.effort, prediction)
        print(f"  {Path(path).name[-32:]:<32} {table['n']:>8d} {table['rmse']:>10.4g} {table['re']:>7.3f}")
    if len(runs) > 1:
        table = metrics_table(np.concatenate([r.effort for r in runs]), np.concatenate(predictions))
        print(f"  {'all runs':<32} {table['n']:>8d} {table['rmse']:>10.4g} {table['re']:>7.3f}")
    print("  (RE = RMSE / mean |effort|)")
    print("parameters:")
    for line in describe_parameters(model):
        print(line)
    print("fit:")
    for name, value in model.fit_summary().items():
        print(f"  {name:<18} = {_format_value(value)}")
    save_model(model, out, overwrite=args.force)
    reloaded = load_model(out)
    if not all(np.array_equal(reloaded.predict(run), p) for run, p in zip(runs, predictions)):
        raise ModelFileError(f"{out}: the saved model does not reproduce the fitted model's predictions")
    print(f"wrote {out}")
    return 0
