"""The model sources prediction takes: a model file, a directory of per-machine models, a machine model.

:func:`open_model` tells them apart; each source carries how it predicts one log (``predict_log``).
"""

from __future__ import annotations

import os
import time
from dataclasses import replace
from pathlib import Path
from typing import Callable

import numpy as np

from ..data.reading import read_prepared
from ..errors import GreyboxError, Setting
from ..models.chunked import chunk_slices, samples_per_chunk
from ..provenance import axis_warning, model_quantity, preparation_warning
from .effort import align_effort
from .interval import ProcessInterval
from .output import output_paths
from .process import ProcessTally
from .request import AxisFigures, Prediction, Request, named

__all__ = ["MachineDirectory", "ModelFile", "ModelsDirectory", "open_model"]


def _window(request: Request, runs, log: str):
    """The picture's time window, checked against the log's time."""
    from ..evaluate.plots import check_window

    log_time = np.concatenate([run.time for run in runs])
    return check_window(request.plot_window, log_time, "plot_window", Path(log).name)


class ModelFile:
    """A model file (``greybox train``): one log predicted in this process.

    Parameters
    ----------
    path : str or path-like
        The model file.
    """

    def __init__(self, path):
        self.path = str(path)

    def predict_log(self, log: str, request: Request) -> Prediction:
        """Predict one log, streamed where it can be (see :func:`~greybox.predict.run.predict_logs`).

        Parameters
        ----------
        log : str
            The log file.
        request : Request
            The call's options.
        """
        from ..data.axis_config import read_axis_config
        from ..data.stream import open_stream
        from ..models.files import load_model

        if request.machine:
            raise GreyboxError(named("machine"), " applies to a machine model (a directory written by 'greybox train "
                               "--axes'); give one axis's mechanics with ", named("axis_config"))
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
                    Path(path).name, names[1], request.notify), records, names[1]))
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
            request.warn(axis_warning(records, streamed.axis, *names))
            request.warn(preparation_warning(records, read, None, *names))
            done = self._stream(model, streamed, config, request, inputs, attrs, interval, figures)
            if done is not None:
                return done
        runs = align_effort(records, model, read_prepared(log, read, columns=columns, notify=request.notify), config,
                            *names, request.notify)
        if streamed is None:
            request.warn(axis_warning(records, runs[0].axis if runs else None, *names))
            request.warn(preparation_warning(records, read, runs, *names))
        return self._whole(model, runs, log, config, request, inputs, attrs, interval, figures)

    def _whole(self, model, runs, log: str, config, request: Request, inputs: list, attrs: dict,
               calibrated: Callable[[], ProcessInterval | None], figures: dict) -> Prediction:
        """The prediction of a log read whole."""
        from .plot import plot_process
        from .process import predict_process

        window = _window(request, runs, log)
        interval = calibrated()
        started = time.perf_counter()
        result = predict_process(model, runs, axis_config=config, interval=interval, chunk_s=request.chunk_s,
                                 progress=request.chunk_progress(lambda: float(runs[-1].time[-1])),
                                 relevel=request.relevel)
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

    def _stream(self, model, log, config, request: Request, inputs: list, attrs: dict,
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
                                  protect=inputs, progress=request.chunk_progress(lambda: log.time_span()[1]),
                                  relevel=request.relevel)
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

    def predict_log(self, log: str, request: Request) -> Prediction:
        """Predict one log with the model of its machine (the name of its folder).

        Parameters
        ----------
        log : str
            The log file.
        request : Request
            The call's options.
        """
        from ..models.plant import model_of_log

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

    def predict_log(self, log: str, request: Request) -> Prediction:
        """Predict every axis of one log (see :func:`~greybox.predict.run.predict_logs`).

        Parameters
        ----------
        log : str
            The log file.
        request : Request
            The call's options.
        """
        if request.relevel:
            raise GreyboxError(named("relevel"), " applies to a model file's log; not to a machine model yet")
        from ..data.machine_config import read_machine_config
        from ..models.files import load_model
        from ..models.machine import load_machine
        from .machine import RESULTANT_COLUMN, predict_machine
        from .plot import plot_machine_process

        read = request.read
        for setting, value in (("axis_config", request.axis_config), ("columns", read.get("columns")),
                               ("axis", read.get("axis"))):
            if value:
                raise GreyboxError(named(setting), f" does not apply to a machine model ({self.path}): it predicts "
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
        Each with ``predict_log(log, request)``.
    """
    from ..models.machine import is_machine_model

    if is_machine_model(path):
        return MachineDirectory(path)
    if os.path.isdir(path):
        return ModelsDirectory(path)
    return ModelFile(path)

