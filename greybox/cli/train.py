"""``greybox train``: fit a current model to logs and save it to a model file."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from ..atomic import check_output_path
from ..data.effort import effort_text
from ..errors import GreyboxError, ModelFileError
from ..identify.intervals import METHODS as INTERVAL_METHODS
from ..models.registry import MODEL_CLASSES
from ..train.candidates import DEFAULT_CANDIDATES
from ._build import add_model_arguments, build_model
from ._model_text import model_lines
from ._options import add_log_arguments, read_options
from ._types import POSITIVE_INT


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "train",
        description="Read and prepare every training log as a separate run, fit the model to all runs, "
        "print the training error and the identified parameters, and save the model file. With --axes (or "
        "--machine), fit one model per axis of logs that hold several axes and write a machine model: a "
        "directory with one model file per axis and a manifest machine.json. With --per-machine, train one model "
        "per machine (the folder of its logs) and axis, on Dask.",
    )
    parser.add_argument("--model", required=True, choices=sorted(MODEL_CLASSES) + [AUTO],
                        help="model kind; 'auto' fits the candidates of --candidates, scores each on the training "
                        "logs it was not fitted on (leave one log out; one log: three stretches held out in turn) "
                        "and keeps the one that predicts them best, the simpler within one standard error")
    parser.add_argument("--candidates", nargs="+", metavar="KIND[:OPTION,...]",
                        help="with --model auto: the candidates, e.g. gms:asymmetric stribeck:offset,backlash "
                        "(options asymmetric, offset, backlash, elements=N, inertia=J; default: "
                        f"{' '.join(DEFAULT_CANDIDATES)})")
    parser.add_argument(
        "--train", required=True, nargs="+", metavar="LOG",
        help="training logs (CSV, Parquet, MCAP, TDMS or MATLAB .mat); with --per-machine also directories "
        "(searched recursively) and glob patterns"
    )
    parser.add_argument(
        "--stage2",
        nargs="+",
        metavar="LOG",
        help="gmssvr only: logs for the SVR stage; the GMS stage is then fitted on --train alone",
    )
    parser.add_argument("--out", required=True, metavar="MODEL",
                        help="model file to write (.gbm); with --axes or --machine, the machine model's directory; "
                        "with --per-machine, the directory of the models OUT/<machine>/<axis>.gbm")
    parser.add_argument("--axes", nargs="+", metavar="AXIS",
                        help="axes to fit (X Y Z, or X,Y,Z): one model each, from the logs' columns "
                        "X_position_mm, X_current_A, ... (MCAP channels /axis/X, TDMS groups X; default with "
                        "--machine: all its axes)")
    parser.add_argument("--machine", metavar="TOML",
                        help="machine file: the axes, their channels in the logs and mechanics (see "
                        "examples/machine.toml)")
    parser.add_argument("--axis-config", metavar="TOML",
                        help="axis file with the axis's inertia (inertia_kg_m2 at the motor shaft, see "
                        "examples/axis_x.toml): an identified inertia more than a factor 2 from it is noted in the "
                        "output and the model file; --model auto fits every candidate with it as the known inertia "
                        "(unless --inertia or --load-side is given). With --machine, the machine file's axes give it")
    parser.add_argument("--force", action="store_true",
                        help="overwrite MODEL (the machine model) if it exists; with --per-machine, train every "
                        "model again, also those complete from an earlier run")
    add_model_arguments(parser, backlash=True, offset_default=True)
    parser.add_argument("--quiet", action="store_true", help="no progress display during the identification")
    parser.add_argument("--intervals", choices=INTERVAL_METHODS, default="sandwich",
                        help="95 %% intervals of the identified parameters, stored in the model file and printed "
                        "with them: 'sandwich' (default) a cluster-robust linearisation over runs or time blocks, "
                        "'bootstrap' a wild cluster bootstrap refitting the model --bootstrap times (slow), 'none' "
                        "(see docs/intervals.md)")
    parser.add_argument("--bootstrap", type=POSITIVE_INT, metavar="N",
                        help="replicates of --intervals bootstrap (default 100)")
    fleet = parser.add_argument_group("fleets (one model per machine)")
    fleet.add_argument("--per-machine", action="store_true",
                       help="train one model per machine and axis, each on all that machine's logs (the machine of "
                       "a log is its folder's name; with --axes a model per axis of logs of several), one task each "
                       "on Dask; --out is a directory OUT/<machine>/<axis>.gbm with OUT/_manifest.json; a re-run "
                       "skips the models complete for the same logs and options; 'greybox predict OUT LOG... --out "
                       "DIR' then predicts each log with its machine's model")
    fleet.add_argument("--scheduler", metavar="ADDRESS",
                       help="with --per-machine: address of a running dask.distributed scheduler, e.g. "
                       "tcp://10.0.0.5:8786 (default: a local cluster of processes)")
    fleet.add_argument("--workers", type=POSITIVE_INT, metavar="N",
                       help="with --per-machine: processes of the local cluster (default: one per core); with "
                       "--model auto: processes fitting the candidates (default: one per core)")
    add_log_arguments(parser)
    parser.set_defaults(run=run)


def _check_interval_options(args: argparse.Namespace) -> None:
    """Refuse --bootstrap without --intervals bootstrap, or with fewer than 2 replicates."""
    if args.bootstrap is not None and args.intervals != "bootstrap":
        raise GreyboxError("--bootstrap N applies with --intervals bootstrap")
    if args.bootstrap is not None and args.bootstrap < 2:
        raise GreyboxError(f"--bootstrap {args.bootstrap}: a bootstrap needs at least 2 replicates")


def _notify(line: str) -> None:
    print(line, file=sys.stderr)


def _training_options(args: argparse.Namespace) -> dict:
    """The options every variant of :mod:`greybox.train` takes, as given on the command line."""
    _check_interval_options(args)
    return {"read": read_options(args), "intervals": args.intervals, "n_bootstrap": args.bootstrap,
            "overwrite": args.force, "report": print, "notify": _notify}


def _machine_axes(args: argparse.Namespace) -> tuple[str, list]:
    """The machine's name and the axes to fit (:class:`~greybox.data.machine_config.MachineAxis`)."""
    from ..data.machine_config import MachineAxis, read_machine_config

    if args.columns:
        raise GreyboxError("--columns does not apply with --axes or --machine: an axis's columns are named "
                           "X_position_mm, ... or mapped in the machine file's [axes.X.channels]")
    if args.axis:
        raise GreyboxError("give the axes to fit with --axes A,B,... (--axis reads one axis into one model file)")
    machine = read_machine_config(args.machine) if args.machine else None
    names = [name.strip() for group in (args.axes or []) for name in group.split(",") if name.strip()]
    if args.axes is not None and not names:
        raise GreyboxError(f"--axes names no axis: {' '.join(args.axes)!r}")
    if len(set(names)) != len(names):
        raise GreyboxError(f"--axes names an axis twice: {' '.join(args.axes)}")
    if machine is None:
        return "", [MachineAxis(name, "linear") for name in names]
    return machine.name, [machine.axis(name) for name in (names or list(machine.axes))]


