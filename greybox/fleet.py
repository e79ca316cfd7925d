"""A plant's worth of logs: ``greybox predict`` over many logs, one task per log on dask.distributed.

:func:`expand_logs` turns files, directories (searched recursively for log files) and glob patterns
into the list of logs; :func:`run_fleet` predicts each on a Dask cluster, by default a local cluster
of processes, one per core, or the cluster of a scheduler address, so that the same command runs on a
laptop and on a cluster. Each log's process table goes to a Parquet dataset partitioned like the plant::

    OUT/machine=<folder of the log>/axis=<axis>/log=<file stem>/part-0.parquet

(``pyarrow.dataset.dataset(OUT, partitioning="hive")`` reads it whole, with the partition columns),
and ``OUT/_manifest.json`` records what ran: every log with its status (``ok``, ``skipped``,
``failed`` with its one-line error), output, samples and seconds, the model file and its SHA-256,
the versions of greybox and its libraries, the cluster and the wall time. A log that fails is
reported and the others go on. A re-run skips every log whose output is complete: listed ``ok`` in
the manifest for the same model file (hash) and the same log file (size and modification time),
its output still there. Every file is written atomically.
"""

from __future__ import annotations

import glob
import hashlib
import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

from .atomic import write_text_atomic
from .errors import GreyboxError

__all__ = ["LOG_SUFFIXES", "MANIFEST", "FleetJob", "expand_logs", "fleet_jobs", "predict_log", "run_fleet"]

#: File extensions taken as logs when a directory is given.
LOG_SUFFIXES = (".csv", ".parquet", ".pq", ".mcap", ".mat", ".tdms")

#: Name of the manifest in the output directory (a leading "_": dataset readers skip it).
MANIFEST = "_manifest.json"

_GLOB_CHARACTERS = set("*?[")


def expand_logs(items: Sequence[str]) -> list[Path]:
    """The log files named by files, directories (searched recursively) and glob patterns, each once.

    Directories and patterns yield the files with a log extension (:data:`LOG_SUFFIXES`), so that a CSV
    log's metadata sidecar or a manifest beside the logs is not taken for a log.

    Raises
    ------
    GreyboxError
        For an item that names nothing, or no log at all.
    """
    logs: list[Path] = []
    for item in items:
        if _GLOB_CHARACTERS & set(item):
            found = [Path(name) for name in sorted(glob.glob(item, recursive=True))
                     if Path(name).is_file() and Path(name).suffix.lower() in LOG_SUFFIXES]
            if not found:
                raise GreyboxError(f"{item}: the pattern matches no log file ({', '.join(LOG_SUFFIXES)})")
            logs += found
        elif os.path.isdir(item):
            found = sorted(path for path in Path(item).rglob("*") if path.is_file()
                           and path.suffix.lower() in LOG_SUFFIXES and not path.name.startswith("."))
            if not found:
                raise GreyboxError(f"{item}: no log file ({', '.join(LOG_SUFFIXES)}) in the directory")
            logs += found
        elif os.path.isfile(item):
            logs.append(Path(item))
        else:
            raise GreyboxError(f"{item}: no such log, directory or pattern")
    unique = list(dict.fromkeys(path.resolve() for path in logs))
    if not unique:
        raise GreyboxError("no log to predict")
    return unique


@dataclass(frozen=True)
class FleetJob:
    """One log of a fleet run: what to read, with which model, and where the outputs go.

    Parameters
    ----------
    log : str
        Log file.
    machine : str
        Machine the log belongs to (its folder's name), the first partition level.
    model : str
        Model file.
    out_dir : str
        Root of the Parquet dataset.
    axis_config : str, optional
        Axis file (force or torque).
    read : dict
        Options of reading and preparing the log: ``columns``, ``topic``, ``axis``, ``sample_time``,
        ``time_tolerance``, ``cutoff_hz``, ``resample``, ``max_gap`` (:func:`greybox.data.io.read_log`,
        :func:`greybox.data.prepare.prepare`).
    chunk_s : float
        Chunk length of the prediction [s].
    """

    log: str
    machine: str
    model: str
    out_dir: str
    axis_config: str | None = None
    read: dict = field(default_factory=dict)
    chunk_s: float = 60.0


