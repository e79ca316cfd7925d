"""Command-line options shared by every sub-command that reads axis logs."""

from __future__ import annotations

import argparse
import sys

from ..data.log import AxisLog
from ..data.prepare import MAX_GAP_STEPS
from ._types import FRACTION, GAP_STEPS, POSITIVE, positive

__all__ = ["add_log_arguments", "read_logs", "read_named_runs", "read_options", "read_runs"]


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
    group.add_argument("--topic", help="MCAP topic (channel) or TDMS group to read when a file holds several axes")
    group.add_argument("--axis", metavar="NAME",
                       help="the axis to read from a log of several axes: its columns named NAME_position_mm, "
                       "NAME_current_A, ... (CSV, Parquet, MATLAB, TDMS channels), the MCAP channel /axis/NAME or "
                       "the TDMS group NAME")
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
            help="resample every log to a uniform step of S seconds before use (linear interpolation): time "
            "stamps may then be irregular, and a log is split into runs at gaps longer than --max-gap steps",
        )
        group.add_argument(
            "--max-gap",
            type=GAP_STEPS,
            default=MAX_GAP_STEPS,
            metavar="STEPS",
            help=f"with --resample: the longest time step, in median steps of the log, that is interpolated "
            f"over; a longer one splits the log into runs (default {MAX_GAP_STEPS:g})",
        )


def read_logs(args: argparse.Namespace, paths, *, prepare: bool = True) -> list[AxisLog]:
    """Read every file in ``paths`` as a separate run, prepared unless told otherwise.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed options added by :func:`add_log_arguments`.
    paths : iterable of str
        Log files (CSV, Parquet, MCAP, TDMS, MATLAB ``.mat``).
    prepare : bool, default True
        Derive velocity and acceleration (and resample when asked).

    Returns
    -------
    list of AxisLog
        One log per file, in the order given.
    """
    from ..data.io import parse_column_mapping

    columns = parse_column_mapping(args.columns) if args.columns else None
    return [run for path in paths for run in read_runs(args, path, columns=columns, prepare=prepare)]


def read_named_runs(args: argparse.Namespace, paths, names, *, prepare: bool = True
                    ) -> tuple[list[AxisLog], list[str]]:
    """Like :func:`read_logs`, with a name per run: the file's ``names`` entry, plus ``run k of n`` where split
    (no slash, so that a file name taken of the label keeps it).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed options added by :func:`add_log_arguments`.
    paths : iterable of str
        Log files.
    names : iterable of str
        A display name per file.
    prepare : bool, default True
        Derive velocity and acceleration (and resample when asked).

    Returns
    -------
    (list of AxisLog, list of str)
        The runs in file order and a name for each.
    """
    from ..data.io import parse_column_mapping

    columns = parse_column_mapping(args.columns) if args.columns else None
    runs, labels = [], []
    for path, name in zip(paths, names):
        pieces = read_runs(args, path, columns=columns, prepare=prepare)
        runs += pieces
        labels += [name] if len(pieces) == 1 else [f"{name} run {k} of {len(pieces)}" for k in
                                                    range(1, len(pieces) + 1)]
    return runs, labels


def read_runs(args: argparse.Namespace, path, *, columns=None, prepare: bool = True) -> list[AxisLog]:
    """Read one file and prepare it as the options say: one run, or several when --resample splits it at gaps.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed options added by :func:`add_log_arguments`.
    path : str
        Log file.
    columns : dict, optional
        Column mapping (``{canonical_name: name_in_file}``).
    prepare : bool, default True
        Derive velocity and acceleration (and resample when asked).

    Returns
    -------
    list of AxisLog
        The runs of the file, in time order (:func:`greybox.data.reading.read_prepared`); a note on stderr
        names the gaps where it was split.
    """
    from ..data.io import read_log
    from ..data.reading import read_prepared
    read = read_options(args)
    if not prepare:
        return [read_log(path, columns=columns, topic=read["topic"], sample_time=read["sample_time"],
                         time_tolerance=read["time_tolerance"], axis=read["axis"])]
    return read_prepared(path, {**read, "columns": None}, columns=columns,
                         notify=lambda line: print(line, file=sys.stderr))


def read_options(args: argparse.Namespace) -> dict:
    """The options of reading and preparing logs (:func:`greybox.data.reading.read_prepared`) as given on the command
    line.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed command-line arguments with the log-reading options (``columns``, ``topic``, ``axis``,
        ``sample_time``, ``time_tolerance``, ``cutoff_hz``, ``resample``, ``max_gap``; the last four
        take their defaults where the command does not offer them).
    """
    from ..data.io import parse_column_mapping

    return {"columns": parse_column_mapping(args.columns) if args.columns else None, "topic": args.topic,
            "axis": getattr(args, "axis", None), "sample_time": args.sample_time,
            "time_tolerance": args.time_tolerance, "cutoff_hz": getattr(args, "cutoff_hz", None),
            "resample": getattr(args, "resample", None), "max_gap": getattr(args, "max_gap", MAX_GAP_STEPS)}
