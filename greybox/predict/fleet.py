"""``greybox predict`` over many logs: one task per log on Dask, a Parquet dataset partitioned like the plant.

:func:`run_fleet` predicts each log (:func:`predict_log`, on a worker of :func:`greybox.fleet.run_tasks`)
and writes its process table to a Parquet dataset partitioned like the plant::

    OUT/machine=<folder of the log>/axis=<axis>/log=<name>/part-0.parquet

where ``<name>`` is the log's path relative to the deepest folder holding every log of the run, suffix
kept, percent-encoded (:func:`greybox.fleet.encode_name`: ``mill1%2Fmonday.mcap``): two distinct logs
never share an output, and ``pyarrow.dataset.dataset(OUT, partitioning="hive")`` reads the dataset whole
with the partition columns, ``log`` decoded to the relative path. Names a file system would merge (logs
whose paths differ only in case) or cannot hold (over 255 bytes) are refused before anything is written.
The manifest records what ran: every log with its status (``ok``, ``skipped``, ``failed`` with its
one-line error), output name, output, samples, seconds and the worker's peak memory, the log's SHA-256,
its model file and the file's SHA-256, the versions of greybox and its libraries, the cluster and the wall
time. A re-run skips every log whose output is complete: listed ``ok`` in the manifest under the same
output name for the same model file (hash) and the same log file (size and modification time), its output
still there, also after a run that was killed. The
model is one model file, or a directory of models written by ``greybox train --per-machine``, from which
each log gets its machine's model (:func:`machine_models`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

from ..data.reading import read_prepared
from ..errors import GreyboxError
from ..fleet import (
    MANIFEST,
    MODELS_FORMAT,
    attempt,
    check_machines,
    check_names,
    encode_name,
    log_names,
    log_stamp,
    machine_of,
    out_dir_of,
    partition,
    read_manifest,
    run_tasks,
)
from ..provenance import file_sha256

__all__ = ["FORMAT_VERSION", "PREDICT_FORMAT", "FleetJob", "fleet_jobs", "machine_models", "model_of_log",
           "predict_log", "run_fleet"]

#: ``format`` of the manifest of a fleet prediction.
PREDICT_FORMAT = "greybox-fleet"

#: ``format_version`` of that manifest: 3 since the outputs are named by the log's relative path
#: (:func:`greybox.fleet.log_names`); a directory of another version is refused.
FORMAT_VERSION = 3


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
    name : str
        The log's output name, its ``log=`` partition value (:func:`greybox.fleet.encode_name` of its
        path relative to the folder of all the run's logs).
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
    name: str
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

    Parameters
    ----------
    directory : str or path-like
        Output directory of ``greybox train --per-machine``, with its manifest.
    log : str or path-like
        Log file; its folder names its machine.
    axis : str, optional
        The axis whose model to take where the machine has models of several.

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
    """One job per log; the machine is the name of the log's folder, the output name its relative path.

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
        For a models directory without a model of a log's machine (or axis), or output names a file system
        would merge or cannot hold (:func:`greybox.fleet.check_names`).
    """
    read = dict(read or {})
    names = [encode_name(name) for name in log_names(logs)]
    check_names([str(log) for log in logs], names)
    check_machines(logs)
    if os.path.isdir(model):
        models = machine_models(model)
        chosen = [_model_for(Path(log), machine_of(log), models, model, read.get("axis")) for log in logs]
    else:
        chosen = [str(model)] * len(logs)
    return [FleetJob(str(log), machine_of(log), path, str(out_dir), name, axis_config, read, float(chunk_s))
            for log, path, name in zip(logs, chosen, names)]


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
        ``log_sha256``, ``seconds``, ``peak_rss_mb`` (of the worker process so far), and for a failure its
        ``error`` (one line). Never raises for a bad log.
    """
    return {"log": job.log, "machine": job.machine, **attempt(job.log, lambda: _predict_and_write(job))}


def _predict_and_write(job: FleetJob) -> dict:
    """The table ``greybox predict`` writes for the job's log, streamed where ``predict`` streams it."""
    from ..data.axis_config import read_axis_config
    from ..persistence import load_model
    from .output import write_process
    from .process import predict_process

    config = read_axis_config(job.axis_config) if job.axis_config else None
    model = load_model(job.model)
    attrs = {"model_file": job.model, "log_file": job.log}
    digest = file_sha256(job.log)
    streamed = _stream_and_write(job, model, config, attrs)
    if streamed is not None:
        return {**streamed, "log_sha256": digest}
    runs = read_prepared(job.log, job.read, columns=config.channels if config else None)
    result = predict_process(model, runs, axis_config=config, chunk_s=job.chunk_s)
    result.attrs.update(attrs)
    target, axis = _partition(job, result.axis)
    path = write_process(result, target, overwrite=True)  # the table `predict` writes
    return {"output": str(path), "axis": axis, "samples": len(result.time), "log_sha256": digest}


def _partition(job: FleetJob, axis: str) -> tuple[Path, str]:
    """The job's table in the dataset (its directory made), and the name of its axis partition."""
    name = partition(axis or "-")
    target = Path(job.out_dir) / f"machine={job.machine}" / f"axis={name}" / f"log={job.name}"
    target.mkdir(parents=True, exist_ok=True)
    return target / "part-0.parquet", name


def _stream_and_write(job: FleetJob, model, config, attrs: dict) -> dict | None:
    """Predict and write the log block by block (:mod:`greybox.data.stream`); None if it is to be read whole."""
    from ..data.blocks import CannotStream
    from ..data.stream import open_stream
    from .stream import stream_process

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
    earlier = read_manifest(out_dir, PREDICT_FORMAT).get("format_version", FORMAT_VERSION)
    if earlier != FORMAT_VERSION:  # its outputs are named otherwise: a re-run would leave them beside the new ones
        raise GreyboxError(f"{out_dir}: holds the dataset of an earlier greybox, whose outputs are named "
                           f"otherwise (manifest format version {earlier}, now {FORMAT_VERSION}); choose another "
                           "output directory")
    files = {job.model for job in jobs} | {job.axis_config for job in jobs if job.axis_config}
    hashes = {path: file_sha256(path) for path in files}
    fingerprints = [{"log": job.log, "name": job.name, "model": job.model, "model_sha256": hashes[job.model],
                     **log_stamp(job.log),
                     "axis_config_sha256": hashes.get(job.axis_config), "read": job.read, "chunk_s": job.chunk_s}
                    for job in jobs]  # an option or axis file changed: the log is predicted again
    header = {"format": PREDICT_FORMAT, "format_version": FORMAT_VERSION, "axis_config": jobs[0].axis_config,
              "read": jobs[0].read, "chunk_s": jobs[0].chunk_s}
    return run_tasks(predict_log, jobs, fingerprints, out_dir=out_dir, header=header, items="logs",
                     scheduler=scheduler, workers=workers, force=force, progress=progress)