def _partition(value: str) -> str:
    """A partition value safe in a path: letters, digits, ``-``, ``_`` and ``.``."""
    return "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in value) or "_"


def fleet_jobs(logs: Sequence[Path], model: str, out_dir: str, *, axis_config: str | None = None,
               read: dict | None = None, chunk_s: float = 60.0) -> list[FleetJob]:
    """One job per log; the machine is the name of the log's folder."""
    return [FleetJob(str(log), _partition(Path(log).parent.name), str(model), str(out_dir), axis_config,
                     dict(read or {}), float(chunk_s)) for log in logs]


def _file_hash(path: str) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _log_stamp(path: str) -> dict:
    stat = os.stat(path)
    return {"size": stat.st_size, "mtime_ns": stat.st_mtime_ns}


def predict_log(job: FleetJob) -> dict:
    """Predict one log and write its process table; the task each worker runs.

    Returns
    -------
    dict
        ``log``, ``machine``, ``status`` (``ok`` or ``failed``), ``output``, ``axis``, ``samples``,
        ``seconds``, ``peak_rss_mb`` (of the worker process so far), and for a failure its ``error``
        (one line). Never raises for a bad log.
    """
    started = time.perf_counter()
    entry = {"log": job.log, "machine": job.machine, **_log_stamp(job.log)}
    try:
        output, axis, samples = _predict_and_write(job)
    except GreyboxError as error:
        return {**entry, "status": "failed", "error": str(error), "seconds": time.perf_counter() - started}
    except Exception as error:  # a bug, not a bad log: reported in the manifest, the fleet goes on
        return {**entry, "status": "failed", "error": f"{job.log}: internal error {type(error).__name__}: {error}",
                "seconds": time.perf_counter() - started}
    return {**entry, "status": "ok", "output": output, "axis": axis, "samples": samples,
            "seconds": time.perf_counter() - started, "peak_rss_mb": _peak_rss_mb()}


def _peak_rss_mb() -> float | None:
    """Peak resident memory of this (worker) process so far [MB]; None where the OS does not say."""
    try:
        import resource
    except ImportError:  # not on Windows
        return None
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / 1024.0 if os.uname().sysname != "Darwin" else peak / 2**20


def _predict_and_write(job: FleetJob) -> tuple[str, str, int]:
    from .data.axis_config import read_axis_config
    from .data.io import read_log
    from .data.prepare import MAX_GAP_STEPS, prepare
    from .evaluate.process import predict_process
    from .evaluate.process_io import write_process
    from .persistence import load_model

    options = job.read
    config = read_axis_config(job.axis_config) if job.axis_config else None
    columns = {**(config.channels if config else {}), **(options.get("columns") or {})} or None
    resample = options.get("resample")
    log = read_log(job.log, columns=columns, topic=options.get("topic"), sample_time=options.get("sample_time"),
                   axis=options.get("axis"), time_tolerance=None if resample else options.get("time_tolerance", 0.25))
    runs = prepare([log], cutoff_hz=options.get("cutoff_hz"), sample_time=resample,
                   tolerance=options.get("time_tolerance", 0.25), max_gap_steps=options.get("max_gap", MAX_GAP_STEPS))
    result = predict_process(load_model(job.model), runs, axis_config=config, chunk_s=job.chunk_s)
    result.attrs.update({"model_file": job.model, "log_file": job.log})
    axis = _partition(result.axis or "-")
    target = Path(job.out_dir) / f"machine={job.machine}" / f"axis={axis}" / f"log={_partition(Path(job.log).stem)}"
    target.mkdir(parents=True, exist_ok=True)
    path = write_process(result, target / "part-0.parquet", overwrite=True)  # the table `predict` writes
    return str(path), axis, len(result.time)


def _previous(out_dir: Path, model_hash: str) -> dict:
    """Entries of the last manifest that a re-run may keep: ok, same model, output still there."""
    path = out_dir / MANIFEST
    if not path.is_file():
        return {}
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError):
        return {}
    if not isinstance(document, dict) or document.get("model_sha256") != model_hash:
        return {}
    kept = {}
    for entry in document.get("logs", []):
        if isinstance(entry, dict) and entry.get("status") in ("ok", "skipped") and \
                isinstance(entry.get("output"), str) and os.path.isfile(entry["output"]):
            kept[entry.get("log")] = entry
    return kept


