"""A plant's worth of logs on dask.distributed: the engine of fleet runs, and ``greybox predict`` over many logs.

:func:`expand_logs` turns files, directories (searched recursively for log files) and glob patterns
into the list of logs. :func:`run_tasks` is the one engine of every fleet run (``greybox predict`` here,
``greybox train --per-machine`` in :mod:`greybox.fleet_train`): it runs one task per job on a Dask
cluster, by default a local cluster of processes, one per core and one thread each, or the cluster of a
scheduler address, so that the same command runs on a laptop and on a cluster; it skips the jobs
complete from an earlier run, reports a job that fails and goes on, and writes ``OUT/_manifest.json``.

:func:`run_fleet` predicts each log and writes its process table to a Parquet dataset partitioned like
the plant::

    OUT/machine=<folder of the log>/axis=<axis>/log=<file stem>/part-0.parquet

(``pyarrow.dataset.dataset(OUT, partitioning="hive")`` reads it whole, with the partition columns).
The manifest records what ran: every log with its status (``ok``, ``skipped``, ``failed`` with its
one-line error), output, samples, seconds and the worker's peak memory, its model file and the file's
SHA-256, the versions of greybox and its libraries, the cluster and the wall time. A re-run skips every
log whose output is complete: listed ``ok`` in the manifest for the same model file (hash) and the same
log file (size and modification time), its output still there, also after a run that was killed (the
manifest is saved while the fleet runs). Every file is written atomically. The model is one model file,
or a directory of models written by ``greybox train --per-machine``, from which each log gets its
machine's model (:func:`machine_models`).
"""

from __future__ import annotations

import contextlib
import glob
import hashlib
import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterator, Mapping, Sequence

from .atomic import write_text_atomic
from .errors import GreyboxError

__all__ = ["LOG_SUFFIXES", "MANIFEST", "MODELS_FORMAT", "SAVE_EVERY_S", "FleetJob", "attempt", "expand_logs",
           "fleet_jobs", "log_stamp", "machine_models", "machine_of", "out_dir_of", "partition", "predict_log",
           "read_manifest", "read_prepared", "run_fleet", "run_tasks"]

#: File extensions taken as logs when a directory is given.
LOG_SUFFIXES = (".csv", ".parquet", ".pq", ".mcap", ".mat", ".tdms")

#: Name of the manifest in the output directory (a leading "_": dataset readers skip it).
MANIFEST = "_manifest.json"

#: ``format`` of the manifest of a directory of models written by ``greybox train --per-machine``.
MODELS_FORMAT = "greybox-fleet-models"

#: ``format`` of the manifest of a fleet prediction.
PREDICT_FORMAT = "greybox-fleet"

#: Least time between two saves of the manifest while a fleet runs [s]: the jobs finished so far are kept
#: for a re-run when a run is killed.
SAVE_EVERY_S = 10.0

_GLOB_CHARACTERS = set("*?[")


