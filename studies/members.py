"""Running a study member by member over processes, with its JSON rewritten after every member."""

from __future__ import annotations

import json
import os
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Callable, Iterable

from greybox.atomic import write_text_atomic

__all__ = ["run_members"]


def run_members(run: Callable, jobs: Iterable, *, json_path: str | os.PathLike, settings: dict,
                summarise: Callable[[list[dict]], dict], describe: Callable[[dict], str], workers: int = 1,
                progress: Callable[[str], None] | None = None) -> tuple[dict, float]:
    """Run ``run(job)`` for every job on ``workers`` processes, in order, saving as the rows come in.

    Parameters
    ----------
    run : callable
        A module-level function (it is sent to the worker processes) taking one job and returning a
        JSON-able row.
    jobs : iterable
        The jobs, one per member.
    json_path : path-like
        Written atomically after every row: ``{"settings", "summary", "members", "seconds"}``.
    settings : dict
        The study's settings, stored as they are.
    summarise : callable
        Rows so far -> summary.
    describe : callable
        Row -> one progress line.
    workers : int, default 1
        Processes.
    progress : callable, optional
        Receives each progress line.

    Returns
    -------
    (dict, float)
        The summary of all rows and the wall time [s].
    """
    say = progress or (lambda line: None)
    started, rows = time.perf_counter(), []

    def save() -> dict:
        summary = summarise(rows) if rows else {}
        write_text_atomic(json_path, json.dumps({"settings": settings, "summary": summary, "members": rows,
                                                 "seconds": time.perf_counter() - started}, indent=1) + "\n")
        return summary

    with ProcessPoolExecutor(max_workers=workers) as pool:
        for row in pool.map(run, jobs):
            rows.append(row)
            say(describe(row))
            save()
    return save(), time.perf_counter() - started
