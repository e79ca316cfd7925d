"""Training a model on logs: read and prepare them, fit, attach intervals, record how it was made, save.

:func:`train_logs` is the one entry point of training one model, beside :func:`greybox.predict.predict_logs`;
``greybox train``, the fleet (:mod:`greybox.fleet.train`) and Python callers all go through it, so every
model it returns carries the same training record (:func:`~greybox.train.record.record_training`), which
:func:`greybox.models.files.save_model` writes into its file.
"""

from __future__ import annotations

import copy
import os
import time
from pathlib import Path
from typing import Callable, Mapping, Sequence

import numpy as np

from ..atomic import check_output_path
from ..data.effort import EFFORT_UNITS, check_effort_measured, check_one_axis, check_one_effort, effort_quantity
from ..data.log import AxisLog
from ..data.reading import read_prepared
from ..errors import GreyboxError, ModelFileError
from ..identify.intervals import METHODS as INTERVAL_METHODS
from ..identify.intervals import attach_intervals
from ..models.files import save_verified
from ..models.registry import model_class, model_kind
from .advice import offset_note, takes_hyperparameter
from .defaults import with_training_defaults
from .record import record_training, run_names

__all__ = ["DEFAULT_BOOTSTRAP", "axis_file_inertia", "check_intervals", "fit_runs", "intervals_line",
           "read_training_logs", "train_logs", "unfitted"]

#: Replicates of a bootstrap of the parameter intervals unless told otherwise.
DEFAULT_BOOTSTRAP = 100


def read_training_logs(logs, read: Mapping | None = None, *, columns: Mapping[str, str] | None = None,
                       notify: Callable[[str], None] | None = None) -> tuple[list[AxisLog], list[str], list[str]]:
    """The prepared runs of training ``logs``, a name for each and the log files they came from.

    Parameters
    ----------
    logs : sequence of (str, path-like or AxisLog)
        Log files, read and prepared as ``read`` says (:func:`greybox.data.reading.read_prepared`), or
        runs prepared already (their ``source`` is their file, where it is one).
    read : mapping, optional
        Options of reading and preparing the logs.
    columns : mapping, optional
        Column mapping (an axis's channels of a machine file).
    notify : callable, optional
        ``notify(line)`` with each ``note:`` line of the reading (a log split at gaps).

    Returns
    -------
    (list of AxisLog, list of str, list of str)
        The runs in order; their names (:func:`~greybox.train.record.run_names`); the files.
    """
    runs, names, files = [], [], []
    pending: list[AxisLog] = []

    def flush() -> None:
        if pending:
            source = pending[0].source
            names.extend(run_names(source or "run", len(pending)))
            if source and os.path.isfile(source):
                files.append(source)
            pending.clear()

    for item in logs:
        if isinstance(item, AxisLog):
            if pending and item.source != pending[0].source:
                flush()
            pending.append(item)
            runs.append(item)
            continue
        flush()
        pieces = read_prepared(os.fspath(item), read or {}, columns=columns, notify=notify)
        runs += pieces
        names += run_names(item, len(pieces))
        files.append(os.fspath(item))
    flush()
    return runs, names, files


def axis_file_inertia(axis_config, runs, *, required: bool = True) -> tuple[float | None, str]:
    """The inertia an axis file gives, in the effort unit of ``runs`` [effort s^2/length], and its source.

    Parameters
    ----------
    axis_config : str, path-like, AxisConfig or None
        Axis file (TOML) or a read configuration; None gives ``(None, "")``.
    runs : list of AxisLog
        Prepared runs: the first gives the effort unit.
    required : bool, default True
        Refuse an axis file without an inertia (one given to check the model against).
    """
    from ..data.axis_config import INERTIA, AxisConfig, read_axis_config

    if axis_config is None or not runs:
        return None, ""
    if isinstance(axis_config, AxisConfig):
        config, source = axis_config, "the axis configuration"
    else:
        config, source = read_axis_config(axis_config), f"the axis file {Path(axis_config).name}"
        if config.inertia_kg_m2 is None and required:
            raise GreyboxError(f"{axis_config}: gives no {INERTIA}, the axis's inertia at the motor shaft that "
                               "--axis-config of greybox train checks the model against")
    return config.model_inertia(runs[0].effort_unit), source


