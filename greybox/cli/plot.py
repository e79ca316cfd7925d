"""``greybox plot``: draw a log (position, velocity, current over time; current over velocity)."""

from __future__ import annotations

import argparse

from ..evaluate.plots import plot_log
from ._options import add_log_arguments, read_logs


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "plot",
        help="draw a log as a PNG",
        description="Draw position, velocity and current over time, and current over velocity.",
    )
    parser.add_argument("log", help="log file (CSV, Parquet, MCAP or EMPS .mat)")
    parser.add_argument("--out", required=True, help="PNG file to write")
    parser.add_argument(
        "--raw",
        action="store_true",
        help="draw the log as read, without deriving a missing velocity",
    )
    add_log_arguments(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    (log,) = read_logs(args, [args.log], prepare=not args.raw)
    path = plot_log(log, args.out)
    print(f"wrote {path}")
    return 0
