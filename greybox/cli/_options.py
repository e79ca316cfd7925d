"""Command-line options shared by every sub-command that reads axis logs."""

from __future__ import annotations

import argparse

from ..data.log import AxisLog
from ._types import FRACTION, POSITIVE, positive

__all__ = ["add_log_arguments", "read_logs"]


def add_log_arguments(parser: argparse.ArgumentParser, *, prepare: bool = True) -> None:
    """Add the options that tell greybox how to read (and prepare) a log.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        Parser of the sub-command.
    prepare : bool, default True
        Also offer the preparation options (derivative cut-off, resampling).
    """
    group = parser.add_argument_group("reading logs")
    group.add_argument(
        "--columns",
        metavar="MAP",
        help="column mapping for exports with other headers, e.g. "
        "'position_mm=X1_ActualPosition,current_A=X1_CurrentFeedback' (CSV, Parquet, MCAP fields)",
    )
    group.add_argument("--topic", help="MCAP topic (channel) to read when a file holds several axes")
    group.add_argument(
        "--sample-time",
        type=positive("seconds"),
        metavar="S",
        help="sample time [s] for logs without a time column (time = row index * S)",
    )
    group.add_argument(
        "--time-tolerance",
        type=FRACTION,
        default=0.25,
        metavar="FRAC",
        help="allowed deviation of a time step from the nominal step, as a fraction of it (default 0.25)",
    )
    if prepare:
        group.add_argument(
            "--cutoff-hz",
            type=POSITIVE,
            metavar="HZ",
            help="cut-off [Hz] of the zero-phase 4th-order Butterworth low-pass applied to position before "
            "differentiating it (default min(50 Hz, 0.4 x Nyquist): 50 Hz at 2 ms and 1 ms, 2 Hz at 0.1 s)",
        )
        group.add_argument(
            "--resample",
            type=positive("seconds"),
            metavar="S",
            help="resample every log to a uniform step of S seconds before use",
        )


def read_logs(args: argparse.Namespace, paths, *, prepare: bool = True) -> list[AxisLog]:
    """Read every file in ``paths`` as a separate run, prepared unless told otherwise.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed options added by :func:`add_log_arguments`.
    paths : iterable of str
        Log files (CSV, Parquet, MCAP, EMPS ``.mat``).
    prepare : bool, default True
        Derive velocity and acceleration (and resample when asked).

    Returns
    -------
    list of AxisLog
        One log per file, in the order given.
    """
    from ..data.io import parse_column_mapping, read_log
    from ..data.prepare import prepare as prepare_logs

    columns = parse_column_mapping(args.columns) if args.columns else None
    logs = [
        read_log(
            path,
            columns=columns,
            topic=args.topic,
            sample_time=args.sample_time,
            time_tolerance=args.time_tolerance,
        )
        for path in paths
    ]
    if not prepare:
        return logs
    return prepare_logs(logs, cutoff_hz=getattr(args, "cutoff_hz", None), sample_time=getattr(args, "resample", None))