def _versions() -> dict:
    from importlib.metadata import PackageNotFoundError, version

    out = {}
    for package in ("greybox", "numpy", "scipy", "scikit-learn", "numba", "pyarrow", "dask", "distributed"):
        try:
            out[package] = version(package)
        except PackageNotFoundError:
            out[package] = None
    return out


def run_fleet(jobs: Sequence[FleetJob], *, scheduler: str | None = None, workers: int | None = None,
              progress: Callable[[int, int, dict], None] | None = None) -> dict:
    """Predict every job's log on a Dask cluster and write the manifest.

    Parameters
    ----------
    jobs : sequence of FleetJob
        All with the same model and output directory (:func:`fleet_jobs`).
    scheduler : str, optional
        Address of a running ``dask.distributed`` scheduler (``tcp://host:8786``); default a local
        cluster of ``workers`` processes, one thread each.
    workers : int, optional
        Processes of the local cluster (default: the machine's cores).
    progress : callable, optional
        ``progress(done, total, entry)`` after each log.

    Returns
    -------
    dict
        The manifest (also written to ``OUT/_manifest.json``).

    Raises
    ------
    GreyboxError
        When the scheduler cannot be reached or the jobs disagree on model or output.
    """
    if not jobs:
        raise GreyboxError("no log to predict")
    models, outs = {job.model for job in jobs}, {job.out_dir for job in jobs}
    if len(models) != 1 or len(outs) != 1:
        raise GreyboxError("a fleet run has one model file and one output directory")
    out_dir = Path(outs.pop())
    out_dir.mkdir(parents=True, exist_ok=True)
    model = models.pop()
    model_hash = _file_hash(model)
    started = time.perf_counter()
    previous = _previous(out_dir, model_hash)
    entries, todo, total = [], [], len(jobs)
    for job in jobs:
        kept = previous.get(job.log)
        if kept is not None and {k: kept.get(k) for k in ("size", "mtime_ns")} == _log_stamp(job.log):
            entries.append({**kept, "status": "skipped"})
            if progress is not None:
                progress(len(entries), total, entries[-1])
        else:
            todo.append(job)
    cluster_info = _run_on_cluster(todo, scheduler, workers, entries, total, progress)
    manifest = {"format": "greybox-fleet", "format_version": 1, "model": model, "model_sha256": model_hash,
                "axis_config": jobs[0].axis_config, "read": jobs[0].read, "chunk_s": jobs[0].chunk_s,
                "cluster": cluster_info, "versions": _versions(), "seconds": time.perf_counter() - started,
                "counts": {status: sum(entry["status"] == status for entry in entries)
                           for status in ("ok", "skipped", "failed")},
                "logs": sorted(entries, key=lambda entry: entry["log"])}
    write_text_atomic(out_dir / MANIFEST, json.dumps(manifest, indent=1) + "\n")
    return manifest


def _run_on_cluster(todo, scheduler, workers, entries, total, progress) -> dict:
    if not todo:
        return {"scheduler": scheduler, "workers": 0}
    import logging

    from distributed import Client, LocalCluster, as_completed

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="5s")
        except (OSError, TimeoutError) as error:
            raise GreyboxError(f"--scheduler {scheduler}: cannot reach the Dask scheduler ({error})") from None
        cluster = None
    else:
        # one thread per worker process, compiled kernels included: the processes share out the cores
        cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.ERROR,
                               env={"NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"})
        client = Client(cluster)
    try:
        info = {"scheduler": scheduler or "local", "workers": len(client.scheduler_info().get("workers", {}))}
        futures = client.map(predict_log, todo, pure=False)
        for future in as_completed(futures):
            entry = future.result()
            entries.append(entry)
            if progress is not None:
                progress(len(entries), total, entry)
        return info
    finally:
        client.close()
        if cluster is not None:
            cluster.close()

