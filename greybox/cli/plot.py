"""``greybox plot``: draw a log (position, velocity, current over time; current over velocity)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..atomic import check_output_path
from ..errors import GreyboxError
from ..evaluate.plots import plot_log
from ._options import add_log_arguments, read_logs
from ._window import add_window_argument, check_window


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "plot",
        help="draw a log as a PNG",
        description="Draw position, velocity and current over time, and current over velocity. A long log is "
        "drawn as its envelope (minimum and maximum of each pixel column); --window draws a stretch of it.",
    )
    parser.add_argument("log", metavar="LOG", help="log file (CSV, Parquet, MCAP or EMPS .mat)")
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


def run(args: argparse.Namespace) -> int:
    _check_out(args)
    (log,) = read_logs(args, [args.log], prepare=not args.raw)
    window = check_window(args.window, log.time, name=Path(args.log).name)
    path = plot_log(log, args.out, window=window)
    print(f"wrote {path}")
    return 0
