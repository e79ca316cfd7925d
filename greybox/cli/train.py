"""``greybox train``: fit a current model to logs and save it to a model file."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from ..atomic import check_output_path
from ..data.effort import (
    EFFORT_UNITS,
    check_effort_measured,
    check_one_axis,
    check_one_effort,
    effort_quantity,
    effort_text,
)
from ..errors import GreyboxError, ModelFileError
from ..identify.intervals import METHODS as INTERVAL_METHODS
from ..identify.intervals import attach_intervals
from ..metrics import metrics_table
from ..model_choice import DEFAULT_CANDIDATES
from ..models.registry import MODEL_CLASSES
from ..persistence import save_verified
from ._advice import offset_note
from ._build import add_model_arguments, build_model, takes_hyperparameter
from ._model_text import model_lines
from ._options import add_log_arguments, read_named_runs
from ._provenance import record_training
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


def _read(args: argparse.Namespace, paths, axis=None) -> tuple[list[str], list]:
    """The runs of ``paths`` (of one axis of a machine: its channels from the machine file) and a name per run."""
    if axis is None:
        runs, names = read_named_runs(args, paths, list(paths))
        return names, runs
    from ._options import read_runs

    columns = dict(axis.channels) or None
    runs, names = [], []
    for path in paths:
        pieces = read_runs(args, path, columns=columns, axis=axis.name)
        runs += pieces
        names += [path] * len(pieces)
    return names, runs


def _read_all(args: argparse.Namespace, axis=None) -> tuple[list, list, list]:
    """The names and runs of --train, and the runs of --stage2 (of one axis of a machine)."""
    names, runs = _read(args, args.train, axis)
    second_names, second = _read(args, args.stage2, axis) if args.stage2 else ([], [])
    check_one_effort(runs + second)  # before any fit: a model of a current and a torque at once is neither
    check_one_axis(runs + second)  # nor is a model of two axes
    check_effort_measured(runs + second)
    return names + second_names, runs, second


def _fit(model, args: argparse.Namespace, names, runs, second):
    """Fit ``model`` as the options say; return the names and runs it was fitted on."""
    progress = None if args.quiet else True
    _check_interval_options(args)
    if args.stage2 and model.first_stage() is None:
        raise GreyboxError(f"option --stage2 does not apply to the {args.model} model: it has one stage")
    if not args.stage2:
        model.fit(runs, progress=progress)
    else:
        model.fit_staged(runs, second, progress=progress)
    _intervals(model, args, runs)
    return names, runs + second


def _check_interval_options(args: argparse.Namespace) -> None:
    """Refuse --bootstrap without --intervals bootstrap, or with fewer than 2 replicates."""
    if args.bootstrap is not None and args.intervals != "bootstrap":
        raise GreyboxError("--bootstrap N applies with --intervals bootstrap")
    if args.bootstrap is not None and args.bootstrap < 2:
        raise GreyboxError(f"--bootstrap {args.bootstrap}: a bootstrap needs at least 2 replicates")


def _intervals(model, args: argparse.Namespace, runs) -> None:
    """Attach the parameter intervals --intervals asks for (of the runs the model, or its first stage, saw)."""
    if args.intervals != "none":
        started = time.perf_counter()
        attach_intervals(model, runs, method=args.intervals, n_bootstrap=args.bootstrap or 100)
        record = model.parameter_intervals_
        print(f"95 % intervals by {args.intervals} over {record['n_clusters']} {record['clusters']} "
              f"in {time.perf_counter() - started:.1f} s")


def _axis_inertia(config, runs, source: str) -> tuple[float | None, str]:
    """The inertia an axis configuration gives, in the effort unit of ``runs`` [effort s^2/length], and ``source``."""
    if config is None or not runs:
        return None, ""
    return config.model_inertia(runs[0].effort_unit), source


def _read_axis_inertia(args: argparse.Namespace, runs) -> tuple[float | None, str]:
    """The inertia of --axis-config for ``runs`` and its source; (None, "") without the option."""
    if not args.axis_config:
        return None, ""
    from ..data.axis_config import INERTIA, read_axis_config

    config = read_axis_config(args.axis_config)
    if config.inertia_kg_m2 is None:
        raise GreyboxError(f"{args.axis_config}: gives no {INERTIA}, the axis's inertia at the motor shaft that "
                           "--axis-config of greybox train checks the model against")
    return _axis_inertia(config, runs, f"the axis file {Path(args.axis_config).name}")


def _check_inertia(model, expected: float | None, source: str) -> None:
    """Note on the model (and so in its output and file) an identified inertia that disagrees with ``expected``."""
    if expected is not None:
        model.check_axis_inertia(expected, source)


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


def _report_fit(model, names, runs, elapsed: float, label: str) -> list:
    """Print the training error per run and the parameters; return the predictions."""
    quantity = effort_quantity(runs[0])
    unit = EFFORT_UNITS[quantity]
    print(f"trained {label} on {len(runs)} run(s), {sum(len(r) for r in runs)} samples, "
          f"effort in {effort_text(quantity)}, in {elapsed:.1f} s")
    print(f"  {'run':<32} {'samples':>8} {'RMSE ' + unit:>10} {'RE %':>7}")
    predictions = [model.predict(run) for run in runs]
    for path, run, prediction in zip(names, runs, predictions):
        table = metrics_table(run.effort, prediction)
        print(f"  {Path(path).name[-32:]:<32} {table['n']:>8d} {table['rmse']:>10.4g} {table['re']:>7.3f}")
    if len(runs) > 1:
        table = metrics_table(np.concatenate([r.effort for r in runs]), np.concatenate(predictions))
        print(f"  {'all runs':<32} {table['n']:>8d} {table['rmse']:>10.4g} {table['re']:>7.3f}")
    print("  (RE = RMSE / mean |effort|)")
    print("\n".join(model_lines(model, quantity=quantity)))
    if takes_hyperparameter(model, "fit_offset"):
        offset_note([run.effort for run in runs], predictions, unit)
    return predictions


def _run_machine(args: argparse.Namespace) -> int:
    from ..machine_model import MachineModel, check_machine_output, save_machine

    name, axes = _machine_axes(args)
    check_machine_output(args.out, [axis.name for axis in axes], overwrite=args.force)
    data = {axis.name: _read_all(args, axis) for axis in axes}  # every axis read before any training
    models, predictions, records = {}, {}, {}
    for axis in axes:
        model = build_model(args.model, args)
        started = time.perf_counter()
        names, runs = _fit(model, args, *data[axis.name])
        _check_inertia(model, *_axis_inertia(axis.config, runs, f"axis {axis.name} of the machine file"))
        predictions[axis.name] = (runs, _report_fit(model, names, runs, time.perf_counter() - started,
                                                    f"{args.model} for axis {axis.name}"))
        records[axis.name] = record_training(args, list(args.train) + list(args.stage2 or ()), names, runs,
                                             predictions[axis.name][1])
        models[axis.name] = model
    written = save_machine(MachineModel(models=models, name=name), args.out, overwrite=args.force, records=records,
                           verify=predictions)
    for path in written:
        print(f"wrote {path}")
    return 0


def _label(entry: dict) -> str:
    """``machine/axis`` of a fleet's model (the machine alone while its axis is not known)."""
    return "/".join(part for part in (entry["machine"], entry.get("axis") or entry["read"].get("axis")) if part)


