"""What ``greybox predict``, ``greybox train --per-machine`` print of a fleet run: its progress and its summary."""

from __future__ import annotations

import sys
import time
from typing import Callable

__all__ = ["fleet_progress", "report_fleet"]


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
