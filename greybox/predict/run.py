"""The one entry point of prediction: :func:`predict_logs` takes a model, logs and an output, and decides the rest.

What it does follows from what it is given:

* the model: a model file (``greybox train``), a machine model directory (``greybox train --axes``:
  every axis of the log, and the resultant force, :mod:`greybox.predict.machine`), or a directory of
  models of ``greybox train --per-machine`` (each log predicted with its machine's model). The kind of
  model source carries what it can do (:func:`open_model`): a machine model predicts one log of
  several axes and refuses a fleet;
* the logs: one log file is predicted in this process, several logs, a directory or a glob pattern
  make a fleet run (one task per log on Dask, a partitioned Parquet dataset, :mod:`greybox.predict.fleet`);
* how a log is read: a Parquet or MCAP log of a linear axis, without a picture, resampling or a sample
  time, is read, predicted and written block by block (:mod:`greybox.predict.stream`), so that its
  length does not bound the memory; any other log, or one that turns out not to stream
  (:class:`~greybox.data.blocks.CannotStream`), is read whole (:mod:`greybox.predict.process`);
* what is written: the process table (:mod:`greybox.predict.output`), with a picture when asked
  (:mod:`greybox.predict.plot`), each output refused before any work if it must not or cannot be written.

It returns a :class:`Prediction`: the lines to show, the figures of each axis and what was written.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable, Mapping, Sequence

import numpy as np

from ..errors import GreyboxError, Setting
from ..fleet import check_out_dir, fleet_summary, read_prepared
from ..models.chunked import DEFAULT_CHUNK_S, chunk_slices, samples_per_chunk
from ..provenance import model_quantity, preparation_warning
from .effort import align_effort
from .interval import DEFAULT_COVERAGE, ProcessInterval, calibrate_interval
from .output import check_output_path, output_paths, write_process
from .process import ProcessTally

__all__ = ["PLOT_SUFFIXES", "AxisFigures", "ChunkProgress", "Prediction", "is_fleet", "open_model", "predict_logs"]

#: Extensions of the picture.
PLOT_SUFFIXES = (".png", ".svg", ".pdf")

_FLEET_CHARACTERS = "*?["


@dataclass(frozen=True)
class ChunkProgress:
    """Where a prediction stands: given to the ``progress`` callback of :func:`predict_logs` after each chunk.

    Attributes
    ----------
    done : int
        Chunks done.
    chunks : int
        Chunks in all (of the axis being predicted).
    time_s : float
        Log time reached [s].
    end_s : float
        Log time of the last sample [s].
    elapsed_s : float
        Wall time since the prediction of the axis started [s].
    """

    done: int
    chunks: int
    time_s: float
    end_s: float
    elapsed_s: float


@dataclass(frozen=True)
class AxisFigures:
    """The figures of one axis's prediction that are reported: rms, largest values, extrapolation, interval.

    Attributes
    ----------
    tally : ProcessTally
        Running figures of the process table (:class:`~greybox.predict.process.ProcessTally`).
    effort_unit : str
        "A", "N" or "Nm".
    motion : str
        "linear" or "rotary".
    load_constants : (float, float) or None
        Factors from process current to load, driving and back-driven [N/A or Nm/A]; None without
        axis metadata.
    extrapolation : dict
        Share of samples outside the training region (:func:`~greybox.predict.process.extrapolation_summary`).
    interval : ProcessInterval or None
        The calibrated interval.
    axis_file : str or None
        Name of the file the load constants came from.
    log_name : str
        Name of the log.
    calibration_logs : int
        Calibration logs the interval was calibrated on.
    quantity : str
        What the effort is (:func:`~greybox.data.effort.effort_quantity`): "current", "motor torque",
        "force" or "torque".
    """

    tally: ProcessTally
    effort_unit: str
    motion: str
    load_constants: tuple[float, float] | None
    extrapolation: dict
    interval: ProcessInterval | None = None
    axis_file: str | None = None
    log_name: str = ""
    calibration_logs: int = 0
    quantity: str = "current"

    @property
    def units(self):
        """Units of the axis (:class:`~greybox.data.quantities.Motion`)."""
        from ..data.quantities import MOTIONS

        return MOTIONS[self.motion]


@dataclass(frozen=True)
class Prediction:
    """What :func:`predict_logs` did, in the order to report it.

    Attributes
    ----------
    summary : list of str
        Lines before the figures (which model predicted which log, samples, chunks).
    axes : list of (str or None, AxisFigures)
        Each axis's figures, with a heading line where the log has several axes.
    closing : list of str
        Lines after the figures (interpolated axes, resultant force; a fleet's summary and failures).
    written : list of str
        Files written, in order (table, its metadata sidecar, picture); a fleet's dataset is in ``closing``.
    elapsed_s : float or None
        Wall time of the prediction itself [s] (reading, predicting, writing of a streamed log); None for
        a fleet run.
    status : int
        Exit status: 0, or 2 when a log of a fleet failed.
    result : ProcessResult or MachineProcessResult or None
        The result of a log read whole; None when it was streamed or for a fleet run.
    manifest : dict or None
        The manifest of a fleet run.
    """

    summary: list = field(default_factory=list)
    axes: list = field(default_factory=list)
    closing: list = field(default_factory=list)
    written: list = field(default_factory=list)
    elapsed_s: float | None = None
    status: int = 0
    result: object = None
    manifest: dict | None = None


@dataclass(frozen=True)
class _Request:
    """The options of one :func:`predict_logs` call, as given."""

    out: Path
    axis_config: str | None
    machine: str | None
    calibration: list | None
    coverage: float | None
    plot: str | None
    plot_mean_s: float
    plot_window: tuple | None
    chunk_s: float
    read: dict
    force: bool
    scheduler: str | None
    workers: int | None
    progress: Callable | None
    fleet_progress: Callable | None
    notify: Callable[[str], None]

    def warn(self, line: str | None) -> None:
        if line is not None:
            self.notify(line)

    def check_outputs(self, log: str, inputs: list) -> None:
        """Refuse, before any work, outputs that must not or cannot be written."""
        out = self.out
        for target in output_paths(out):  # the table, and for CSV its metadata sidecar
            check_output_path(target, overwrite=self.force, protect=inputs)
        if self.plot:
            plot = Path(self.plot)
            if plot.suffix.lower() not in PLOT_SUFFIXES:
                raise GreyboxError(f"{plot}: unknown picture extension '{plot.suffix}'; use {', '.join(PLOT_SUFFIXES)}")
            if plot.resolve() == out.resolve():
                raise GreyboxError(f"{plot}: ", _named("plot"), " and ", _named("out"), " name the same file")
            check_output_path(plot, overwrite=self.force, protect=inputs)
        elif self.plot_window is not None:
            raise GreyboxError(_named("plot_window"), " needs ", Setting("plot"))
        if self.calibration is None and self.coverage is not None:
            raise GreyboxError(_named("coverage"), " needs ", Setting("calibration"),
                               " (air-cut logs the model was not trained on)")
        own = [path for path in self.calibration or () if Path(path).resolve() == Path(log).resolve()]
        if own:
            raise GreyboxError(_named("calibration"), f": {own[0]} is the cutting log itself; calibrate on air cuts "
                               "the model was not trained on")

    def interval(self, model, read: Callable[[str], list]) -> ProcessInterval | None:
        """The calibrated interval of ``model`` from the calibration logs (``read(path)`` gives their runs)."""
        if not self.calibration:
            return None
        return calibrate_interval(model, [run for path in self.calibration for run in read(path)],
                                  coverage=DEFAULT_COVERAGE if self.coverage is None else self.coverage,
                                  chunk_s=self.chunk_s)

    def chunk_progress(self, end_s: Callable[[], float]) -> Callable[[int, int, float], None] | None:
        """The chunk callback of the predictors, reporting :class:`ChunkProgress` (``end_s()`` once known)."""
        if self.progress is None:
            return None
        started = time.perf_counter()
        end: list = []

        def step(done: int, chunks: int, time_s: float) -> None:
            if not end:  # a streamed log's end is known once its time stamps have been read
                end.append(end_s())
            self.progress(ChunkProgress(done, chunks, time_s, end[0], time.perf_counter() - started))

        return step

    def write(self, result, inputs: list, window, draw) -> list[str]:
        """Write the table (atomically) and the picture ``draw`` makes of ``result`` when asked; what was written."""
        write_process(result, self.out, overwrite=self.force, protect=inputs)
        written = [str(target) for target in output_paths(self.out)]
        if self.plot:
            draw(result, self.plot, mean_s=self.plot_mean_s, window=window)
            written.append(str(self.plot))
        return written

    def fleet(self, model: str, logs: Sequence[str]) -> Prediction:
        """Every log a task on Dask, each with ``model`` (a file, or a directory of per-machine models)."""
        from ..fleet import MANIFEST, expand_logs
        from ..persistence import load_model
        from .fleet import fleet_jobs, run_fleet

        out = check_out_dir(self.out)
        jobs = fleet_jobs(expand_logs(logs), str(Path(model).resolve()), str(out),
                          axis_config=str(Path(self.axis_config).resolve()) if self.axis_config else None,
                          read=self.read, chunk_s=self.chunk_s)
        for path in sorted({job.model for job in jobs}):
            load_model(path)  # a bad model file is one error before any cluster starts
        manifest = run_fleet(jobs, scheduler=self.scheduler, workers=self.workers, force=self.force,
                             progress=self.fleet_progress)
        lines, status = fleet_summary(manifest, "logs", "predicted", lambda entry: entry["error"])
        lines.append(f"wrote {out / MANIFEST} and the dataset {out}/machine=*/axis=*/log=*/part-0.parquet")
        return Prediction(closing=lines, status=status, manifest=manifest)


def _named(name: str) -> Setting:
    """The setting ``name`` of :func:`predict_logs`, named in a message (the command line spells its option)."""
    return Setting(name, assign=False)


def _window(request: _Request, runs, log: str):
    """The picture's time window, checked against the log's time."""
    from ..evaluate.plots import check_window

    log_time = np.concatenate([run.time for run in runs])
    return check_window(request.plot_window, log_time, "plot_window", Path(log).name)


class ModelFile:
    """A model file (``greybox train``): one log predicted in this process, or a fleet of logs.

    Parameters
    ----------
    path : str or path-like
        The model file.
    """

    def __init__(self, path):
        self.path = str(path)

    def predict_fleet(self, logs: Sequence[str], request: _Request) -> Prediction:
        """Predict every log on Dask with this model (see :func:`predict_logs`)."""
        return request.fleet(self.path, logs)

    def predict_log(self, log: str, request: _Request) -> Prediction:
        """Predict one log, streamed where it can be (see :func:`predict_logs`)."""
        from ..data.axis_config import read_axis_config
        from ..data.stream import open_stream
        from ..persistence import load_model

        if request.machine:
            raise GreyboxError(_named("machine"), " applies to a machine model (a directory written by 'greybox train "
                               "--axes'); give one axis's mechanics with ", _named("axis_config"))
        inputs = [self.path, log, *([request.axis_config] if request.axis_config else []), *(request.calibration or [])]
        request.check_outputs(log, inputs)
        config = read_axis_config(request.axis_config) if request.axis_config else None
        model, records = load_model(self.path, records=True)
        read = request.read
        columns = {**(config.channels if config else {}), **(read.get("columns") or {})} or None  # the file's names
        names = (Path(log).name, Path(self.path).name)
        calibrated: list = []

        def interval() -> ProcessInterval | None:  # computed once, whether the log streams or not
            if not calibrated:
                calibrated.append(request.interval(model, lambda path: align_effort(
                    records, model, read_prepared(path, read, columns=columns, notify=request.notify), config,
                    Path(path).name, names[1], request.notify)))
            return calibrated[0]

        figures = {"axis_file": Path(request.axis_config).name if request.axis_config else None,
                   "log_name": Path(log).name, "calibration_logs": len(request.calibration or ())}
        attrs = {"model_file": self.path, "log_file": str(log)}
        streamed = None
        if not request.plot:
            streamed = open_stream(log, columns=columns,
                                   topic=read.get("topic"), axis=read.get("axis"), sample_time=read.get("sample_time"),
                                   resample=read.get("resample"))
        if streamed is not None and _first_quantity(streamed) != model_quantity(records, model):
            streamed = None  # read whole, to convert its effort (align_effort)
        if streamed is not None:
            request.warn(preparation_warning(records, read, None, *names))
            done = self._stream(model, streamed, config, request, inputs, attrs, interval, figures)
            if done is not None:
                return done
        runs = align_effort(records, model, read_prepared(log, read, columns=columns, notify=request.notify), config,
                            *names, request.notify)
        if streamed is None:
            request.warn(preparation_warning(records, read, runs, *names))
        return self._whole(model, runs, log, config, request, inputs, attrs, interval, figures)

    def _whole(self, model, runs, log: str, config, request: _Request, inputs: list, attrs: dict,
               calibrated: Callable[[], ProcessInterval | None], figures: dict) -> Prediction:
        """The prediction of a log read whole."""
        from .plot import plot_process
        from .process import predict_process

        window = _window(request, runs, log)
        interval = calibrated()
        started = time.perf_counter()
        result = predict_process(model, runs, axis_config=config, interval=interval, chunk_s=request.chunk_s,
                                 progress=request.chunk_progress(lambda: float(runs[-1].time[-1])))
        elapsed = time.perf_counter() - started
        result.attrs.update(attrs)
        n_chunks = sum(len(chunk_slices(len(run), samples_per_chunk(run.sample_time, request.chunk_s))) for run in runs)
        duration = sum(run.duration for run in runs)
        summary = (f"predicted {Path(log).name} with the {result.attrs['model_kind']} model {Path(self.path).name}: "
                   f"{len(result.time)} samples, {duration:.1f} s, {n_chunks} chunk(s) of {request.chunk_s:g} s"
                   + (f" in {len(runs)} runs" if len(runs) > 1 else "")
                   + (f", dataset {result.dataset}" if result.dataset else ""))
        written = request.write(result, inputs, window, plot_process)
        return Prediction(summary=[summary], axes=[(None, _figures_of(result, interval, figures))], written=written,
                          elapsed_s=elapsed, result=result)

    def _stream(self, model, log, config, request: _Request, inputs: list, attrs: dict,
                interval: Callable[[], ProcessInterval | None], figures: dict) -> Prediction | None:
        """The prediction of a log read, predicted and written block by block; None if it cannot be streamed."""
        from ..data.blocks import CannotStream
        from .stream import stream_process

        calibrated = interval()
        started = time.perf_counter()
        try:
            done = stream_process(model, log, request.out, axis_config=config, interval=calibrated,
                                  chunk_s=request.chunk_s, tolerance=request.read.get("time_tolerance", 0.25),
                                  cutoff_hz=request.read.get("cutoff_hz"), attrs=attrs, overwrite=request.force,
                                  protect=inputs, progress=request.chunk_progress(lambda: log.time_span()[1]))
        except CannotStream:
            return None
        elapsed = time.perf_counter() - started
        table_attrs, dataset, unit = done.metadata["attrs"], done.metadata["dataset"], done.metadata["effort_unit"]
        quantity = table_attrs["effort"]["quantity"]
        if config is not None and quantity == "motor torque":  # the effort is k_t I already
            config = config.without_torque_constant()
        summary = (f"predicted {Path(attrs['log_file']).name} with the {table_attrs['model_kind']} model "
                   f"{Path(self.path).name}: {done.tally.n_samples} samples, {done.duration:.1f} s, {done.n_chunks} "
                   f"chunk(s) of {request.chunk_s:g} s" + (f", dataset {dataset}" if dataset else "")
                   + ", read and written block by block")
        load_constants = config.load_constants if config is not None and unit == "A" else None
        axis = AxisFigures(done.tally, unit, done.motion, load_constants, table_attrs["extrapolation"],
                           interval=calibrated, quantity=quantity, **figures)
        return Prediction(summary=[summary], axes=[(None, axis)],
                          written=[str(target) for target in output_paths(request.out)], elapsed_s=elapsed)


def _figures_of(result, interval: ProcessInterval | None, figures: dict) -> AxisFigures:
    """The :class:`AxisFigures` of a whole process result."""
    tally = ProcessTally()
    tally.add(result)
    return AxisFigures(tally, result.effort_unit, result.motion, result.load_constants,
                       result.attrs["extrapolation"], interval=interval, quantity=result.quantity, **figures)


def _first_quantity(log) -> str:
    """What the effort of a log opened block by block is (:func:`~greybox.data.effort.effort_quantity`)."""
    from ..data.effort import effort_quantity

    return effort_quantity(next(iter(log.blocks(1))))


class ModelsDirectory(ModelFile):
    """The models of ``greybox train --per-machine``: each log predicted with its machine's model.

    Parameters
    ----------
    path : str or path-like
        The directory, with the manifest of ``greybox train --per-machine``.
    """

    def predict_log(self, log: str, request: _Request) -> Prediction:
        """Predict one log with the model of its machine (the name of its folder)."""
        from .fleet import model_of_log

        chosen = model_of_log(self.path, log, request.read.get("axis"))
        done = ModelFile(chosen).predict_log(log, request)
        line = f"model of machine {Path(log).resolve().parent.name}: {chosen}"
        return replace(done, summary=[line, *done.summary])


class MachineDirectory:
    """A machine model (``greybox train --axes``): every axis of one log, and the resultant force.

    Parameters
    ----------
    path : str or path-like
        The machine model directory.
    """

    def __init__(self, path):
        self.path = str(path)

    def predict_fleet(self, logs: Sequence[str], request: _Request) -> Prediction:
        """Refused: a fleet run takes one model file."""
        raise GreyboxError(f"{self.path}: a fleet run takes one model file; run one fleet per axis of the machine "
                           "model with its file and ", _named("axis"))

    def predict_log(self, log: str, request: _Request) -> Prediction:
        """Predict every axis of one log (see :func:`predict_logs`)."""
        from ..data.machine_config import read_machine_config
        from ..machine_model import load_machine
        from ..persistence import load_model
        from .machine import RESULTANT_COLUMN, predict_machine
        from .plot import plot_machine_process

        read = request.read
        for setting, value in (("axis_config", request.axis_config), ("columns", read.get("columns")),
                               ("axis", read.get("axis"))):
            if value:
                raise GreyboxError(_named(setting), f" does not apply to a machine model ({self.path}): it predicts "
                                   "every axis of the log; give the axes' channels and mechanics with ",
                                   Setting("machine"))
        inputs = [self.path, log] + ([request.machine] if request.machine else []) + list(request.calibration or [])
        request.check_outputs(log, inputs)
        machine = load_machine(self.path)
        config = read_machine_config(request.machine) if request.machine else None
        missing = [name for name in machine.axes if config is not None and name not in config.axes]
        if missing:
            raise GreyboxError(f"{request.machine}: no [axes.{missing[0]}] table; the machine model {self.path} has "
                               f"axes {', '.join(machine.axes)}, the machine file {', '.join(config.axes)}")
        described = {name: config.axis(name) for name in machine.axes} if config else {}

        def read_axis(path, name):
            channels = dict(described[name].channels) if name in described else {}
            return read_prepared(path, {**read, "axis": name}, columns=channels or None, notify=request.notify)

        runs = {name: read_axis(log, name) for name in machine.axes}
        for name in machine.axes:  # each axis's model file, its training record against the log's preparation
            records = load_model(Path(self.path) / f"{name}.gbm", records=True)[1]
            runs[name] = align_effort(records, machine.models[name], runs[name],
                                      described[name].config if name in described else None,
                                      f"{Path(log).name} (axis {name})", f"{name}.gbm", request.notify)
            request.warn(preparation_warning(records, read, runs[name], f"{Path(log).name} (axis {name})",
                                             f"{name}.gbm"))
        window = _window(request, runs[machine.axes[0]], log)
        intervals = {name: request.interval(machine.models[name], lambda path, name=name: read_axis(path, name))
                     for name in machine.axes}
        started = time.perf_counter()
        result = predict_machine(machine.models, runs,
                                 axis_configs={name: axis.config for name, axis in described.items()},
                                 intervals=intervals, name=machine.name, chunk_s=request.chunk_s,
                                 progress=lambda name: request.chunk_progress(lambda: float(runs[name][-1].time[-1])))
        elapsed = time.perf_counter() - started
        result.attrs.update({"model_dir": self.path, "log_file": str(log)})
        kinds = ", ".join(f"{name}: {axis_result.attrs['model_kind']}" for name, axis_result in result.results.items())
        summary = (f"predicted {Path(log).name} with the machine model {Path(self.path).name} ({kinds}): "
                   f"{len(result.time)} samples" + (f", dataset {result.dataset}" if result.dataset else ""))
        axes = [(f"axis {name}:", _figures_of(axis_result, intervals[name], {
                    "axis_file": Path(request.machine).name if name in described and described[name].config else None,
                    "log_name": Path(log).name, "calibration_logs": len(request.calibration or ())}))
                for name, axis_result in result.results.items()]
        closing = []
        if result.attrs["interpolated_axes"]:
            closing.append(f"  axes {', '.join(result.attrs['interpolated_axes'])} interpolated onto the time stamps "
                           f"of axis {result.attrs['time_of']}")
        resultant = result.resultant()
        if resultant is not None:
            closing.append(f"resultant process force of axes {', '.join(result.forces())}: rms "
                           f"{float(np.sqrt(np.mean(np.square(resultant)))):.4g} N, largest {np.max(resultant):.4g} N "
                           f"(column {RESULTANT_COLUMN})")
        written = request.write(result, inputs, window, plot_machine_process)
        return Prediction(summary=[summary], axes=axes, closing=closing, written=written, elapsed_s=elapsed,
                          result=result)


def open_model(path: str | os.PathLike) -> ModelFile | ModelsDirectory | MachineDirectory:
    """The model source ``path`` names: a machine model directory, a directory of per-machine models, or a file.

    Parameters
    ----------
    path : str or path-like
        A model file (``greybox train``), a machine model directory (``greybox train --axes``), or the
        models directory of ``greybox train --per-machine``.

    Returns
    -------
    ModelFile or ModelsDirectory or MachineDirectory
        Each with ``predict_log(log, request)`` and ``predict_fleet(logs, request)``.
    """
    from ..machine_model import is_machine_model

    if is_machine_model(path):
        return MachineDirectory(path)
    if os.path.isdir(path):
        return ModelsDirectory(path)
    return ModelFile(path)


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
                 fleet_progress: Callable[[int, int, dict], None] | None = None,
                 notify: Callable[[str], None] | None = None) -> Prediction:
    """Predict the process current (and force) of cutting logs with a model trained on air cuts, and write it.

    Parameters
    ----------
    model : str or path-like
        A model file, a machine model directory, or the models directory of ``greybox train
        --per-machine`` (:func:`open_model`).
    logs : str, path-like or sequence of them
        One cutting log, or (a fleet run, :func:`is_fleet`) several logs, directories searched
        recursively, glob patterns.
    out : str or path-like
        The process table (.csv, .parquet, .mcap) of one log; the dataset directory of a fleet run.
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
        Options of reading and preparing the logs (:func:`greybox.fleet.read_prepared`).
    force : bool, default False
        Replace outputs that exist (never an input).
    scheduler : str, optional
        Address of a dask.distributed scheduler for a fleet run (default a local cluster).
    workers : int, optional
        Processes of the local cluster of a fleet run.
    progress : callable, optional
        ``progress(ChunkProgress)`` after each chunk of a log predicted here.
    fleet_progress : callable, optional
        ``fleet_progress(done, total, entry)`` after each log of a fleet run.
    notify : callable, optional
        ``notify(line)`` with each ``note:`` or ``warning:`` line while the logs are read and prepared
        (default: dropped).

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
    request = _Request(out=Path(out), axis_config=axis_config, machine=machine,
                       calibration=None if calibration is None else list(calibration), coverage=coverage, plot=plot,
                       plot_mean_s=plot_mean_s, plot_window=None if plot_window is None else tuple(plot_window),
                       chunk_s=chunk_s, read=dict(read or {}), force=force, scheduler=scheduler, workers=workers,
                       progress=progress, fleet_progress=fleet_progress, notify=notify or (lambda line: None))
    source = open_model(model)
    if is_fleet(logs):
        for setting, value in (("plot", plot), ("plot_window", plot_window), ("calibration", calibration),
                               ("coverage", coverage), ("machine", machine)):
            if value is not None:
                raise GreyboxError(_named(setting), " applies to one log; a fleet run (several logs) writes the "
                                   "process tables")
        return source.predict_fleet([str(item) for item in logs], request)
    if scheduler or workers:
        raise GreyboxError(_named("scheduler"), " and ", _named("workers"),
                           " apply to fleet runs (several logs, a directory or a pattern)")
    return source.predict_log(str(logs[0]), request)