def check_intervals(intervals: str, n_bootstrap: int | None) -> None:
    """Refuse an unknown method of parameter intervals, or a bootstrap of fewer than 2 replicates.

    Parameters
    ----------
    intervals : str
        Method (:data:`greybox.identify.intervals.METHODS`).
    n_bootstrap : int or None
        Replicates of a bootstrap.
    """
    if intervals not in INTERVAL_METHODS:
        raise GreyboxError(f"intervals {intervals!r}: choose one of {', '.join(INTERVAL_METHODS)}")
    if n_bootstrap is not None and n_bootstrap < 2:
        raise GreyboxError(f"--bootstrap {n_bootstrap}: a bootstrap needs at least 2 replicates")


def fit_runs(model, runs, *, stage2: Sequence[AxisLog] = (), intervals: str = "sandwich",
             n_bootstrap: int | None = None, progress=None,
             report: Callable[[str], None] | None = None) -> tuple[list[AxisLog], list[np.ndarray]]:
    """Fit ``model`` to prepared ``runs`` (``stage2`` for the second stage) and attach its parameter intervals.

    Parameters
    ----------
    model : CurrentModel
        Unfitted model, fitted in place.
    runs : list of AxisLog
        Prepared training runs (of the first stage of a two-stage model given ``stage2``).
    stage2 : sequence of AxisLog, default ()
        Runs of the second stage of a two-stage model (gmssvr); the first is then fitted on ``runs`` alone.
    intervals : {"sandwich", "bootstrap", "none"}, default "sandwich"
        95 % intervals of the identified parameters (:func:`greybox.identify.intervals.attach_intervals`).
    n_bootstrap : int, optional
        Replicates of a bootstrap (default :data:`DEFAULT_BOOTSTRAP`).
    progress : bool or callable, optional
        Progress display of the identification, as the model's ``fit`` takes it.
    report : callable, optional
        ``report(line)`` with the line saying how the intervals were computed and in how long.

    Returns
    -------
    (list of AxisLog, list of ndarray)
        All the runs it was fitted on and its effort for each [A, or N, Nm].
    """
    check_intervals(intervals, n_bootstrap)
    stage2 = list(stage2)
    everything = list(runs) + stage2
    check_one_effort(everything)  # before any fit: a model of a current and a torque at once is neither
    check_one_axis(everything)  # nor is a model of two axes
    check_effort_measured(everything)
    if stage2 and model.first_stage() is None:
        raise GreyboxError(f"option --stage2 does not apply to the {model_kind(model)} model: it has one stage")
    if stage2:
        model.fit_staged(list(runs), stage2, progress=progress)
    else:
        model.fit(list(runs), progress=progress)
    intervals_line(model, list(runs), intervals, n_bootstrap, report)
    return everything, [model.predict(run) for run in everything]


def intervals_line(model, runs, intervals: str, n_bootstrap: int | None,
                   report: Callable[[str], None] | None) -> None:
    """Attach the parameter intervals ``intervals`` asks for and report how they were computed and in how long.

    Parameters
    ----------
    model : CurrentModel
        The fitted model.
    runs : list of AxisLog
        The runs it (or its first stage) was fitted on.
    intervals : {"sandwich", "bootstrap", "none"}
        Method (:func:`greybox.identify.intervals.attach_intervals`).
    n_bootstrap : int or None
        Replicates of a bootstrap (default :data:`DEFAULT_BOOTSTRAP`).
    report : callable or None
        ``report(line)`` with the line of the intervals.
    """
    if intervals == "none":
        return
    started = time.perf_counter()
    attach_intervals(model, runs, method=intervals, n_bootstrap=n_bootstrap or DEFAULT_BOOTSTRAP)
    record = model.parameter_intervals_
    if report is not None:
        report(f"95 % intervals by {intervals} over {record['n_clusters']} {record['clusters']} "
               f"in {time.perf_counter() - started:.1f} s")