def expand_logs(items: Sequence[str]) -> list[Path]:
    """The log files named by files, directories (searched recursively) and glob patterns, each once.

    Directories and patterns yield the files with a log extension (:data:`LOG_SUFFIXES`), so that a CSV
    log's metadata sidecar or a manifest beside the logs is not taken for a log.

    Parameters
    ----------
    items : sequence of str
        Log files, directories and glob patterns (``**`` matches across directories).

    Returns
    -------
    list of pathlib.Path
        The logs, resolved to absolute paths, in the order found; a file named twice appears once.

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
        raise GreyboxError("no log given")
    return unique


def partition(value: str) -> str:
    """A partition value safe in a path: letters, digits, ``-``, ``_`` and ``.``.

    Parameters
    ----------
    value : str
        Name to make safe; every other character becomes ``_``, and an empty name ``_``.
    """
    return "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in value) or "_"


def machine_of(log: str | os.PathLike) -> str:
    """The machine a log belongs to: the name of its folder, made safe for a path (:func:`partition`).

    Parameters
    ----------
    log : str or path-like
        Log file.
    """
    return partition(Path(log).parent.name)


def log_stamp(path: str | os.PathLike) -> dict:
    """``size`` [bytes] and ``mtime_ns`` [ns] of a file: a log changed since a run differs in one of them.

    Parameters
    ----------
    path : str or path-like
        An existing file.
    """
    stat = os.stat(path)
    return {"size": stat.st_size, "mtime_ns": stat.st_mtime_ns}


def read_prepared(path: str, read: Mapping, *, columns: Mapping[str, str] | None = None) -> list:
    """Read and prepare one log as ``greybox predict`` and ``greybox train`` do: its runs (AxisLog).

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
    """
    from .data.io import read_log
    from .data.prepare import MAX_GAP_STEPS, prepare

    columns = {**(columns or {}), **(read.get("columns") or {})} or None
    resample = read.get("resample")
    tolerance = read.get("time_tolerance", 0.25)
    log = read_log(path, columns=columns, topic=read.get("topic"), sample_time=read.get("sample_time"),
                   axis=read.get("axis"), time_tolerance=None if resample else tolerance)
    return prepare([log], cutoff_hz=read.get("cutoff_hz"), sample_time=resample, tolerance=tolerance,
                   max_gap_steps=read.get("max_gap", MAX_GAP_STEPS))


def attempt(label: str, work: Callable[[], dict]) -> dict:
    """Run one task's ``work`` on a worker and say how it went; never raises for bad input.

    Parameters
    ----------
    label : str
        What the task works on (e.g. the log file), named in the error of a failure that is a bug.
    work : callable
        ``work() -> dict``: does the task and returns the fields of its entry; a
        :class:`GreyboxError` it raises is reported as the failure.

    Returns
    -------
    dict
        ``status`` ``ok`` with what ``work`` returned, ``seconds`` and ``peak_rss_mb`` (of the worker
        process so far [MB]); or ``failed`` with ``error``, one line (a bug is named an internal
        error of ``label``), and ``seconds``.
    """
    started = time.perf_counter()
    try:
        result = work()
    except GreyboxError as error:
        return {"status": "failed", "error": str(error), "seconds": time.perf_counter() - started}
    except Exception as error:  # a bug, not bad input: reported in the manifest, the fleet goes on
        return {"status": "failed", "error": f"{label}: internal error {type(error).__name__}: {error}",
                "seconds": time.perf_counter() - started}
    return {"status": "ok", **result, "seconds": time.perf_counter() - started, "peak_rss_mb": _peak_rss_mb()}


def _peak_rss_mb() -> float | None:
    """Peak resident memory of this (worker) process so far [MB]; None where the OS does not say.

    On Linux ``VmHWM`` of ``/proc/self/status``: ``ru_maxrss`` keeps across ``exec`` the peak of the
    process the worker was forked from (a large parent would be counted as the worker's own).
    """
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            return next(int(line.split()[1]) for line in status if line.startswith("VmHWM:")) / 1024.0
    except (OSError, StopIteration, ValueError, IndexError):
        pass
    try:
        import resource
    except ImportError:  # not on Windows
        return None
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / 1024.0 if os.uname().sysname != "Darwin" else peak / 2**20


def _canonical(value) -> str:
    return json.dumps(value, sort_keys=True)


def _load_manifest(directory: str | os.PathLike) -> dict:
    """The manifest in ``directory`` of any format, or ``{}`` when there is none or it is unreadable."""
    path = Path(directory) / MANIFEST
    if not path.is_file():
        return {}
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError):
        return {}
    return document if isinstance(document, dict) else {}


def read_manifest(directory: str | os.PathLike, fmt: str) -> dict:
    """The manifest of ``fmt`` in ``directory``, or ``{}`` when there is none, it is unreadable or of another format.

    Parameters
    ----------
    directory : str or path-like
        Output directory holding :data:`MANIFEST`.
    fmt : str
        The ``format`` the manifest must have (:data:`MODELS_FORMAT`, or that of a fleet prediction).
    """
    document = _load_manifest(directory)
    return document if document.get("format") == fmt else {}


def _complete(document: dict, items: str, out_dir: Path, fields: Sequence[str]) -> dict:
    """Entries of an earlier manifest a re-run may keep, by their ``fields``: ok, output still there."""
    kept = {}
    for entry in document.get(items, []):
        if isinstance(entry, dict) and entry.get("status") in ("ok", "skipped") and \
                isinstance(entry.get("output"), str) and (out_dir / entry["output"]).is_file():
            kept[_canonical({name: entry.get(name) for name in fields})] = entry
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


def run_tasks(task: Callable, jobs: Sequence, fingerprints: Sequence[dict], *, out_dir: str | os.PathLike,
              header: dict, items: str, scheduler: str | None = None, workers: int | None = None,
              force: bool = False, progress: Callable[[int, int, dict], None] | None = None) -> dict:
    """Run ``task(job)`` for every job not complete from an earlier run, on a Dask cluster; write the manifest.

    Parameters
    ----------
    task : callable
        Picklable function a worker runs, ``task(job) -> dict`` (an entry with ``status``, ``output``
        relative to ``out_dir`` or absolute, ...; see :func:`attempt`).
    jobs : sequence
        Picklable jobs.
    fingerprints : sequence of dict
        Per job, what makes its output current (its inputs' names, stamps, options), JSON values,
        the same keys for all jobs; merged into its entry. A job whose fingerprint matches an ``ok``
        entry of the earlier manifest, its output still there, is skipped.
    out_dir : path-like
        Output directory (created); the manifest is ``out_dir/_manifest.json``.
    header : dict
        First fields of the manifest; ``header["format"]`` names its format.
    items : str
        Name of the manifest's list of entries (``"logs"``, ``"models"``), in the order of ``jobs``.
    scheduler : str, optional
        Address of a running ``dask.distributed`` scheduler (``tcp://host:8786``); default a local
        cluster of ``workers`` processes, one thread each.
    workers : int, optional
        Processes of the local cluster (default: the machine's cores).
    force : bool, default False
        Run every job, whatever the earlier manifest says.
    progress : callable, optional
        ``progress(done, total, entry)`` after each job.

    While the jobs run, the manifest lists those finished, saved at most every :data:`SAVE_EVERY_S`
    seconds, so that a re-run after the run was killed skips them.

    Returns
    -------
    dict
        The manifest: ``header``, ``cluster``, ``versions``, ``seconds`` (wall time [s]), ``counts``
        per status and the entries.

    Raises
    ------
    GreyboxError
        When ``out_dir`` holds the manifest of another kind of fleet run, or the scheduler cannot be reached.
    """
    out_dir = Path(out_dir)
    other = _load_manifest(out_dir).get("format", header["format"])
    if other != header["format"]:
        raise GreyboxError(f"{out_dir}: holds the {MANIFEST} of another kind of run ({other}); choose another "
                           "output directory")
    out_dir.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    fields = list(fingerprints[0]) if fingerprints else []
    previous = {} if force else _complete(read_manifest(out_dir, header["format"]), items, out_dir, fields)
    entries: list[dict | None] = [None] * len(jobs)
    done, saved = 0, time.perf_counter()

    def finish(index: int, entry: dict) -> None:
        nonlocal done, saved
        entries[index] = {**entry, **fingerprints[index]}
        done += 1
        if time.perf_counter() - saved >= SAVE_EVERY_S:  # a run killed later keeps what is done
            _write_manifest(out_dir, {**header, items: [entry for entry in entries if entry is not None]})
            saved = time.perf_counter()
        if progress is not None:
            progress(done, len(jobs), entries[index])

    todo = []
    for index, fingerprint in enumerate(fingerprints):
        kept = previous.get(_canonical(fingerprint))
        if kept is not None:
            finish(index, {**kept, "status": "skipped"})
        else:
            todo.append(index)
    cluster = _run_on_cluster(task, [(index, jobs[index]) for index in todo], scheduler, workers, finish)
    manifest = {**header, "cluster": cluster, "versions": _versions(), "seconds": time.perf_counter() - started,
                "counts": {status: sum(entry["status"] == status for entry in entries)
                           for status in ("ok", "skipped", "failed")},
                items: entries}
    _write_manifest(out_dir, manifest)
    return manifest


def _write_manifest(out_dir: Path, manifest: dict) -> None:
    """Write ``out_dir/_manifest.json`` atomically."""
    write_text_atomic(out_dir / MANIFEST, json.dumps(manifest, indent=1) + "\n")


def out_dir_of(jobs: Sequence, nothing: str) -> str:
    """The one output directory of a fleet's jobs (their ``out_dir``).

    Parameters
    ----------
    jobs : sequence
        Jobs with an ``out_dir`` attribute (:class:`FleetJob`, or those of ``greybox train --per-machine``).
    nothing : str
        Error message for no job at all.

    Raises
    ------
    GreyboxError
        With the message ``nothing`` for no job, or for jobs that disagree.
    """
    if not jobs:
        raise GreyboxError(nothing)
    outs = {job.out_dir for job in jobs}
    if len(outs) != 1:
        raise GreyboxError("a fleet run has one output directory")
    return outs.pop()


@contextlib.contextmanager
def _client(scheduler: str | None, workers: int | None) -> Iterator:
    """A Dask client of the scheduler at ``scheduler``, or of a local cluster of ``workers`` processes."""
    import logging

    from distributed import Client, LocalCluster

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
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _run_on_cluster(task: Callable, todo: list, scheduler: str | None, workers: int | None,
                    finish: Callable[[int, dict], None]) -> dict:
    """Run ``task`` on every ``(index, job)`` of ``todo``; ``finish(index, entry)`` as each ends; the cluster."""
    if not todo:
        return {"scheduler": scheduler, "workers": 0}
    from distributed import as_completed

    with _client(scheduler, workers) as client:
        info = {"scheduler": scheduler or "local", "workers": len(client.scheduler_info().get("workers", {}))}
        futures = client.map(task, [job for _, job in todo], pure=False)
        index = {future.key: position for future, (position, _) in zip(futures, todo)}
        for future in as_completed(futures):
            error = future.exception() if future.status == "error" else None
            finish(index[future.key], future.result() if error is None else
                   {"status": "failed", "error": f"lost on the cluster: {type(error).__name__}: {error}"})
        return info


@dataclass(frozen=True)
class FleetJob:
    """One log of a fleet prediction: what to read, with which model, and where the outputs go.

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
        Options of reading and preparing the log (:func:`read_prepared`).
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


def machine_models(directory: str | os.PathLike) -> dict[str, dict[str, str]]:
    """The models of a directory written by ``greybox train --per-machine``: ``{machine: {axis: model file}}``.

    Only the models its manifest lists as trained (``ok`` or ``skipped``) whose file is there count.

    Parameters
    ----------
    directory : str or path-like
        Output directory of ``greybox train --per-machine``, with its manifest.

    Raises
    ------
    GreyboxError
        For a directory without such a manifest.
    """
    directory = Path(directory)
    document = read_manifest(directory, MODELS_FORMAT)
    if not document:
        raise GreyboxError(f"{directory}: a directory without the {MANIFEST} of 'greybox train --per-machine'; "
                           "give a model file or a directory of models it wrote")
    table: dict[str, dict[str, str]] = {}
    for entry in document.get("models", []):
        if isinstance(entry, dict) and entry.get("status") in ("ok", "skipped") and \
                isinstance(entry.get("output"), str) and (directory / entry["output"]).is_file():
            table.setdefault(str(entry.get("machine")), {})[str(entry.get("axis"))] = str(directory / entry["output"])
    return table


def model_of_log(directory: str | os.PathLike, log: str | os.PathLike, axis: str | None = None) -> str:
    """The model file of ``log``'s machine (the name of its folder) in a directory of ``greybox train --per-machine``.

    Raises
    ------
    GreyboxError
        For a directory without that manifest, a machine without a model, or (without ``axis``) a machine
        with models of several axes.
    """
    return _model_for(Path(log), machine_of(Path(log)), machine_models(directory), str(directory), axis)


def _model_for(log: Path, machine: str, models: dict[str, dict[str, str]], directory: str, axis: str | None) -> str:
    """The model file of ``log``'s machine in a models directory (of ``axis`` where it has several)."""
    by_axis = models.get(machine)
    if not by_axis:
        known = ", ".join(sorted(models)) or "none"
        raise GreyboxError(f"{log}: no trained model of machine {machine} in {directory} (machines: {known})")
    if axis is not None:
        if axis not in by_axis:
            raise GreyboxError(f"{log}: --axis {axis}: machine {machine} has models of axes "
                               f"{', '.join(sorted(by_axis))}")
        return by_axis[axis]
    if len(by_axis) > 1:
        raise GreyboxError(f"{log}: machine {machine} has models of axes {', '.join(sorted(by_axis))} in {directory}; "
                           "give --axis NAME (one fleet per axis)")
    return next(iter(by_axis.values()))


def fleet_jobs(logs: Sequence[Path], model: str, out_dir: str, *, axis_config: str | None = None,
               read: dict | None = None, chunk_s: float = 60.0) -> list[FleetJob]:
    """One job per log; the machine is the name of the log's folder.

    ``model`` is one model file for every log, or a directory written by ``greybox train --per-machine``:
    each log then gets its machine's model (of ``read["axis"]`` where the machine has several).

    Parameters
    ----------
    logs : sequence of path-like
        Log files (:func:`expand_logs`); each one's folder names its machine.
    model : str
        Model file, or directory of models of ``greybox train --per-machine``.
    out_dir : str
        Root of the Parquet dataset the jobs write.
    axis_config : str, optional
        Axis file (force or torque) used for every log.
    read : dict, optional
        Options of reading and preparing the logs (:func:`read_prepared`); its ``axis`` also picks the
        model in a models directory.
    chunk_s : float, default 60.0
        Chunk length of the prediction [s].

    Raises
    ------
    GreyboxError
        For a models directory without a model of a log's machine (or axis).
    """
    read = dict(read or {})
    if os.path.isdir(model):
        models = machine_models(model)
        chosen = [_model_for(Path(log), machine_of(log), models, model, read.get("axis")) for log in logs]
    else:
        chosen = [str(model)] * len(logs)
    return [FleetJob(str(log), machine_of(log), path, str(out_dir), axis_config, read, float(chunk_s))
            for log, path in zip(logs, chosen)]


def _file_hash(path: str) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def predict_log(job: FleetJob) -> dict:
    """Predict one log and write its process table; the task each worker runs.

    Parameters
    ----------
    job : FleetJob
        The log, its model and options, and the dataset it is written to.

    Returns
    -------
    dict
        ``log``, ``machine``, ``status`` (``ok`` or ``failed``), ``output``, ``axis``, ``samples``,
        ``seconds``, ``peak_rss_mb`` (of the worker process so far), and for a failure its ``error``
        (one line). Never raises for a bad log.
    """
    return {"log": job.log, "machine": job.machine, **attempt(job.log, lambda: _predict_and_write(job))}


def _predict_and_write(job: FleetJob) -> dict:
    """The table ``greybox predict`` writes for the job's log, streamed where ``predict`` streams it."""
    from .data.axis_config import read_axis_config
    from .evaluate.process import predict_process
    from .evaluate.process_io import write_process
    from .persistence import load_model

    config = read_axis_config(job.axis_config) if job.axis_config else None
    model = load_model(job.model)
    attrs = {"model_file": job.model, "log_file": job.log}
    streamed = _stream_and_write(job, model, config, attrs)
    if streamed is not None:
        return streamed
    runs = read_prepared(job.log, job.read, columns=config.channels if config else None)
    result = predict_process(model, runs, axis_config=config, chunk_s=job.chunk_s)
    result.attrs.update(attrs)
    target, axis = _partition(job, result.axis)
    path = write_process(result, target, overwrite=True)  # the table `predict` writes
    return {"output": str(path), "axis": axis, "samples": len(result.time)}


def _partition(job: FleetJob, axis: str) -> tuple[Path, str]:
    """The job's table in the dataset (its directory made), and the name of its axis partition."""
    name = partition(axis or "-")
    target = Path(job.out_dir) / f"machine={job.machine}" / f"axis={name}" / f"log={partition(Path(job.log).stem)}"
    target.mkdir(parents=True, exist_ok=True)
    return target / "part-0.parquet", name


def _stream_and_write(job: FleetJob, model, config, attrs: dict) -> dict | None:
    """Predict and write the log block by block (:mod:`greybox.data.stream`); None if it is to be read whole."""
    from .data.blocks import CannotStream
    from .data.stream import open_stream
    from .evaluate.process_stream import stream_process

    read = job.read
    columns = {**(config.channels if config else {}), **(read.get("columns") or {})} or None
    log = open_stream(job.log, columns=columns, topic=read.get("topic"), axis=read.get("axis"),
                      sample_time=read.get("sample_time"), resample=read.get("resample"))
    if log is None:
        return None
    target, axis = _partition(job, log.axis or (config.name if config is not None else ""))
    try:
        done = stream_process(model, log, target, axis_config=config, chunk_s=job.chunk_s,
                              tolerance=read.get("time_tolerance", 0.25), cutoff_hz=read.get("cutoff_hz"),
                              attrs=attrs, overwrite=True)
    except CannotStream:
        return None
    return {"output": str(target), "axis": axis, "samples": done.tally.n_samples}


def run_fleet(jobs: Sequence[FleetJob], *, scheduler: str | None = None, workers: int | None = None,
              force: bool = False, progress: Callable[[int, int, dict], None] | None = None) -> dict:
    """Predict every job's log on a Dask cluster and write the manifest (:func:`run_tasks`).

    Parameters
    ----------
    jobs : sequence of FleetJob
        All with the same output directory (:func:`fleet_jobs`).
    scheduler, workers, force, progress
        The cluster, whether to predict again the logs complete from an earlier run, and the progress
        callback, as in :func:`run_tasks`.

    Returns
    -------
    dict
        The manifest (also written to ``OUT/_manifest.json``).

    Raises
    ------
    GreyboxError
        When the scheduler cannot be reached or the jobs disagree on the output directory.
    """
    out_dir = out_dir_of(jobs, "no log to predict")
    files = {job.model for job in jobs} | {job.axis_config for job in jobs if job.axis_config}
    hashes = {path: _file_hash(path) for path in files}
    fingerprints = [{"log": job.log, "model": job.model, "model_sha256": hashes[job.model], **log_stamp(job.log),
                     "axis_config_sha256": hashes.get(job.axis_config), "read": job.read, "chunk_s": job.chunk_s}
                    for job in jobs]  # an option or axis file changed: the log is predicted again
    header = {"format": PREDICT_FORMAT, "format_version": 2, "axis_config": jobs[0].axis_config,
              "read": jobs[0].read, "chunk_s": jobs[0].chunk_s}
    return run_tasks(predict_log, jobs, fingerprints, out_dir=out_dir, header=header, items="logs",
                     scheduler=scheduler, workers=workers, force=force, progress=progress)
