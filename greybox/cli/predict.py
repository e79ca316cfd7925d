"""``greybox predict``: the process share of the current of a cutting log, and its force."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from ..errors import GreyboxError
from ._options import add_log_arguments
from ._types import FRACTION, non_negative, positive
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
        "= measured - model; with --axis-config also the process force in N. The model runs over chunks "
        "of --chunk-s seconds carrying its state, so long logs need little working memory.",
    )
    parser.add_argument("model", metavar="MODEL", help="model file written by 'greybox train' (.gbm)")
    parser.add_argument("log", metavar="LOG", help="cutting log (CSV, Parquet, MCAP, TDMS or MATLAB .mat)")
    parser.add_argument("--out", required=True, metavar="OUT",
                        help="table to write: .csv, .parquet or .mcap (CSV: plain, header first, metadata in "
                        "OUT.json beside it; MCAP: one message per sample, topic /process/<axis>)")
    parser.add_argument("--axis-config", metavar="TOML",
                        help="axis metadata (torque constant, screw lead, gear ratio, efficiency driving and "
                        "back-driven, channel names); adds force_process_N, converted by the direction of the "
                        "power flow (see examples/axis_x.toml)")
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


def run(args: argparse.Namespace) -> int:
    run_started = time.perf_counter()
    from ..data.axis_config import read_axis_config
    from ..evaluate.process import predict_process
    from ..evaluate.process_io import check_output_path, output_paths, write_process
    from ..models.chunked import chunk_slices, samples_per_chunk
    from ..persistence import load_model

    inputs = [args.model, args.log] + ([args.axis_config] if args.axis_config else []) + list(args.calibration or [])
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
    config = read_axis_config(args.axis_config) if args.axis_config else None
    model = load_model(args.model)
    runs = _read_runs(args, config.channels if config else {})
    log_time = np.concatenate([run.time for run in runs])
    window = check_window(args.plot_window, log_time, "--plot-window", Path(args.log).name)
    interval = None
    if args.calibration:
        from ..evaluate.interval import calibrate_interval

        own = [path for path in args.calibration if Path(path).resolve() == Path(args.log).resolve()]
        if own:
            raise GreyboxError(f"--calibration: {own[0]} is the cutting log itself; calibrate on air cuts the "
                               "model was not trained on")

        interval = calibrate_interval(model, [run for path in args.calibration
                                              for run in _read_runs(args, config.channels if config else {}, path)],
                                      coverage=DEFAULT_COVERAGE if args.interval is None else args.interval,
                                      chunk_s=args.chunk_s)

    started = time.perf_counter()
    result = predict_process(model, runs, axis_config=config, interval=interval, chunk_s=args.chunk_s,
                             progress=_progress(float(log_time[-1]), args.quiet))
    elapsed = time.perf_counter() - started
    result.attrs.update({"model_file": str(args.model), "log_file": str(args.log)})
    n_chunks = sum(len(chunk_slices(len(run), samples_per_chunk(run.sample_time, args.chunk_s))) for run in runs)
    duration = sum(run.duration for run in runs)
    unit = result.effort_unit
    noun = "current" if unit == "A" else "force"
    process = result.process
    print(f"predicted {Path(args.log).name} with the {result.attrs['model_kind']} model {Path(args.model).name}: "
          f"{len(result.time)} samples, {duration:.1f} s, {n_chunks} chunk(s) of {args.chunk_s:g} s"
          + (f" in {len(runs)} runs" if len(runs) > 1 else "")
          + (f", dataset {result.dataset}" if result.dataset else ""))
    print(f"  {noun:<8} rms measured {_rms(result.measured):.4g} {unit}, model {_rms(result.model):.4g} {unit}, "
          f"process {_rms(process):.4g} {unit}, largest |process| {np.max(np.abs(process)):.4g} {unit}")
    if unit == "A" and result.force is not None:
        driving, backdriven = result.force_constants_N_per_A
        factors = (f"{driving:.6g} N/A" if driving == backdriven
                   else f"{driving:.6g} N/A driving, {backdriven:.6g} N/A back-driven")
        print(f"  force    rms process {_rms(result.force):.4g} N, "
              f"largest |process| {np.max(np.abs(result.force)):.4g} N "
              f"({factors} from {Path(args.axis_config).name})")
    _report_extrapolation(result.attrs["extrapolation"], Path(args.log).name)
    if interval is not None:
        from ..evaluate.interval import MIN_CLASS_SAMPLES

        widths = ", ".join(f"{name.replace('_', ' ')} {value:.3g}"
                           + ("" if interval.samples[name] >= MIN_CLASS_SAMPLES
                              else f" (pooled: {interval.samples[name]} samples)")
                           for name, value in interval.half_width_A.items())
        print(f"  interval {100 * interval.coverage:g} % (split conformal per regime on "
              f"{sum(interval.samples.values())} air-cut samples of {len(args.calibration)} log(s)): "
              f"half-width [{unit}] {widths}; mean {np.mean(result.half_width):.3g} {unit}")
    write_process(result, out, overwrite=args.force, protect=inputs)
    for target in output_paths(out):
        print(f"wrote {target}")
    if args.plot:
        from ..evaluate.process_plot import plot_process

        plot_process(result, args.plot, mean_s=args.plot_mean_s, window=window)
        print(f"wrote {args.plot}")
    print(f"done in {time.perf_counter() - run_started:.2f} s wall (model {elapsed:.2f} s)")
    return 0


def _report_extrapolation(summary: dict, log_name: str) -> None:
    """One line on the share of samples outside the training region; a note on stderr above the limit."""
    if summary["share"] is None:
        print(f"  outside the training region: not known ({summary['reason']})")
        return
    parts = ", ".join(f"{name} {100 * share:.1f} %" for name, share in summary["by"].items())
    print(f"  outside the training region: {100 * summary['share']:.1f} % of the samples ({parts})")
    if summary["share"] > summary["warn_above"]:
        print(f"note: {log_name}: {100 * summary['share']:.1f} % of the samples lie outside the positions, speeds "
              f"or inputs the model was trained on (more than {100 * summary['warn_above']:g} %): the model "
              "extrapolates there (column outside_training); train on air cuts that cover the cutting programme, "
              "or check the units of position and velocity (--columns)",
              file=sys.stderr)


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(values))))
