"""``greybox predict``: the process share of the current of a cutting log, and its force."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ._options import add_log_arguments
from ._types import FRACTION, POSITIVE_INT, non_negative, positive
from ._window import add_window_argument


def add_parser(subparsers) -> None:
    from ..models.chunked import DEFAULT_CHUNK_S
    from ..predict.interval import DEFAULT_COVERAGE

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
    parser.add_argument("--relevel", action="store_true",
                        help="scale the model's current per chunk (--chunk-s) and direction of motion to the log's "
                        "air moves, found in the log: a friction changed since training (warm-up) leaves the "
                        "process current (off by default: it adds the scale's noise, docs/predict.md)")
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


def run(args: argparse.Namespace) -> int:
    """``greybox predict``: :func:`greybox.predict.predict_logs` with the options (a fleet run:
    :func:`greybox.fleet.predict.predict_fleet`), its report printed."""
    from ..fleet.predict import predict_fleet
    from ..predict import predict_logs
    from ..predict.run import is_fleet
    from ._fleet import fleet_progress
    from ._options import read_options

    run_started = getattr(args, "started_s", None) or time.perf_counter()
    options = dict(out=args.out, axis_config=args.axis_config, machine=args.machine, calibration=args.calibration,
                   coverage=args.interval, plot=args.plot, plot_window=args.plot_window, chunk_s=args.chunk_s,
                   read=read_options(args), force=args.force, scheduler=args.scheduler, workers=args.workers,
                   relevel=args.relevel)
    if is_fleet(args.logs):
        done = predict_fleet(args.model, args.logs, **options,
                             progress=fleet_progress("logs", args.quiet, lambda entry: Path(entry["log"]).name))
    else:
        done = predict_logs(args.model, args.logs, **options, plot_mean_s=args.plot_mean_s,
                            progress=None if args.quiet else _progress(),
                            notify=lambda line: print(line, file=sys.stderr))
    for line in done.summary:
        print(line)
    for heading, figures in done.axes:
        if heading is not None:
            print(heading)
        _print_figures(figures)
    for line in done.closing:
        print(line)
    for target in done.written:
        print(f"wrote {target}")
    if done.elapsed_s is not None:
        print(_done_line(args, run_started, done.elapsed_s))
    return done.status


def _progress():
    """Progress of the chunks on stderr: one line per chunk, updated in place on a terminal."""
    terminal = sys.stderr.isatty()

    def show(step) -> None:
        text = (f"predicting: chunk {step.done}/{step.chunks}, {step.time_s:.1f} of {step.end_s:.1f} s of log, "
                f"{step.elapsed_s:.1f} s elapsed")
        if terminal:
            print("\r" + text, end="\n" if step.done == step.chunks else "", file=sys.stderr, flush=True)
        else:
            print(text, file=sys.stderr, flush=True)

    return show


def _print_figures(figures) -> None:
    """The console lines of one axis's figures (:class:`greybox.predict.AxisFigures`); the load's figures leave
    out the samples at standstill (:attr:`greybox.predict.process.ProcessResult.standstill`)."""
    from ..data.effort import EFFORT_UNITS

    tally, quantity, units = figures.tally, figures.quantity, figures.units
    noun, unit = quantity, EFFORT_UNITS[quantity]
    print(f"  {noun:<8} rms measured {tally.rms('measured'):.4g} {unit}, model {tally.rms('model'):.4g} "
          f"{unit}, process {tally.rms('process'):.4g} {unit}, largest |process| {tally.largest['process']:.4g} {unit}")
    if quantity in ("current", "motor torque") and figures.load_constants is not None:
        driving, backdriven = figures.load_constants
        per_ampere = f"{units.load_unit}/{unit}"
        factors = (f"{driving:.6g} {per_ampere}" if driving == backdriven
                   else f"{driving:.6g} {per_ampere} driving, {backdriven:.6g} {per_ampere} back-driven")
        standing = tally.n_samples - tally.n_moving
        where = f" of the {tally.n_moving} samples in motion (standstill left out)" if standing else ""
        print(f"  {units.load:<8} rms process {tally.rms('load_moving'):.4g} {units.load_unit}, "
              f"largest |process| {tally.largest['load_moving']:.4g} {units.load_unit}{where} "
              f"({factors} from {figures.axis_file})")
    _report_extrapolation(figures.extrapolation, figures.log_name)
    interval = figures.interval
    if interval is not None:
        from ..predict.interval import MIN_CLASS_SAMPLES

        widths = ", ".join(f"{name.replace('_', ' ')} {value:.3g}"
                           + ("" if interval.samples[name] >= MIN_CLASS_SAMPLES
                              else f" (pooled: {interval.samples[name]} samples)")
                           for name, value in interval.half_width_A.items())
        print(f"  interval {100 * interval.coverage:g} % (split conformal per regime on "
              f"{sum(interval.samples.values())} air-cut samples of {figures.calibration_logs} log(s)): "
              f"half-width [{unit}] {widths}; mean {tally.half_width_sum / tally.n_samples:.3g} {unit}")


def _done_line(args: argparse.Namespace, started: float, elapsed: float) -> str:
    """``done in 3.12 s wall (model 0.40 s)``: the wall time from ``started`` [s, perf_counter], which includes
    Python's start-up and the imports when greybox ran as a command of its own (then said so)."""
    startup = ", start-up included" if getattr(args, "startup_counted", False) else ""
    return f"done in {time.perf_counter() - started:.2f} s wall{startup} (model {elapsed:.2f} s)"


def _report_extrapolation(summary: dict, log_name: str) -> None:
    """One line on the share of samples outside the training region; a note on stderr above the limit."""
    from ..models.estimator import extrapolates

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
    if extrapolates(summary["by"], summary["share"]):
        print(f"note: {log_name}: {100 * summary['share']:.1f} % of the samples lie outside the positions, speeds "
              f"or inputs the model was trained on (more than {100 * summary['warn_above']:g} %): the model "
              "extrapolates there (column outside_training); train on air cuts that cover the cutting programme, "
              "or check the units of position and velocity (--columns)",
              file=sys.stderr)
