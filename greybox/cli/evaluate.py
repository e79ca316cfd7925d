"""``greybox evaluate``: test saved models on logs, overall and per operating regime."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..atomic import check_output_path, write_text_atomic
from ..data.effort import EFFORT_UNITS, check_one_effort
from ..errors import GreyboxError
from ..evaluate.records import evaluate_models, write_evaluation_pdf, write_evaluation_report
from ..evaluate.regimes import REGIME_NAMES, TRAINING_REGION_NAMES
from ..evaluate.report import RE_NOTE, check_output_dir, records_json
from ..models.files import load_model
from ..provenance import model_quantity
from ._options import add_log_arguments, read_named_runs
from ._provenance import warn_preparation


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "evaluate",
        description="Load model files, predict the current of every test log, and print RMSE, RE and NMSE per "
        "model, overall and per operating regime (low/high velocity, reversals, constant feed, acceleration). "
        "With --out, also write a report: metrics.json/csv, tables.md, figures and index.html (or one PDF file).",
    )
    parser.add_argument("models", nargs="+", metavar="MODEL", help="model files written by 'greybox train'")
    parser.add_argument("--test", required=True, nargs="+", metavar="LOG",
                        help="test logs (CSV, Parquet, MCAP, TDMS or MATLAB .mat); their errors are pooled")
    parser.add_argument("--out", metavar="DIR", help="write a report (tables, figures, HTML page) into DIR; "
                        "DIR ending in .pdf: one PDF file of the tables and figures instead")
    parser.add_argument("--json", metavar="FILE", help="write the metric records (with regimes) to FILE")
    parser.add_argument("--force", action="store_true",
                        help="write into a non-empty DIR and replace an existing FILE")
    add_log_arguments(parser)
    parser.set_defaults(run=run)


def _model_names(paths) -> list[str]:
    """Report names of the model files: their stems, or their paths where stems repeat."""
    stems = [Path(p).stem for p in paths]
    return [stem if stems.count(stem) == 1 else str(p) for stem, p in zip(stems, paths)]


def _check_outputs(args) -> None:
    """Refuse before any work when an output cannot or must not be written."""
    inputs = [Path(p) for p in list(args.models) + list(args.test)]
    if args.out and Path(args.out).suffix.lower() == ".pdf":
        check_output_path(args.out, overwrite=args.force, protect=inputs)
    elif args.out:
        check_output_dir(args.out, force=args.force)
    if args.json:
        target = Path(args.json)
        if any(target.exists() and p.exists() and target.samefile(p) for p in inputs):
            raise GreyboxError(f"{target}: is one of the inputs; refusing to overwrite it")
        if target.exists() and not args.force:
            raise GreyboxError(f"{target}: file exists; use --force to replace it")
        if not target.parent.is_dir():
            raise GreyboxError(f"{target}: directory {target.parent} does not exist")


def _row(name: str, label: str, width: int, m) -> str:
    return f"  {name:<24} {label:<{width}} {m['n']:>8d} {m['rmse']:>10.4g} {m['re']:>7.2f} {m['nmse']:>8.2f}"


def _print_records(records, unit: str, run_names) -> None:
    """Per model: one row per test log (when there are several), then the pooled rows per regime, then those inside
    and outside the model's training region (a model whose file records it)."""
    per_log = len(run_names) > 1
    labels = [f"log {name}" for name in run_names] if per_log else []
    width = max([14, *map(len, labels), *(len(name) for record in records for name in record["regimes"])])
    rows = "log / regime" if per_log else "regime"
    print(f"  {'model':<24} {rows:<{width}} {'samples':>8} {'RMSE ' + unit:>10} {'RE %':>7} {'NMSE %':>8}")
    for record in records:
        name = record["model"][-24:]
        if per_log:
            for label, log in zip(labels, run_names):
                print(_row(name, label, width, record["per_log"][log]))
                name = ""
        for regime in REGIME_NAMES + tuple(name for name in TRAINING_REGION_NAMES if name in record["regimes"]):
            label = "all (pooled)" if per_log and regime == "all" else regime
            print(_row(name, label, width, record["regimes"][regime]))
            name = ""
    print(f"  ({RE_NOTE})")


def run(args: argparse.Namespace) -> int:
    _check_outputs(args)
    names = _model_names(args.models)
    loaded = dict(zip(names, (load_model(path, records=True) for path in args.models)))
    models = {name: model for name, (model, _) in loaded.items()}
    runs, run_names = read_named_runs(args, args.test, _model_names(args.test))
    for name, (_, records) in loaded.items():
        for path in dict.fromkeys(args.test):
            warn_preparation(records, args, [run for run in runs if run.source == str(path)] or runs,
                             Path(path).name, name)
    units = dict.fromkeys(run.effort_unit for run in runs)
    if len(units) > 1:
        listed = ", ".join(f"{name} in {run.effort_unit}" for name, run in zip(run_names, runs))
        raise GreyboxError(f"--test: the logs carry effort in different units ({listed}); evaluate them apart")
    quantity = check_one_effort(runs, "--test: the logs", "evaluate them apart")  # a current and a motor torque
    for name, (model, records) in loaded.items():
        if model_quantity(records, model) != quantity:
            trained = model_quantity(records, model)
            raise GreyboxError(f"{name} was trained on a {trained} [{EFFORT_UNITS[trained]}], the --test logs carry "
                               f"a {quantity} [{EFFORT_UNITS[quantity]}]; evaluate it on logs of its quantity "
                               "(greybox predict --axis-config converts a current and a motor torque)")
    unit = EFFORT_UNITS[quantity]
    records, predictions = evaluate_models(models, runs, run_names)
    print(f"evaluated {len(models)} model(s) on {len(runs)} log(s), {sum(len(r) for r in runs)} samples, "
          f"effort in {unit}")
    _print_records(records, unit, run_names)
    if args.json:
        path = write_text_atomic(args.json, records_json(records))
        print(f"wrote {path}")
    if args.out and Path(args.out).suffix.lower() == ".pdf":
        print(f"wrote {write_evaluation_pdf(args.out, records, predictions, runs, run_names)}")
    elif args.out:
        files = write_evaluation_report(args.out, records, predictions, runs, run_names)
        print(f"wrote {files['html']}")
    return 0