def _print_fit(model, elapsed: float, label: str) -> None:
    """Print the training error per run (from the model's training record) and the parameters."""
    record = model.training_record_
    total = record["training_error"]
    quantity = total["quantity"]

    def row(name: str, figures: dict) -> str:
        re = "-" if figures["re_percent"] is None else f"{figures['re_percent']:.3f}"
        return f"  {name:<32} {figures['samples']:>8d} {figures['rmse']:>10.4g} {re:>7}"

    print(f"trained {label} on {len(record['runs'])} run(s), {total['samples']} samples, "
          f"effort in {effort_text(quantity)}, in {elapsed:.1f} s")
    print(f"  {'run':<32} {'samples':>8} {'RMSE ' + total['unit']:>10} {'RE %':>7}")
    for run in record["runs"]:
        print(row(Path(run["name"]).name[-32:], run))
    if len(record["runs"]) > 1:
        print(row("all runs", total))
    print("  (RE = RMSE / mean |effort|)")
    print("\n".join(model_lines(model, quantity=quantity)))


def _run_machine(args: argparse.Namespace) -> int:
    from ..models.machine import MANIFEST
    from ..train import train_machine_logs

    name, axes = _machine_axes(args)
    model = build_model(args.model, args)  # a bad option is one error before any log is read
    machine = train_machine_logs(model, args.train, axes, name=name, stage2=args.stage2 or (),
                                 out=args.out, progress=None if args.quiet else True,
                                 on_fit=lambda axis, fitted, seconds: _print_fit(fitted, seconds,
                                                                                 f"{args.model} for axis {axis}"),
                                 **_training_options(args))
    for axis in machine.axes:
        print(f"wrote {Path(args.out) / f'{axis}.gbm'}")
    print(f"wrote {Path(args.out) / MANIFEST}")
    return 0


def _label(entry: dict) -> str:
    """``machine/axis`` of a fleet's model (the machine alone while its axis is not known)."""
    return "/".join(part for part in (entry["machine"], entry.get("axis") or entry["read"].get("axis")) if part)


