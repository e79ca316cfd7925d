"""``greybox monitor --workers N`` or ``--scheduler ADDRESS``: the logs fingerprinted on a Dask cluster.

:func:`monitor_fleet` runs :func:`greybox.monitor.workflow.run_monitor`'s work with the fingerprints on the
engine of every fleet run (:func:`greybox.fleet.engine.run_tasks`: one task per log, :func:`fingerprint_job`,
on a local cluster or a scheduler's), then ends as it does (:func:`greybox.monitor.workflow.finish_run`: the
history compacted, the change detection, the dashboard). The run leaves its manifest (format
:data:`MONITOR_FORMAT`) in the history and skips the logs it lists as done, unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

from ..errors import GreyboxError, LogError
from ..models.plant import MANIFEST
from ..monitor.workflow import DuplicateLogError, MonitorResult, fingerprint_file, finish_run, start_run
from .engine import attempt, log_stamp, run_tasks

__all__ = ["MONITOR_FORMAT", "FingerprintJob", "fingerprint_job", "monitor_fleet"]

#: ``format`` of the manifest a fleet run of the fingerprints leaves in the history (``_manifest.json``).
MONITOR_FORMAT = "greybox-monitor"


@dataclass(frozen=True)
class FingerprintJob:
    """One log of a fleet run of ``greybox monitor``: what to read and where its fingerprint goes.

    Parameters
    ----------
    path : str
        Log file.
    history : str
        History directory.
    machine, axis : str or None
        As :func:`fingerprint_file` takes them.
    model_path : str or None
        Reference model file, loaded by the worker.
    spindle_column : str or None
        Spindle-load column.
    find_cuts : bool
        Find the cutting stretches from the current.
    """

    path: str
    history: str
    machine: str | None = None
    axis: str | None = None
    model_path: str | None = None
    spindle_column: str | None = None
    find_cuts: bool = False


def fingerprint_job(job: FingerprintJob) -> dict:
    """Fingerprint one log on a fleet worker (:func:`greybox.fleet.engine.run_tasks`); never raises for bad input.

    Parameters
    ----------
    job : FingerprintJob
        The log and its settings.

    Returns
    -------
    dict
        The manifest entry (:func:`greybox.fleet.engine.attempt`): ``output``, the history file of the log's row,
        and ``fitted``, whether it was fitted now.
    """
    def work() -> dict:
        model = None
        if job.model_path is not None:
            from ..models.files import load_model

            model = load_model(job.model_path)
        try:
            row, new = fingerprint_file(job.path, job.history, machine=job.machine, axis=job.axis, model=model,
                                        spindle_column=job.spindle_column, find_cuts=job.find_cuts)
        except DuplicateLogError as copy:
            return {"output": None, "fitted": False, "duplicate": str(copy)}
        return {"output": str(row), "fitted": bool(new)}

    return attempt(str(job.path), work)


def _fingerprint_on_cluster(logs, history, machine, axis, model_path, spindle_column, find_cuts, scheduler,
                            workers, progress) -> tuple[int, int, list]:
    """Fingerprint ``logs`` on a Dask cluster (:func:`greybox.fleet.engine.run_tasks`); the logs fitted, known, and the
    copies found (one line each)."""
    jobs = [FingerprintJob(str(path), str(history), machine, axis, None if model_path is None else str(model_path),
                           spindle_column, find_cuts) for path in logs]
    for job in jobs:
        if not Path(job.path).is_file():
            raise LogError(job.path, "no such log file")
    stamps = [{"log": job.path, **log_stamp(job.path), "machine": machine, "axis": axis,
               "model": job.model_path, "spindle_column": spindle_column, "find_cuts": find_cuts} for job in jobs]

    def report(done: int, total: int, entry: dict) -> None:
        if progress is not None:
            state = entry.get("error") or entry.get("duplicate") or (
                "fingerprinted" if entry.get("fitted") else "already in the history")
            progress(f"[{done}/{total}] {entry['log']}: {state}")

    manifest = run_tasks(fingerprint_job, jobs, stamps, out_dir=history, header={"format": MONITOR_FORMAT},
                         items="logs", scheduler=scheduler, workers=workers, progress=report)
    failed = [entry for entry in manifest["logs"] if entry["status"] == "failed"]
    if failed:
        raise GreyboxError(f"{len(failed)} of {len(jobs)} logs failed (listed in {Path(history) / MANIFEST});"
                           f" the first: {failed[0]['error']}")
    fitted = sum(bool(entry.get("fitted")) and entry["status"] == "ok" for entry in manifest["logs"])
    copies = [entry["duplicate"] for entry in manifest["logs"] if entry.get("duplicate")]
    return fitted, len(jobs) - fitted - len(copies), copies


def monitor_fleet(logs: Sequence, history, out_dir, *, machine: str | None = None, axis: str | None = None,
                  model_path=None, spindle_column: str | None = None, find_cuts: bool = False,
                  baseline_days: int = 28, scheduler: str | None = None, workers: int | None = None,
                  progress: Callable[[str], None] | None = None, force: bool = False) -> MonitorResult:
    """Fingerprint ``logs`` into ``history`` on a Dask cluster, then detect changes and write the dashboard.

    Parameters
    ----------
    logs : sequence of path-like
        Log files (may be empty: then no cluster starts and only the history is analysed).
    history : path-like
        History directory (created if missing); the run's manifest is written there.
    out_dir : path-like
        Directory of the dashboard ``index.html``.
    machine, axis, model_path, spindle_column, find_cuts, baseline_days, progress, force
        As :func:`greybox.monitor.workflow.run_monitor` takes them (``progress``: one line per log as it is done).
    scheduler : str, optional
        Address of a Dask scheduler: the logs are fingerprinted on that cluster.
    workers : int, optional
        Processes of the local Dask cluster (without ``scheduler``).

    Returns
    -------
    MonitorResult

    Raises
    ------
    GreyboxError
        For bad options, a log that is not there, or when any log failed (the first failure named, every one
        listed in the manifest).
    """
    detector = start_run(history, out_dir, baseline_days=baseline_days, force=force)
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise GreyboxError(f"workers must be a positive whole number, got {workers!r}")
    fitted = known = 0
    duplicates: list = []
    if logs:
        fitted, known, duplicates = _fingerprint_on_cluster(logs, history, machine, axis, model_path, spindle_column,
                                                            find_cuts, scheduler, workers, progress)
    return finish_run(history, out_dir, detector, fitted=fitted, known=known, duplicates=duplicates)
