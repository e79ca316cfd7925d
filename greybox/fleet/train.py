"""``greybox train --per-machine``: one model per machine and axis of a plant's logs, trained on dask.distributed.

The machine of a log is the name of its folder (as in the ``machine=`` partition of a fleet prediction;
folders of one name in different places are one machine).
Each machine's model of an axis is fitted on all that machine's logs, one Dask task per (machine, axis),
on the engine of every fleet run (:func:`greybox.fleet.run_tasks`: a local cluster or a scheduler
address, failures reported while the rest go on, complete models skipped on a re-run). The output
directory (manifest format ``greybox-fleet-models``)::

    OUT/<machine>/<axis>.gbm     the model of one axis of one machine, an ordinary greybox model file with
                                 the training record of every model (:func:`greybox.train.train_logs`)
    OUT/_manifest.json           every model: machine, axis, the logs it was fitted on (paths, sizes,
                                 modification times), status (ok, skipped, failed with its one-line
                                 error), training RMSE and RE, samples, seconds and the worker's peak
                                 memory, the model kind and hyperparameters, the reading options; the
                                 versions, the cluster and the wall time

With axes to read from logs of several (``--axes``) there is one task per machine and axis; otherwise one
per machine, whose logs must all be of one axis, the model named after it (``-`` where the logs name
none). A re-run skips every model whose entry is ``ok`` for the same logs (size and modification time),
kind, hyperparameters and reading options, its file still there. ``greybox predict OUT LOG... --out DIR``
predicts each log with its machine's model (:func:`greybox.models.plant.model_of_log`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

from ..data.reading import read_prepared
from ..errors import GreyboxError
from ..models.plant import MODELS_FORMAT, machine_of, partition
from .engine import attempt, check_machines, check_out_dir, expand_logs, log_stamp, out_dir_of, run_tasks

__all__ = ["TrainJob", "run_training", "train_fleet", "train_jobs", "train_model"]


@dataclass(frozen=True)
class TrainJob:
    """One model of a fleet: a machine's logs, the axis to read from them and the model to fit.

    Parameters
    ----------
    machine : str
        Machine (the folder name of its logs); the model goes to ``out_dir/<machine>/<axis>.gbm``.
    logs : tuple of str
        The machine's log files, fitted together as separate runs in this order.
    model : estimator
        Unfitted model (a copy is fitted).
    out_dir : str
        Directory of the fleet's models.
    read : dict
        Options of reading and preparing the logs (:func:`greybox.data.reading.read_prepared`); ``read["axis"]``
        the axis read from logs of several, None for the logs' own.
    """

    machine: str
    logs: tuple
    model: object
    out_dir: str
    read: dict


def train_jobs(logs: Sequence[Path], model, out_dir: str, *, axes: Sequence[str] | None = None,
               read: dict | None = None) -> list[TrainJob]:
    """One job per machine (the folder of its logs), or per machine and axis of ``axes``.

    Parameters
    ----------
    logs : sequence of path
        Log files (:func:`greybox.fleet.expand_logs`).
    model : estimator
        Unfitted model, the same kind and hyperparameters for every job.
    out_dir : str
        Directory of the models.
    axes : sequence of str, optional
        Axes to read from logs of several, a model each; default the axis of each machine's logs.
    read : dict, optional
        Options of reading and preparing the logs.
    """
    read = dict(read or {})
    check_machines(logs)
    machines: dict[str, list[str]] = {}
    for log in logs:
        machines.setdefault(machine_of(log), []).append(str(log))
    readings = [{**read, "axis": axis} for axis in axes] if axes else [read]
    return [TrainJob(machine, tuple(paths), model, str(out_dir), reading)
            for machine, paths in machines.items() for reading in readings]


def _hyperparameters(model) -> dict:
    """Kind and hyperparameters of a model as JSON values: a nested model likewise, other values as text."""
    from ..models.registry import model_kind

    def value(item):
        if hasattr(item, "get_params"):
            return _hyperparameters(item)
        return item if item is None or isinstance(item, (bool, int, float, str)) else repr(item)

    return {"kind": model_kind(model),
            "params": {name: value(item) for name, item in sorted(model.get_params(deep=False).items())}}


def _axis_of(runs: list, job: TrainJob) -> str:
    """The axis of a machine's runs: the one read, or the one their logs name."""
    if job.read.get("axis"):
        return job.read["axis"]
    named = sorted({run.axis for run in runs})
    if len(named) > 1:
        sources = {run.axis: Path(run.source or "?").name for run in runs}
        listed = ", ".join(f"{axis or '(unnamed)'} ({sources[axis]})" for axis in named)
        raise GreyboxError(f"machine {job.machine}: its logs are of several axes, {listed}; keep one axis per "
                           "folder, or give --axes for logs that hold several")
    return named[0]


