"""``greybox predict`` over many logs: one task per log on Dask, a Parquet dataset partitioned like the plant.

:func:`predict_fleet` is the entry point (``greybox predict`` with several logs, a directory or a pattern:
:func:`greybox.predict.run.is_fleet`); :func:`run_fleet` predicts each log (:func:`predict_log`, on a worker
of :func:`greybox.fleet.run_tasks`) with what :mod:`greybox.predict` predicts one log with,
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
each log gets its machine's model (:func:`greybox.models.plant.machine_models`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

from ..data.reading import read_prepared
from ..errors import GreyboxError
from ..models.chunked import DEFAULT_CHUNK_S
from ..models.plant import MANIFEST, machine_models, machine_of, model_for, partition, read_manifest
from ..predict.request import Prediction, named
from ..provenance import file_sha256
from .engine import (
    attempt,
    check_machines,
    check_names,
    check_out_dir,
    encode_name,
    expand_logs,
    fleet_summary,
    log_names,
    log_stamp,
    out_dir_of,
    run_tasks,
)

__all__ = ["FORMAT_VERSION", "PREDICT_FORMAT", "FleetJob", "fleet_jobs", "predict_fleet", "predict_log",
           "run_fleet"]

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
        chosen = [model_for(Path(log), machine_of(log), models, model, read.get("axis")) for log in logs]
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
    from ..models.files import load_model
    from ..predict.output import write_process
    from ..predict.process import predict_process

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
    from ..predict.stream import stream_process

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


def predict_fleet(model: str | os.PathLike, logs: Sequence[str | os.PathLike], *, out: str | os.PathLike,
                  axis_config: str | None = None, chunk_s: float = DEFAULT_CHUNK_S, read: dict | None = None,
                  force: bool = False, scheduler: str | None = None, workers: int | None = None,
                  progress: Callable[[int, int, dict], None] | None = None, machine: str | None = None,
                  calibration: Sequence[str] | None = None, coverage: float | None = None, plot: str | None = None,
                  plot_window: tuple[float, float] | None = None, relevel: bool = False) -> Prediction:
    """Predict every log as a task on Dask and write the partitioned dataset and its manifest; the run's summary.

    It takes the options of :func:`greybox.predict.predict_logs` (the one-log entry point) by the same names,
    so that a caller switches between the two on :func:`greybox.predict.run.is_fleet`.

    Parameters
    ----------
    model : str or path-like
        A model file for every log, or the models directory of ``greybox train --per-machine`` (each log
        predicted with its machine's model). A machine model (``greybox train --axes``) is refused.
    logs : sequence of str or path-like
        Log files, directories searched recursively, glob patterns (:func:`greybox.fleet.expand_logs`).
    out : str or path-like
        The dataset directory (not one of the inputs).
    axis_config : str, optional
        Axis file (TOML) of every log's axis: adds the process force.
    chunk_s : float, default 60.0
        Chunk length of the model [s].
    read : dict, optional
        Options of reading and preparing the logs (:func:`greybox.data.reading.read_prepared`).
    force : bool, default False
        Predict again the logs complete from an earlier run.
    scheduler : str, optional
        Address of a dask.distributed scheduler (default a local cluster).
    workers : int, optional
        Processes of the local cluster.
    progress : callable, optional
        ``progress(done, total, entry)`` after each log.
    machine, calibration, coverage, plot, plot_window : None
        Options of one log: refused (a fleet run writes the process tables).
    relevel : bool, default False
        An option of one log: refused when true.

    Returns
    -------
    Prediction
        The summary and failure lines in ``closing``, the manifest, the exit status (2 when a log failed).

    Raises
    ------
    GreyboxError
        For an option of one log, a machine model, a bad model file, an output directory that is a file or
        an input, or a scheduler that cannot be reached.
    """
    for setting, value in (("plot", plot), ("plot_window", plot_window), ("calibration", calibration),
                           ("coverage", coverage), ("machine", machine), ("relevel", relevel or None)):
        if value is not None:
            raise GreyboxError(named(setting), " applies to one log; a fleet run (several logs) writes the "
                               "process tables")
    from ..models.files import load_model
    from ..models.machine import is_machine_model

    if is_machine_model(model):
        raise GreyboxError(f"{model}: a fleet run takes one model file; run one fleet per axis of the machine "
                           "model with its file and ", named("axis"))
    out = check_out_dir(out)
    jobs = fleet_jobs(expand_logs([str(log) for log in logs], exclude=[out]), str(Path(model).resolve()), str(out),
                      axis_config=str(Path(axis_config).resolve()) if axis_config else None, read=dict(read or {}),
                      chunk_s=chunk_s)
    for path in sorted({job.model for job in jobs}):
        load_model(path)  # a bad model file is one error before any cluster starts
    manifest = run_fleet(jobs, scheduler=scheduler, workers=workers, force=force, progress=progress)
    lines, status = fleet_summary(manifest, "logs", "predicted", lambda entry: entry["error"])
    if manifest["counts"]["ok"] + manifest["counts"]["skipped"]:
        lines.append(f"wrote {out / MANIFEST} and the dataset {out}/machine=*/axis=*/log=*/part-0.parquet")
    else:
        lines.append(f"wrote {out / MANIFEST} (every log failed: no output)")
    return Prediction(closing=lines, status=status, manifest=manifest)
