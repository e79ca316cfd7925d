"""``greybox predict``: the process share of the current of a cutting log, and its force."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from ..errors import GreyboxError
from ._options import add_log_arguments
from ._provenance import align_effort, model_quantity, warn_preparation
from ._types import FRACTION, POSITIVE_INT, non_negative, positive
from ._window import add_window_argument, check_window

#: Nominal coverage of the bounds when --calibration is given without --interval.
DEFAULT_COVERAGE = 0.95

#: Output extensions accepted for the table and for the picture.
_PLOT_SUFFIXES = (".png", ".svg", ".pdf")


def add_parser(subparsers) -> None:
    from ..models.chunked import DEFAULT_CHUNK_S

    parser = subparsers.add_parser(
        "predict",
        help="process current (and force) of a cutting log from a model trained on air cuts",
        description="Run a model trained on air cuts over a log recorded while cutting and write, per "
        "sample, the measured current, the model current (inertia + friction) and the process current "
        "= measured - model; with --axis-config also the process force in N (torque in Nm for a rotary "
        "axis). The model runs over chunks "
        "of --chunk-s seconds carrying its state; a Parquet or MCAP log of a linear axis (without --plot, "
        "--resample, --sample-time) is read, prepared and written block by block, so its length does not "
        "bound the memory.",
    )
    parser.add_argument("model", metavar="MODEL",
                        help="model file written by 'greybox train' (.gbm), a machine model directory "
                        "('greybox train --axes'), or for a fleet run the models directory of 'greybox train "
                        "--per-machine' (each log predicted with its machine's model)")
    parser.add_argument("logs", nargs="+", metavar="LOG",
                        help="cutting log (CSV, Parquet, MCAP, TDMS or MATLAB .mat); several logs, directories "
                        "(searched recursively) or glob patterns make a fleet run: one task per log on Dask, "
                        "--out a directory of a Parquet dataset partitioned machine/axis/log with _manifest.json")
    parser.add_argument("--out", required=True, metavar="OUT",
                        help="table to write: .csv, .parquet or .mcap (CSV: plain, header first, metadata in "
                        "OUT.json beside it; MCAP: one message per sample, topic /process/<axis>)")
    parser.add_argument("--axis-config", metavar="TOML",
                        help="axis metadata (torque constant, screw lead, gear ratio, efficiency driving and "
                        "back-driven, channel names); adds force_process_N (torque_process_Nm for a rotary axis), "
                        "converted by the direction of the power flow (see examples/axis_x.toml, axis_c.toml; "
                        "'greybox examples' writes them)")
    parser.add_argument("--machine", metavar="TOML",
                        help="with a machine model (a directory written by 'greybox train --axes'): the machine "
                        "file with each axis's channels and mechanics (see examples/machine.toml); adds each "
                        "axis's force or torque and the resultant force of the linear axes")
    parser.add_argument("--calibration", nargs="+", metavar="AIRCUT",
                        help="air-cut logs the model was NOT trained on: its residuals there calibrate lower and "
                        "upper bounds of the process current (and force), split-conformal per regime (reversal, "
                        "acceleration, constant feed, other)")
    parser.add_argument("--interval", type=FRACTION, metavar="C",
                        help=f"nominal coverage of the bounds, a fraction in (0, 1) (default {DEFAULT_COVERAGE:g}; "
                        "needs --calibration)")
    parser.add_argument("--plot", metavar="PNG", help="also draw measured, model and process current (and force)")
    parser.add_argument("--plot-mean-s", type=non_negative("seconds"), default=0.1, metavar="S",
                        help="window of the moving mean drawn over the process current, in seconds (default "
                        "0.1; 0 draws none)")
    parser.add_argument("--chunk-s", type=positive("seconds"), default=DEFAULT_CHUNK_S, metavar="S",
                        help=f"chunk length in seconds (default {DEFAULT_CHUNK_S:g})")
    add_window_argument(parser, "--plot-window")
    parser.add_argument("--force", action="store_true", help="overwrite OUT (and OUT.json) and PNG if they exist")
    parser.add_argument("--quiet", action="store_true", help="no progress display (one line per chunk on stderr)")
    fleet = parser.add_argument_group("fleet runs (several logs)")
    fleet.add_argument("--scheduler", metavar="ADDRESS",
                       help="address of a running dask.distributed scheduler, e.g. tcp://10.0.0.5:8786 (default: a "
                       "local cluster of processes)")
    fleet.add_argument("--workers", type=POSITIVE_INT, metavar="N",
                       help="processes of the local cluster (default: one per core)")
    add_log_arguments(parser)
    parser.set_defaults(run=run)


def _read_runs(args: argparse.Namespace, channels: dict, path=None):
    """Read and prepare a log (the cutting log by default) into its runs; column mapping from the axis
    metadata, overridden by --columns."""
    from ..data.io import parse_column_mapping
    from ._options import read_runs

    columns = dict(channels)
    if args.columns:
        columns.update(parse_column_mapping(args.columns))
    return read_runs(args, path or args.log, columns=columns or None)


def _progress(total_s: float, quiet: bool):
    """Progress of the chunks on stderr, or None with --quiet: one line per chunk, updated in place on a terminal.

    Parameters
    ----------
    total_s : float
        Log time [s] at the last sample.
    quiet : bool
        The --quiet option.
    """
    if quiet:
        return None
    started = time.perf_counter()
    terminal = sys.stderr.isatty()

    def show(done: int, chunks: int, time_s: float) -> None:
        text = (f"predicting: chunk {done}/{chunks}, {time_s:.1f} of {total_s:.1f} s of log, "
                f"{time.perf_counter() - started:.1f} s elapsed")
        if terminal:
            print("\r" + text, end="\n" if done == chunks else "", file=sys.stderr, flush=True)
        else:
            print(text, file=sys.stderr, flush=True)

    return show


def _check_outputs(args: argparse.Namespace, inputs: list) -> tuple[Path, object]:
    """Refuse, before any work, outputs that must not or cannot be written; return the table path and window."""
    from ..evaluate.process_io import check_output_path, output_paths

    out = Path(args.out)
    for target in output_paths(out):  # the table, and for CSV its metadata sidecar
        check_output_path(target, overwrite=args.force, protect=inputs)
    if args.plot:
        plot = Path(args.plot)
        if plot.suffix.lower() not in _PLOT_SUFFIXES:
            raise GreyboxError(f"{plot}: unknown picture extension '{plot.suffix}'; use {', '.join(_PLOT_SUFFIXES)}")
        if plot.resolve() == out.resolve():
            raise GreyboxError(f"{plot}: --plot and --out name the same file")
        check_output_path(plot, overwrite=args.force, protect=inputs)
    elif args.plot_window is not None:
        raise GreyboxError("--plot-window needs --plot PNG")
    if args.calibration is None and args.interval is not None:
        raise GreyboxError("--interval needs --calibration AIRCUT... (air-cut logs the model was not trained on)")
    own = [path for path in args.calibration or () if Path(path).resolve() == Path(args.log).resolve()]
    if own:
        raise GreyboxError(f"--calibration: {own[0]} is the cutting log itself; calibrate on air cuts the "
                           "model was not trained on")
    return out


def _interval(args: argparse.Namespace, model, read):
    """The calibrated interval of ``model`` from the --calibration logs (``read(path)`` gives their runs)."""
    if not args.calibration:
        return None
    from ..evaluate.interval import calibrate_interval

    return calibrate_interval(model, [run for path in args.calibration for run in read(path)],
                              coverage=DEFAULT_COVERAGE if args.interval is None else args.interval,
                              chunk_s=args.chunk_s)


def _print_result(result, args: argparse.Namespace, interval, axis_file: str | None) -> None:
    """The console lines of one axis's result: effort, load, extrapolation and interval."""
    from ..evaluate.process import ProcessTally

    tally = ProcessTally()
    tally.add(result)
    _print_figures(tally, result.quantity, result.units, result.load_constants, result.attrs["extrapolation"],
                   args, interval, axis_file)