def unfitted(kind, params: Mapping | None = None):
    """A fresh unfitted model: of the kind named, with ``params``, or a copy of the model given.

    Parameters
    ----------
    kind : str or estimator
        Registered model kind (:data:`greybox.models.registry.MODEL_CLASSES`), with the training defaults
        (:func:`~greybox.train.defaults.with_training_defaults`) for the hyperparameters ``params`` does not
        set, as ``greybox train --model KIND`` builds it; or an unfitted model, copied as it is, never changed.
    params : mapping, optional
        Hyperparameters of a kind given by name.
    """
    if isinstance(kind, str):
        params = dict(params or {})
        return with_training_defaults(model_class(kind)(**params), given=params)
    if params:
        raise GreyboxError("params apply to a model kind given by name; set them on the model given")
    return copy.deepcopy(kind)


def train_logs(kind, logs, *, params: Mapping | None = None, stage2=(), read: Mapping | None = None,
               files: Sequence | None = None, axis_config=None, intervals: str = "sandwich",
               n_bootstrap: int | None = None, out=None, overwrite: bool = False, progress=None,
               report: Callable[[str], None] | None = None, notify: Callable[[str], None] | None = None):
    """Train one model on logs: read and prepare them, fit, attach intervals, record how, and return it.

    Parameters
    ----------
    kind : str or estimator
        Model kind (``"gms"``, ``"gmssvr"``, ...), with the training defaults of ``greybox train --model KIND``
        for what ``params`` does not set (an offset where the model takes one, :func:`unfitted`); or an
        unfitted model with its hyperparameters (copied as it is).
    logs : sequence of (str, path-like or AxisLog)
        Training logs, each a separate run (or several where split at gaps); or prepared runs.
    params : mapping, optional
        Hyperparameters of a ``kind`` given by name.
    stage2 : sequence of (str, path-like or AxisLog), default ()
        Logs of the second stage of a two-stage model (gmssvr).
    read : mapping, optional
        Options of reading and preparing the logs (:func:`greybox.data.reading.read_prepared`).
    files : sequence of path-like, optional
        The training files to record, for ``logs`` given as prepared runs (default: the runs' sources).
    axis_config : str, path-like or AxisConfig, optional
        Axis file with the axis's inertia: an identified inertia more than a factor 2 from it is noted on
        the model (:meth:`~greybox.models.estimator.CurrentModel.check_axis_inertia`).
    intervals : {"sandwich", "bootstrap", "none"}, default "sandwich"
        95 % intervals of the identified parameters.
    n_bootstrap : int, optional
        Replicates of a bootstrap (default 100).
    out : str or path-like, optional
        Model file to write (checked before anything is read), loaded back and compared.
    overwrite : bool, default False
        Replace an existing ``out``.
    progress : bool or callable, optional
        Progress display of the identification.
    report : callable, optional
        ``report(line)`` with the line of the parameter intervals.
    notify : callable, optional
        ``notify(line)`` with each ``note:`` line (a log split at gaps; a training residual whose mean
        points to an offset the model lacks).

    Returns
    -------
    CurrentModel
        The fitted model; its ``training_record_`` holds the training record.
    """
    model = unfitted(kind, params)
    stage2 = list(stage2 or ())
    paths = [item for item in [*logs, *stage2] if not isinstance(item, AxisLog)]
    if out is not None:
        check_output_path(out, overwrite=overwrite, protect=paths, error=ModelFileError,
                          inputs_name="one of the training logs")
    runs, names, found = read_training_logs(logs, read, notify=notify)
    second, second_names, second_found = read_training_logs(stage2, read, notify=notify)
    expected, source = axis_file_inertia(axis_config, runs + second)  # a bad axis file stops before the fit
    everything, predictions = fit_runs(model, runs, stage2=second, intervals=intervals, n_bootstrap=n_bootstrap,
                                       progress=progress, report=report)
    if expected is not None:
        model.check_axis_inertia(expected, source)
    record_training(model, everything, predictions, names=names + second_names,
                    files=found + second_found if files is None else files, read=read)
    _offset_note(model, everything, predictions, notify)
    if out is not None:
        save_verified(model, out, everything, predictions=predictions, overwrite=overwrite)
    return model


def _offset_note(model, runs, predictions, notify) -> None:
    """Pass on the note of an offset the model lacks, for a model that takes one (:func:`offset_note`)."""
    if notify is not None and takes_hyperparameter(model, "fit_offset"):
        line = offset_note([run.effort for run in runs], predictions, EFFORT_UNITS[effort_quantity(runs[0])])
        if line is not None:
            notify(line)