def _fit_and_save(job: TrainJob) -> dict:
    """Train the job's model on all its logs (:func:`greybox.train.train_logs`) and save it, checked."""
    from ..train import train_logs

    runs = [run for log in job.logs for run in read_prepared(log, job.read)]
    axis = partition(_axis_of(runs, job) or "-")
    path = Path(job.out_dir) / job.machine / f"{axis}.gbm"
    path.parent.mkdir(parents=True, exist_ok=True)
    model = train_logs(job.model, runs, files=job.logs, read=job.read, out=path, overwrite=True)
    total = model.training_record_["training_error"]
    return {"axis": axis, "output": str(path.relative_to(job.out_dir)), "runs": len(runs), "samples": total["samples"],
            "effort_unit": total["unit"], "rmse": total["rmse"], "re": total["re_percent"]}


def train_model(job: TrainJob) -> dict:
    """Train and save one model of the fleet; the task each worker runs.

    Parameters
    ----------
    job : TrainJob
        The machine's logs, the axis to read, the unfitted model and the output directory.

    Returns
    -------
    dict
        ``machine``, ``status`` (``ok`` or ``failed``), ``axis``, ``output`` (the model file, relative to
        the output directory), ``runs``, ``samples``, ``effort_unit``, the training ``rmse`` [A or N] and
        ``re`` [%] of the model on all its runs (``RE = RMSE / mean(|effort|)``; from its training record,
        which the saved file reproduces bit for bit), ``seconds``, ``peak_rss_mb``, and for a failure its
        ``error`` (one line). Never raises for a bad log.
    """
    return {"machine": job.machine, **attempt(f"machine {job.machine}", lambda: _fit_and_save(job))}


def run_training(jobs: Sequence[TrainJob], *, scheduler: str | None = None, workers: int | None = None,
                 force: bool = False, progress: Callable[[int, int, dict], None] | None = None) -> dict:
    """Train every job's model on a Dask cluster and write the manifest ``OUT/_manifest.json``.

    Parameters
    ----------
    jobs : sequence of TrainJob
        All with the same output directory (:func:`train_jobs`).
    scheduler, workers, force, progress
        The cluster, whether to train again the models complete from an earlier run, and the progress
        callback, as in :func:`greybox.fleet.run_tasks`.

    Returns
    -------
    dict
        The manifest; its ``models`` list has an entry per job (:func:`train_model`) with the
        ``logs`` it was fitted on (``path``, ``size`` [bytes], ``mtime_ns`` [ns]), the ``model``
        (``kind`` and ``params``) and the ``read`` options.

    Raises
    ------
    GreyboxError
        For no job, jobs that disagree on the output directory, or a scheduler that cannot be reached.
    """
    out_dir = out_dir_of(jobs, "no log to train on")
    fingerprints = [{"machine": job.machine, "read": job.read, "model": _hyperparameters(job.model),
                     "logs": [{"path": log, **log_stamp(log)} for log in job.logs]} for job in jobs]
    return run_tasks(train_model, jobs, fingerprints, out_dir=out_dir,
                     header={"format": MODELS_FORMAT, "format_version": 1}, items="models", scheduler=scheduler,
                     workers=workers, force=force, progress=progress)


def train_fleet(model, logs: Sequence[str], *, out: str | Path, axes: Sequence[str] | None = None,
                read: dict | None = None, scheduler: str | None = None, workers: int | None = None,
                force: bool = False, progress: Callable[[int, int, dict], None] | None = None) -> tuple[Path, dict]:
    """``greybox train --per-machine``: a model per machine (and axis) of the logs, trained on Dask.

    Parameters
    ----------
    model : estimator
        Unfitted model, the same kind and hyperparameters for every machine.
    logs : sequence of str
        Log files, directories searched recursively, glob patterns (:func:`greybox.fleet.expand_logs`); the
        folder of a log names its machine.
    out : str or path
        Directory of the models (not one of ``logs``).
    axes : sequence of str, optional
        Axes to read from logs of several, a model each.
    read : dict, optional
        Options of reading and preparing the logs.
    scheduler, workers, force, progress
        The cluster, whether to train again the models complete from an earlier run, and the progress
        callback, as in :func:`greybox.fleet.run_tasks`.

    Returns
    -------
    (Path, dict)
        The models directory (resolved) and its manifest (:func:`run_training`).
    """
    out = check_out_dir(out, logs)
    jobs = train_jobs(expand_logs(logs, exclude=[out]), model, str(out), axes=axes, read=read)
    return out, run_training(jobs, scheduler=scheduler, workers=workers, force=force, progress=progress)