def _print_figures(tally, quantity: str, units, load_constants, extrapolation: dict, args: argparse.Namespace,
                   interval, axis_file: str | None) -> None:
    """The console lines of one axis's figures (a :class:`~greybox.evaluate.process.ProcessTally`); the load's
    figures leave out the samples at standstill (:attr:`~greybox.evaluate.process.ProcessResult.standstill`)."""
    from ..data.effort import EFFORT_UNITS

    noun, unit = quantity, EFFORT_UNITS[quantity]
    print(f"  {noun:<8} rms measured {tally.rms('measured'):.4g} {unit}, model {tally.rms('model'):.4g} "
          f"{unit}, process {tally.rms('process'):.4g} {unit}, largest |process| {tally.largest['process']:.4g} {unit}")
    if quantity in ("current", "motor torque") and load_constants is not None:
        driving, backdriven = load_constants
        per_ampere = f"{units.load_unit}/{unit}"
        factors = (f"{driving:.6g} {per_ampere}" if driving == backdriven
                   else f"{driving:.6g} {per_ampere} driving, {backdriven:.6g} {per_ampere} back-driven")
        standing = tally.n_samples - tally.n_moving
        where = f" of the {tally.n_moving} samples in motion (standstill left out)" if standing else ""
        print(f"  {units.load:<8} rms process {tally.rms('load_moving'):.4g} {units.load_unit}, "
              f"largest |process| {tally.largest['load_moving']:.4g} {units.load_unit}{where} "
              f"({factors} from {axis_file})")
    _report_extrapolation(extrapolation, Path(args.log).name)
    if interval is not None:
        from ..evaluate.interval import MIN_CLASS_SAMPLES

        widths = ", ".join(f"{name.replace('_', ' ')} {value:.3g}"
                           + ("" if interval.samples[name] >= MIN_CLASS_SAMPLES
                              else f" (pooled: {interval.samples[name]} samples)")
                           for name, value in interval.half_width_A.items())
        print(f"  interval {100 * interval.coverage:g} % (split conformal per regime on "
              f"{sum(interval.samples.values())} air-cut samples of {len(args.calibration)} log(s)): "
              f"half-width [{unit}] {widths}; mean {tally.half_width_sum / tally.n_samples:.3g} {unit}")


