"""What ``greybox predict`` and ``greybox train --per-machine`` share on the command line about fleet runs."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Callable

from ..errors import GreyboxError

__all__ = ["check_out_dir", "fleet_progress", "read_options", "report_fleet"]


def read_options(args: argparse.Namespace) -> dict:
    """The options of reading and preparing logs (:func:`greybox.fleet.read_prepared`) as given on the command line.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed command-line arguments with the log-reading options (``columns``, ``topic``, ``axis``,
        ``sample_time``, ``time_tolerance``, ``cutoff_hz``, ``resample``, ``max_gap``).
    """
    from ..data.io import parse_column_mapping

    return {"columns": parse_column_mapping(args.columns) if args.columns else None, "topic": args.topic,
            "axis": args.axis, "sample_time": args.sample_time, "time_tolerance": args.time_tolerance,
            "cutoff_hz": args.cutoff_hz, "resample": args.resample, "max_gap": args.max_gap}


def check_out_dir(out: str, inputs=()) -> Path:
    """``--out`` of a fleet run: a directory or a path not yet taken, none of the ``inputs``; return it resolved.

    Parameters
    ----------
    out : str
        The ``--out`` path given on the command line.
    inputs : iterable of str or Path, default ()
        Input paths of the run; the output directory must not be one of them.

    Raises
    ------
    GreyboxError
        For a path that is a file or one of the inputs.
    """
    path = Path(out)
    if path.exists() and not path.is_dir():
        raise GreyboxError(f"{path}: exists and is not a directory; the output of a fleet run is a directory")
    if any(path.resolve() == Path(item).resolve() for item in inputs):
        raise GreyboxError(f"--out {path}: is one of the inputs; choose another output directory")
    return path.resolve()


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
    """Print the fleet's summary line and its failures; return the exit status (2 if any job failed).

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
    counts = manifest["counts"]
    cluster = manifest["cluster"]
    where = f" on {cluster['workers']} worker(s) of {cluster['scheduler']}" if cluster["workers"] else ""
    print(f"fleet: {counts['ok']} {verb}, {counts['skipped']} skipped (complete from an earlier run), "
          f"{counts['failed']} failed of {len(manifest[items])} {items} in {manifest['seconds']:.1f} s{where}")
    for entry in manifest[items]:
        if entry["status"] == "failed":
            print(f"  failed: {describe(entry)}")
    return 2 if counts["failed"] else 0