def _run_per_machine(args: argparse.Namespace) -> int:
    """``greybox train --per-machine``: a model per machine and axis on Dask (:mod:`greybox.fleet.train`)."""
    from ..fleet.train import train_fleet
    from ..models.plant import MANIFEST
    from ._fleet import fleet_progress, report_fleet

    if args.intervals != "sandwich" or args.bootstrap is not None:
        raise GreyboxError("--intervals and --bootstrap do not apply with --per-machine: a fleet's models get the "
                           "sandwich intervals")
    for option, value in (("--stage2", args.stage2), ("--machine", args.machine), ("--axis-config", args.axis_config)):
        if value:
            raise GreyboxError(f"{option} does not apply with --per-machine: every machine's model is fitted on "
                               "its logs in --train (give the axes of logs of several with --axes)")
    axes = [axis.name for axis in _machine_axes(args)[1]] if args.axes is not None else None
    model = build_model(args.model, args)  # a bad option is one error before any cluster starts
    out, manifest = train_fleet(model, args.train, out=args.out, axes=axes, read=read_options(args),
                                scheduler=args.scheduler, workers=args.workers, force=args.force,
                                progress=fleet_progress("models", args.quiet, _label))
    status = report_fleet(manifest, "models", "trained", lambda entry: f"{_label(entry)}: {entry['error']}")
    for entry in manifest["models"]:
        if entry["status"] != "failed":
            print(f"  {_label(entry)}: {len(entry['logs'])} log(s), {entry['samples']} samples, training RMSE "
                  f"{entry['rmse']:.4g} {entry['effort_unit']}, RE {entry['re']:.3f} % ({entry['status']}) "
                  f"-> {out / entry['output']}")
    print("  (RE = RMSE / mean |effort|)")
    print(f"wrote {out / MANIFEST}; predict each machine's logs with its model: greybox predict {args.out} LOG... "
          "--out DIR")
    return status


def _refuse_fleet_items(items) -> None:
    """A directory or pattern in --train asks for --per-machine (one model is trained on named log files)."""
    for item in items:
        if os.path.isdir(item) or (not os.path.exists(item) and set("*?[") & set(item)):
            raise GreyboxError(f"--train {item}: a directory or pattern; name the log files to train one model, "
                               "or give --per-machine to train one model per machine")


#: The ``--model`` value that chooses the model by cross-validation.
AUTO = "auto"


def _run_auto(args: argparse.Namespace) -> int:
    """``greybox train --model auto``: choose the model by held-out runs, save it with the table."""
    from ..train import train_auto_logs

    for option, value in (("--per-machine", args.per_machine), ("--axes", args.axes), ("--machine", args.machine),
                          ("--stage2", args.stage2), ("--asymmetric", args.asymmetric), ("--offset", args.offset),
                          ("--elements", args.elements), ("--backlash", args.backlash), ("--set", args.set)):
        if value:
            raise GreyboxError(f"{option} does not apply with --model auto: write a candidate's options into "
                               "--candidates, e.g. --candidates gms:asymmetric,backlash stribeck:offset")
    started = time.perf_counter()
    progress = None if args.quiet else (lambda line: print(f"  {line}", file=sys.stderr, flush=True))
    model = train_auto_logs(args.train, candidates=args.candidates or DEFAULT_CANDIDATES, inertia=args.model_inertia,
                            axis_config=args.axis_config, workers=args.workers, out=args.out, progress=progress,
                            **_training_options(args))
    _print_fit(model, time.perf_counter() - started, f"{model.selection_['chosen']} (chosen by held-out runs)")
    print(f"wrote {args.out}")
    return 0


def run(args: argparse.Namespace) -> int:
    from ..train import train_logs

    if args.model == AUTO:
        return _run_auto(args)
    if args.candidates:
        raise GreyboxError("--candidates applies with --model auto")
    if args.per_machine:
        return _run_per_machine(args)
    if args.scheduler or args.workers:
        raise GreyboxError("--scheduler and --workers apply with --per-machine (a model per machine on Dask)")
    _refuse_fleet_items(args.train)
    inputs = list(args.train) + list(args.stage2 or ())
    if args.axes is not None or args.machine:
        if args.axis_config:
            raise GreyboxError("--axis-config does not apply with --axes or --machine: give each axis's "
                               "inertia_kg_m2 in the machine file's [axes.NAME] table")
        out = Path(args.out)
        if any(out.resolve() == Path(path).resolve() for path in inputs):
            raise ModelFileError(f"{out}: is one of the training logs; choose another output directory")
        return _run_machine(args)
    options = _training_options(args)
    check_output_path(args.out, overwrite=args.force, protect=inputs, error=ModelFileError,
                      inputs_name="one of the training logs")  # before the model's options: as every command
    model = build_model(args.model, args)
    started = time.perf_counter()
    model = train_logs(model, args.train, stage2=args.stage2 or (), axis_config=args.axis_config, out=args.out,
                       progress=None if args.quiet else True, **options)
    _print_fit(model, time.perf_counter() - started, args.model)
    print(f"wrote {args.out}")
    return 0