def _is_fleet(args: argparse.Namespace) -> bool:
    """Several logs, a directory or a pattern: a fleet run."""
    item = args.logs[0]
    return len(args.logs) > 1 or os.path.isdir(item) or any(ch in item for ch in "*?[")


def run(args: argparse.Namespace) -> int:
    from ..machine_model import is_machine_model

    if _is_fleet(args):
        return _run_fleet(args)
    if args.scheduler or args.workers:
        raise GreyboxError("--scheduler and --workers apply to fleet runs (several logs, a directory or a pattern)")
    args.log = args.logs[0]
    if is_machine_model(args.model):
        return _run_machine(args)
    if os.path.isdir(args.model):  # the models of 'greybox train --per-machine': the one of this log's machine
        from ..fleet import model_of_log

        args.model = model_of_log(args.model, args.log, args.axis)
        print(f"model of machine {Path(args.log).resolve().parent.name}: {args.model}")
    run_started = getattr(args, "started_s", None) or time.perf_counter()
    from ..data.axis_config import read_axis_config
    from ..evaluate.process import predict_process
    from ..models.chunked import chunk_slices, samples_per_chunk
    from ..persistence import load_model

    if args.machine:
        raise GreyboxError("--machine applies to a machine model (a directory written by 'greybox train --axes'); "
                           "give one axis's mechanics with --axis-config")
    inputs = [args.model, args.log] + ([args.axis_config] if args.axis_config else []) + list(args.calibration or [])
    out = _check_outputs(args, inputs)
    config = read_axis_config(args.axis_config) if args.axis_config else None
    model, records = load_model(args.model, records=True)
    streamed = _streamed_log(args, config)
    if streamed is not None and _first_quantity(streamed) != model_quantity(records, model):
        streamed = None  # read whole, to convert its effort (align_effort)
    if streamed is not None:
        warn_preparation(records, args, None, Path(args.log).name, Path(args.model).name)
    status = None if streamed is None else _run_streamed(args, model, streamed, config, out, inputs, run_started)
    if status is not None:
        return status
    runs = _read_runs(args, config.channels if config else {})
    runs = align_effort(records, model, runs, config, Path(args.log).name, Path(args.model).name)
    if streamed is None:
        warn_preparation(records, args, runs, Path(args.log).name, Path(args.model).name)
    log_time = np.concatenate([run.time for run in runs])
    window = check_window(args.plot_window, log_time, "--plot-window", Path(args.log).name)
    interval = _interval(args, model, lambda path: align_effort(
        records, model, _read_runs(args, config.channels if config else {}, path), config, Path(path).name,
        Path(args.model).name))
    started = time.perf_counter()
    result = predict_process(model, runs, axis_config=config, interval=interval, chunk_s=args.chunk_s,
                             progress=_progress(float(log_time[-1]), args.quiet))
    elapsed = time.perf_counter() - started
    result.attrs.update({"model_file": str(args.model), "log_file": str(args.log)})
    n_chunks = sum(len(chunk_slices(len(run), samples_per_chunk(run.sample_time, args.chunk_s))) for run in runs)
    duration = sum(run.duration for run in runs)
    print(f"predicted {Path(args.log).name} with the {result.attrs['model_kind']} model {Path(args.model).name}: "
          f"{len(result.time)} samples, {duration:.1f} s, {n_chunks} chunk(s) of {args.chunk_s:g} s"
          + (f" in {len(runs)} runs" if len(runs) > 1 else "")
          + (f", dataset {result.dataset}" if result.dataset else ""))
    _print_result(result, args, interval, Path(args.axis_config).name if args.axis_config else None)
    from ..evaluate.process_plot import plot_process

    _write_outputs(args, result, out, inputs, window, plot_process)
    print(_done_line(args, run_started, elapsed))
    return 0


