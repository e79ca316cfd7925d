"""The one entry point of prediction: :func:`predict_logs` takes a model, logs and an output, and decides the rest.

What it does follows from what it is given:

* the model: a model file (``greybox train``), a machine model directory (``greybox train --axes``:
  every axis of the log, and the resultant force, :mod:`greybox.predict.machine`), or a directory of
  models of ``greybox train --per-machine`` (each log predicted with its machine's model). The kind of
  model source carries what it can do (:func:`~greybox.predict.sources.open_model`): a machine model
  predicts one log of several axes;
* the logs: one log file, predicted in this process. Several logs, a directory or a glob pattern make a
  fleet run (:func:`is_fleet`: one task per log on Dask, a partitioned Parquet dataset), which
  :func:`greybox.fleet.predict.predict_fleet` runs on top of this package; this function refuses it;
* how a log is read: a Parquet or MCAP log of a linear axis, without a picture, resampling or a sample
  time, is read, predicted and written block by block (:mod:`greybox.predict.stream`), so that its
  length does not bound the memory; any other log, or one that turns out not to stream
  (:class:`~greybox.data.blocks.CannotStream`), is read whole (:mod:`greybox.predict.process`);
* what is written: the process table (:mod:`greybox.predict.output`), with a picture when asked
  (:mod:`greybox.predict.plot`), each output refused before any work if it must not or cannot be written.

It returns a :class:`~greybox.predict.request.Prediction`: the lines to show, the figures of each axis
and what was written.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, Mapping, Sequence

from ..errors import GreyboxError
from ..models.chunked import DEFAULT_CHUNK_S
from .request import ChunkProgress, Prediction, Request, named
from .sources import open_model

__all__ = ["is_fleet", "predict_logs"]

_FLEET_CHARACTERS = "*?["


def is_fleet(logs: Sequence[str | os.PathLike]) -> bool:
    """Whether ``logs`` make a fleet run: several logs, a directory or a glob pattern.

    Parameters
    ----------
    logs : sequence of str or path-like
        The logs as given.
    """
    first = str(logs[0])
    return len(logs) > 1 or os.path.isdir(first) or any(ch in first for ch in _FLEET_CHARACTERS)


def predict_logs(model: str | os.PathLike, logs: str | os.PathLike | Sequence[str | os.PathLike], *,
                 out: str | os.PathLike, axis_config: str | None = None, machine: str | None = None,
                 calibration: Sequence[str] | None = None, coverage: float | None = None, plot: str | None = None,
                 plot_mean_s: float = 0.1, plot_window: tuple[float, float] | None = None,
                 chunk_s: float = DEFAULT_CHUNK_S, read: Mapping | None = None, force: bool = False,
                 scheduler: str | None = None, workers: int | None = None,
                 progress: Callable[[ChunkProgress], None] | None = None,
                 notify: Callable[[str], None] | None = None, relevel: bool = False) -> Prediction:
    """Predict the process current (and force) of cutting logs with a model trained on air cuts, and write it.

    Parameters
    ----------
    model : str or path-like
        A model file, a machine model directory, or the models directory of ``greybox train
        --per-machine`` (:func:`~greybox.predict.sources.open_model`).
    logs : str, path-like or sequence of one
        One cutting log (several, a directory or a glob pattern make a fleet run, :func:`is_fleet`: refused,
        :func:`greybox.fleet.predict.predict_fleet` runs it).
    out : str or path-like
        The process table (.csv, .parquet, .mcap).
    axis_config : str, optional
        Axis file (TOML) of a model file's axis: adds the process force (torque on a rotary axis).
    machine : str, optional
        Machine file (TOML) of a machine model: each axis's channels and mechanics.
    calibration : sequence of str, optional
        Air-cut logs the model was not trained on: they calibrate the bounds of the process current.
    coverage : float, optional
        Nominal coverage of the bounds, in (0, 1) (default :data:`~greybox.predict.interval.DEFAULT_COVERAGE`;
        needs ``calibration``).
    plot : str, optional
        Picture to draw (.png, .svg, .pdf); the log is then read whole.
    plot_mean_s : float, default 0.1
        Window of the moving mean drawn over the process current [s]; 0 draws none.
    plot_window : (float, float), optional
        Time window of the picture [s].
    chunk_s : float, default 60.0
        Chunk length of the model [s].
    read : mapping, optional
        Options of reading and preparing the logs (:func:`greybox.data.reading.read_prepared`).
    force : bool, default False
        Replace outputs that exist (never an input).
    scheduler, workers : None
        Options of a fleet run (:func:`greybox.fleet.predict.predict_fleet`, which takes the options of this
        function): refused here, one log is predicted in this process.
    progress : callable, optional
        ``progress(ChunkProgress)`` after each chunk.
    notify : callable, optional
        ``notify(line)`` with each ``note:`` or ``warning:`` line while the logs are read and prepared
        (default: dropped).
    relevel : bool, default False
        Scale the model's current per chunk (``chunk_s``, the sliding window) and direction of motion to the
        log's air moves (:mod:`greybox.predict.relevel`): a friction that changed since training (warm-up) leaves
        the process current. One log with a model file only.

    Returns
    -------
    Prediction

    Raises
    ------
    GreyboxError
        For options that do not apply to the model or the run, outputs that must not be written, bad
        model files, logs or axis files.
    """
    logs = [logs] if isinstance(logs, (str, os.PathLike)) else list(logs)
    if not logs:
        raise GreyboxError("no log given")
    request = Request(out=Path(out), axis_config=axis_config, machine=machine,
                       calibration=None if calibration is None else list(calibration), coverage=coverage, plot=plot,
                       plot_mean_s=plot_mean_s, plot_window=None if plot_window is None else tuple(plot_window),
                       chunk_s=chunk_s, read=dict(read or {}), force=force, progress=progress,
                       notify=notify or (lambda line: None), relevel=relevel)
    source = open_model(model)
    if is_fleet(logs):
        raise GreyboxError(f"{logs[0]}: several logs, a directory or a pattern make a fleet run; "
                           "greybox.fleet.predict.predict_fleet runs it")
    if scheduler or workers:
        raise GreyboxError(named("scheduler"), " and ", named("workers"),
                           " apply to fleet runs (several logs, a directory or a pattern)")
    return source.predict_log(str(logs[0]), request)
