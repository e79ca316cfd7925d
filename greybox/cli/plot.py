"""``greybox plot``: draw a log (position, velocity, current over time; current over velocity)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..atomic import check_output_path
from ..errors import GreyboxError
from ..evaluate.plots import check_window, plot_log
from ._options import add_log_arguments, read_logs
from ._window import add_window_argument


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "plot",
        description="Draw position, velocity and current over time, and current over velocity. A long log is "
        "drawn as its envelope (minimum and maximum of each pixel column); --window draws a stretch of it.",
    )
    parser.add_argument("log", metavar="LOG", help="log file (CSV, Parquet, MCAP, TDMS or MATLAB .mat)")
    parser.add_argument("--out", required=True, metavar="PNG",
                        help="picture to write (.png, .svg or .pdf); an existing file is kept unless --force")
    parser.add_argument("--force", action="store_true", help="overwrite PNG if it exists")
    parser.add_argument(
        "--raw",
        action="store_true",
        help="draw the log as read, without deriving a missing velocity",
    )
    add_window_argument(parser)
    add_log_arguments(parser)
    parser.set_defaults(run=run)


#: Picture formats by file extension.
_PLOT_SUFFIXES = (".png", ".svg", ".pdf")


def _check_out(args: argparse.Namespace) -> None:
    """Refuse before reading the log: unknown extension, existing file without --force, the log itself."""
    out = Path(args.out)
    if out.suffix.lower() not in _PLOT_SUFFIXES:
        raise GreyboxError(f"{out}: unknown picture extension '{out.suffix}'; use {', '.join(_PLOT_SUFFIXES)}")
    check_output_path(out, overwrite=args.force, protect=[args.log], inputs_name="the log to draw")


def _run_to_draw(runs, window, name: str):
    """The one run to draw: the log's only run, or, for a log split at gaps, the run where --window starts."""
    if len(runs) == 1:
        return runs[0]
    starts = ", ".join(f"{run.time[0]:.6g}-{run.time[-1]:.6g}" for run in runs)
    if window is None:
        raise GreyboxError(f"{name}: split into {len(runs)} runs at gaps ({starts} s); plot draws one: give "
                           "--window START END inside one of them, or a larger --max-gap")
    for run in runs:
        if run.time[0] <= window[0] <= run.time[-1]:
            return run
    raise GreyboxError(f"{name}: --window starts at {window[0]:g} s, in no run of the log ({starts} s)")


def run(args: argparse.Namespace) -> int:
    _check_out(args)
    runs = read_logs(args, [args.log], prepare=not args.raw)
    log = _run_to_draw(runs, args.window, Path(args.log).name)
    window = check_window(args.window, log.time, name=Path(args.log).name)
    path = plot_log(log, args.out, window=window)
    print(f"wrote {path}")
    return 0