def _done_line(args: argparse.Namespace, started: float, elapsed: float) -> str:
    """``done in 3.12 s wall (model 0.40 s)``: the wall time from ``started`` [s, perf_counter], which includes
    Python's start-up and the imports when greybox ran as a command of its own (then said so)."""
    startup = ", start-up included" if getattr(args, "startup_counted", False) else ""
    return f"done in {time.perf_counter() - started:.2f} s wall{startup} (model {elapsed:.2f} s)"


def _first_quantity(log) -> str:
    """What the effort of a log opened block by block is (:func:`~greybox.data.effort.effort_quantity`)."""
    from ..data.effort import effort_quantity

    return effort_quantity(next(iter(log.blocks(1))))


def _streamed_log(args: argparse.Namespace, config):
    """The cutting log opened block by block (:func:`~greybox.data.stream.open_stream`), or None to read it whole.

    A Parquet or MCAP log of a linear axis, without --resample, --sample-time and --plot, is streamed: its
    length then does not bound the memory (:mod:`greybox.data.stream`).
    """
    from ..data.io import parse_column_mapping
    from ..data.stream import open_stream

    if args.plot:
        return None
    columns = dict(config.channels if config else {})
    if args.columns:
        columns.update(parse_column_mapping(args.columns))
    return open_stream(args.log, columns=columns or None, topic=args.topic, axis=args.axis,
                       sample_time=args.sample_time, resample=args.resample)


def _run_streamed(args: argparse.Namespace, model, log, config, out: Path, inputs: list, run_started: float):
    """``greybox predict`` of a log read, predicted and written block by block; None if it cannot be streamed."""
    from ..data.blocks import CannotStream
    from ..data.quantities import MOTIONS
    from ..evaluate.process_stream import stream_process

    interval = _interval(args, model, lambda path: _read_runs(args, config.channels if config else {}, path))
    started = time.perf_counter()
    shown = []

    def progress(done: int, chunks: int, time_s: float) -> None:
        if not shown:  # the log's end is known once the time stamps have been read
            shown.append(_progress(log.time_span()[1], False))
        shown[0](done, chunks, time_s)

    try:
        done = stream_process(model, log, out, axis_config=config, interval=interval, chunk_s=args.chunk_s,
                              tolerance=args.time_tolerance, cutoff_hz=args.cutoff_hz,
                              attrs={"model_file": str(args.model), "log_file": str(args.log)},
                              overwrite=args.force, protect=inputs, progress=None if args.quiet else progress)
    except CannotStream:
        return None
    elapsed = time.perf_counter() - started
    attrs = done.metadata["attrs"]
    dataset = done.metadata["dataset"]
    print(f"predicted {Path(args.log).name} with the {attrs['model_kind']} model {Path(args.model).name}: "
          f"{done.tally.n_samples} samples, {done.duration:.1f} s, {done.n_chunks} chunk(s) of {args.chunk_s:g} s"
          + (f", dataset {dataset}" if dataset else "") + ", read and written block by block")
    if config is not None and attrs["effort"]["quantity"] == "motor torque":  # the effort is k_t I already
        config = config.without_torque_constant()
    load_constants = config.load_constants if config is not None and done.metadata["effort_unit"] == "A" else None
    _print_figures(done.tally, attrs["effort"]["quantity"], MOTIONS[done.motion], load_constants,
                   attrs["extrapolation"], args, interval, Path(args.axis_config).name if args.axis_config else None)
    from ..evaluate.process_io import output_paths

    for target in output_paths(out):
        print(f"wrote {target}")
    print(_done_line(args, run_started, elapsed))
    return 0


