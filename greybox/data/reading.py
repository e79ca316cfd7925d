"""Reading and preparing one log as every workflow does: the one reader of logs into prepared runs."""

from __future__ import annotations

from pathlib import Path
from typing import Callable, Mapping

from .io import read_log
from .prepare import MAX_GAP_STEPS, prepare

__all__ = ["read_prepared"]


def read_prepared(path: str, read: Mapping, *, columns: Mapping[str, str] | None = None,
                  notify: Callable[[str], None] | None = None) -> list:
    """Read and prepare one log as every command does: its runs (AxisLog), several where it is split at gaps.

    Parameters
    ----------
    path : str
        Log file.
    read : mapping
        Options of reading and preparing: ``columns``, ``topic``, ``axis``, ``sample_time``,
        ``time_tolerance`` (fraction of the step), ``cutoff_hz`` [Hz], ``resample`` [s], ``max_gap``
        [steps] (:func:`greybox.data.io.read_log`, :func:`greybox.data.prepare.prepare`); missing ones
        take their defaults.
    columns : mapping, optional
        Column mapping under ``read["columns"]`` (an axis file's channels).
    notify : callable, optional
        ``notify(line)`` with a ``note:`` line naming the gaps where the log was split into runs.
    """
    columns = {**(columns or {}), **(read.get("columns") or {})} or None
    resample = read.get("resample")
    tolerance = read.get("time_tolerance", 0.25)
    max_gap = read.get("max_gap", MAX_GAP_STEPS)
    log = read_log(path, columns=columns, topic=read.get("topic"), sample_time=read.get("sample_time"),
                   axis=read.get("axis"), time_tolerance=None if resample else tolerance)
    runs = prepare([log], cutoff_hz=read.get("cutoff_hz"), sample_time=resample, tolerance=tolerance,
                   max_gap_steps=max_gap)
    if len(runs) > 1 and notify is not None:
        starts = ", ".join(f"{run.attrs['split']['start_s']:.6g}" for run in runs[1:])
        notify(f"note: {Path(path).name}: split into {len(runs)} runs at gaps longer than {max_gap:g} steps "
               f"(--max-gap); the runs after the first start at t = {starts} s")
    return runs