def _run_per_machine(args: argparse.Namespace) -> int:
    """``greybox train --per-machine``: a model per machine and axis on Dask (:mod:`greybox.fleet_train`)."""
    from ..fleet import MANIFEST, expand_logs
    from ..fleet_train import run_training, train_jobs
    from ._fleet import check_out_dir, fleet_progress, read_options, report_fleet

    if args.intervals != "sandwich" or args.bootstrap is not None:
        raise GreyboxError("--intervals and --bootstrap do not apply with --per-machine: a fleet's models get the "
                           "sandwich intervals")
    for option, value in (("--stage2", args.stage2), ("--machine", args.machine), ("--axis-config", args.axis_config)):
        if value:
            raise GreyboxError(f"{option} does not apply with --per-machine: every machine's model is fitted on "
                               "its logs in --train (give the axes of logs of several with --axes)")
    axes = [axis.name for axis in _machine_axes(args)[1]] if args.axes is not None else None
    out = check_out_dir(args.out, args.train)
    logs = expand_logs(args.train, exclude=[out])
    model = build_model(args.model, args)  # a bad option is one error before any cluster starts
    jobs = train_jobs(logs, model, str(out), axes=axes, read=read_options(args))
    manifest = run_training(jobs, scheduler=args.scheduler, workers=args.workers, force=args.force,
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
    from ..model_choice import choose_model

    for option, value in (("--per-machine", args.per_machine), ("--axes", args.axes), ("--machine", args.machine),
                          ("--stage2", args.stage2), ("--asymmetric", args.asymmetric), ("--offset", args.offset),
                          ("--elements", args.elements), ("--backlash", args.backlash), ("--set", args.set)):
        if value:
            raise GreyboxError(f"{option} does not apply with --model auto: write a candidate's options into "
                               "--candidates, e.g. --candidates gms:asymmetric,backlash stribeck:offset")
    _check_interval_options(args)
    out = Path(args.out)
    check_output_path(out, overwrite=args.force, protect=list(args.train), error=ModelFileError,
                      inputs_name="one of the training logs")
    runs, groups = [], []
    for path in args.train:
        pieces, _ = read_named_runs(args, [path], [path])
        runs += pieces
        groups += [str(path)] * len(pieces)
    check_one_effort(runs)
    check_one_axis(runs)
    check_effort_measured(runs)  # the held-out relative errors the choice compares would be undefined
    started = time.perf_counter()
    report = None if args.quiet else (lambda line: print(f"  {line}", file=sys.stderr, flush=True))
    inertia, source = _read_axis_inertia(args, runs)
    if args.model_inertia is not None:
        inertia = args.model_inertia  # --inertia or --load-side say more than the axis file
    elif inertia is not None:
        unit = f"{runs[0].effort_unit} s^2/{runs[0].units.length}"
        print(f"inertia J = {inertia:.4g} {unit} from {source}: every candidate is fitted with it")
    model = choose_model(runs, groups, candidates=args.candidates or DEFAULT_CANDIDATES, inertia=inertia,
                         workers=args.workers or os.cpu_count() or 1, progress=report)
    _intervals(model, args, runs)
    names = [Path(group).name for group in groups]
    predictions = _report_fit(model, names, runs, time.perf_counter() - started,
                              f"{model.selection_['chosen']} (chosen by held-out runs)")
    save_verified(model, out, runs, predictions=predictions, overwrite=args.force,
                  records=record_training(args, list(args.train), names, runs, predictions))
    print(f"wrote {out}")
    return 0


def run(args: argparse.Namespace) -> int:
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
    out = Path(args.out)
    check_output_path(out, overwrite=args.force, protect=inputs, error=ModelFileError,
                      inputs_name="one of the training logs")
    model = build_model(args.model, args)
    started = time.perf_counter()
    data = _read_all(args)
    expected, source = _read_axis_inertia(args, data[1])  # a bad axis file stops before the fit
    names, runs = _fit(model, args, *data)
    _check_inertia(model, expected, source)
    predictions = _report_fit(model, names, runs, time.perf_counter() - started, args.model)
    save_verified(model, out, runs, predictions=predictions, overwrite=args.force,
                  records=record_training(args, inputs, names, runs, predictions))
    print(f"wrote {out}")
    return 0