def _write_outputs(args: argparse.Namespace, result, out: Path, inputs: list, window, draw) -> None:
    """Write the table (atomically) and, with --plot, the picture ``draw`` makes of ``result``."""
    from ..evaluate.process_io import output_paths, write_process

    write_process(result, out, overwrite=args.force, protect=inputs)
    for target in output_paths(out):
        print(f"wrote {target}")
    if args.plot:
        draw(result, args.plot, mean_s=args.plot_mean_s, window=window)
        print(f"wrote {args.plot}")


def _run_fleet(args: argparse.Namespace) -> int:
    """``greybox predict MODEL LOG... --out DIR``: every log a task on Dask, a partitioned Parquet dataset.

    MODEL is one model file, or a directory written by ``greybox train --per-machine``: each log is then
    predicted with its machine's model."""
    from ..fleet import MANIFEST, expand_logs, fleet_jobs, run_fleet
    from ..machine_model import is_machine_model
    from ..persistence import load_model
    from ._fleet import check_out_dir, fleet_progress, read_options, report_fleet

    for option, value in (("--plot", args.plot), ("--plot-window", args.plot_window),
                          ("--calibration", args.calibration), ("--interval", args.interval),
                          ("--machine", args.machine)):
        if value is not None:
            raise GreyboxError(f"{option} applies to one log; a fleet run (several logs) writes the process tables")
    if is_machine_model(args.model):
        raise GreyboxError(f"{args.model}: a fleet run takes one model file; run one fleet per axis of the machine "
                           "model with its file and --axis")
    out = check_out_dir(args.out)
    jobs = fleet_jobs(expand_logs(args.logs), str(Path(args.model).resolve()), str(out),
                      axis_config=str(Path(args.axis_config).resolve()) if args.axis_config else None,
                      read=read_options(args), chunk_s=args.chunk_s)
    for model in sorted({job.model for job in jobs}):
        load_model(model)  # a bad model file is one error before any cluster starts
    manifest = run_fleet(jobs, scheduler=args.scheduler, workers=args.workers, force=args.force,
                         progress=fleet_progress("logs", args.quiet, lambda entry: Path(entry["log"]).name))
    status = report_fleet(manifest, "logs", "predicted", lambda entry: entry["error"])
    print(f"wrote {out / MANIFEST} and the dataset {out}/machine=*/axis=*/log=*/part-0.parquet")
    return status


