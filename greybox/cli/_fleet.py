"""What ``greybox predict`` and ``greybox train --per-machine`` share on the command line about fleet runs."""

from __future__ import annotations

import argparse
import sys
import time
from typing import Callable

__all__ = ["fleet_progress", "read_options", "report_fleet"]


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
    from ..data.prepare import MAX_GAP_STEPS

    return {"columns": parse_column_mapping(args.columns) if args.columns else None, "topic": args.topic,
            "axis": getattr(args, "axis", None), "sample_time": args.sample_time,
            "time_tolerance": args.time_tolerance, "cutoff_hz": getattr(args, "cutoff_hz", None),
            "resample": getattr(args, "resample", None), "max_gap": getattr(args, "max_gap", MAX_GAP_STEPS)}


def fleet_progress(noun: str, quiet: bool, label: Callable[[dict], str]) -> Callable[[int, int, dict], None]:
    """One progress line for the fleet on stderr (updated in place on a terminal); counts failures even if quiet.

    Parameters
    ----------
    noun : str
        What the fleet counts (``"logs"``, ``"models"``).
    quiet : bool
        The --quiet option: print nothing.
    label : callable
        Name of the job of an entry, shown with its status.
    """
    started = time.perf_counter()
    terminal = sys.stderr.isatty()
    failed = 0

    def show(done: int, total: int, entry: dict) -> None:
        nonlocal failed
        failed += entry["status"] == "failed"
        if quiet:
            return
        text = (f"fleet: {done}/{total} {noun}, {failed} failed, {time.perf_counter() - started:.1f} s elapsed "
                f"({label(entry)}: {entry['status']})")
        print("\r" + text.ljust(100) if terminal else text, end="\n" if not terminal or done == total else "",
              file=sys.stderr, flush=True)

    return show


def report_fleet(manifest: dict, items: str, verb: str, describe: Callable[[dict], str]) -> int:
    """Print the fleet's summary line and its failures (:func:`greybox.fleet.fleet_summary`); the exit status.

    Parameters
    ----------
    manifest : dict
        Written by :func:`greybox.fleet.run_tasks`.
    items : str
        Its list of entries (``"logs"``, ``"models"``), also the noun of the summary.
    verb : str
        What an ``ok`` job did (``"predicted"``, ``"trained"``).
    describe : callable
        The line of a failed entry.
    """
    from ..fleet import fleet_summary

    lines, status = fleet_summary(manifest, items, verb, describe)
    for line in lines:
        print(line)
    return status