def _run_machine(args: argparse.Namespace) -> int:
    """``greybox predict`` with a machine model: every axis of the log, and the resultant force."""
    run_started = getattr(args, "started_s", None) or time.perf_counter()
    from ..data.machine_config import read_machine_config
    from ..evaluate.machine_process import RESULTANT_COLUMN, predict_machine
    from ..machine_model import load_machine
    from ._options import read_runs

    for option, value in (("--axis-config", args.axis_config), ("--columns", args.columns), ("--axis", args.axis)):
        if value:
            raise GreyboxError(f"{option} does not apply to a machine model ({args.model}): it predicts every axis "
                               "of the log; give the axes' channels and mechanics with --machine TOML")
    inputs = [args.model, args.log] + ([args.machine] if args.machine else []) + list(args.calibration or [])
    out = _check_outputs(args, inputs)
    machine = load_machine(args.model)
    config = read_machine_config(args.machine) if args.machine else None
    missing = [name for name in machine.axes if config is not None and name not in config.axes]
    if missing:
        raise GreyboxError(f"{args.machine}: no [axes.{missing[0]}] table; the machine model {args.model} has axes "
                           f"{', '.join(machine.axes)}, the machine file {', '.join(config.axes)}")
    described = {name: config.axis(name) for name in machine.axes} if config else {}

    def read(path, name):
        channels = dict(described[name].channels) if name in described else {}
        return read_runs(args, path, columns=channels or None, axis=name)

    runs = {name: read(args.log, name) for name in machine.axes}
    from ..persistence import load_model

    for name in machine.axes:  # each axis's model file, its training record against the log's preparation
        records = load_model(Path(args.model) / f"{name}.gbm", records=True)[1]
        runs[name] = align_effort(records, machine.models[name], runs[name],
                                  described[name].config if name in described else None,
                                  f"{Path(args.log).name} (axis {name})", f"{name}.gbm")
        warn_preparation(records, args, runs[name], f"{Path(args.log).name} (axis {name})", f"{name}.gbm")
    log_time = np.concatenate([run.time for run in runs[machine.axes[0]]])
    window = check_window(args.plot_window, log_time, "--plot-window", Path(args.log).name)
    intervals = {name: _interval(args, machine.models[name], lambda path, name=name: read(path, name))
                 for name in machine.axes}
    started = time.perf_counter()
    result = predict_machine(machine.models, runs,
                             axis_configs={name: axis.config for name, axis in described.items()},
                             intervals=intervals, name=machine.name, chunk_s=args.chunk_s,
                             progress=None if args.quiet else
                             (lambda name: _progress(float(runs[name][-1].time[-1]), False)))
    elapsed = time.perf_counter() - started
    result.attrs.update({"model_dir": str(args.model), "log_file": str(args.log)})
    kinds = ", ".join(f"{name}: {axis_result.attrs['model_kind']}" for name, axis_result in result.results.items())
    print(f"predicted {Path(args.log).name} with the machine model {Path(args.model).name} ({kinds}): "
          f"{len(result.time)} samples" + (f", dataset {result.dataset}" if result.dataset else ""))
    for name, axis_result in result.results.items():
        print(f"axis {name}:")
        _print_result(axis_result, args, intervals[name],
                      Path(args.machine).name if name in described and described[name].config else None)
    if result.attrs["interpolated_axes"]:
        print(f"  axes {', '.join(result.attrs['interpolated_axes'])} interpolated onto the time stamps of axis "
              f"{result.attrs['time_of']}")
    resultant = result.resultant()
    if resultant is not None:
        print(f"resultant process force of axes {', '.join(result.forces())}: rms {_rms(resultant):.4g} N, "
              f"largest {np.max(resultant):.4g} N (column {RESULTANT_COLUMN})")
    from ..evaluate.process_plot import plot_machine_process

    _write_outputs(args, result, out, inputs, window, plot_machine_process)
    print(_done_line(args, run_started, elapsed))
    return 0


def _report_extrapolation(summary: dict, log_name: str) -> None:
    """One line on the share of samples outside the training region; a note on stderr above the limit."""
    if summary["share"] is None:
        print(f"  outside the training region: not known ({summary['reason']})")
        return
    parts = ", ".join(f"{name} {100 * share:.1f} %" for name, share in summary["by"].items())
    print(f"  outside the training region: {100 * summary['share']:.1f} % of the samples ({parts})")
    standstill = summary["by"].get("standstill", 0.0)
    if standstill > 0.0:
        print(f"note: {log_name}: {100 * standstill:.1f} % of the samples are at standstill, where a memoryless "
              "model cannot know the friction the drive holds (flagged in the column standstill and left out of "
              "the process force figures); gms, lugre and gmssvr carry it from the last motion", file=sys.stderr)
    beyond = max([share for name, share in summary["by"].items() if name != "standstill"] or [0.0])
    if summary["share"] > summary["warn_above"] and beyond > 0.0:
        print(f"note: {log_name}: {100 * summary['share']:.1f} % of the samples lie outside the positions, speeds "
              f"or inputs the model was trained on (more than {100 * summary['warn_above']:g} %): the model "
              "extrapolates there (column outside_training); train on air cuts that cover the cutting programme, "
              "or check the units of position and velocity (--columns)",
              file=sys.stderr)


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(values))))
