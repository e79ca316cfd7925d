"""The training record of a model: the files, their preparation, the training errors and ranges.

:func:`record_training` builds it from the runs a model was fitted on and keeps it on the model as the
learned attribute ``training_record_``; :func:`greybox.models.files.save_model` writes it as the file's
``training`` record, however the model was trained (``greybox train``, the fleet, Python).
"""

from __future__ import annotations

import os

import numpy as np

from ..data.effort import EFFORT_UNITS, check_one_axis, check_one_effort
from ..data.operating import operating_record
from ..json_values import jsonable
from ..metrics import metrics_table
from ..provenance import TRAINING_ATTRIBUTE, file_identity, preparation_of, training_record

__all__ = ["record_training", "run_names"]


def run_names(path, count: int) -> list[str]:
    """The names of the ``count`` runs of one log: its file name, plus ``run k of n`` where it was split.

    Parameters
    ----------
    path : str or path-like
        The log file.
    count : int
        How many runs it gave.
    """
    name = os.path.basename(os.fspath(path))
    return [name] if count == 1 else [f"{name} run {k} of {count}" for k in range(1, count + 1)]


def _figures(table) -> dict:
    """``samples``, ``rmse`` and ``re_percent`` of a :func:`~greybox.metrics.metrics_table`."""
    return {"samples": int(table["n"]), "rmse": float(table["rmse"]), "re_percent": jsonable(float(table["re"]))}


def record_training(model, runs, predictions, *, names, files=(), read=None) -> dict:
    """Build the training record of ``model`` fitted on ``runs`` and keep it as ``model.training_record_``.

    Parameters
    ----------
    model : CurrentModel
        The fitted model.
    runs : list of AxisLog
        The prepared runs it was fitted on (both stages' of a two-stage model).
    predictions : list of ndarray
        The model's effort for each run [A, or N, Nm].
    names : list of str
        A name per run (:func:`run_names`).
    files : sequence of str or path-like, default ()
        The training log files (each recorded once, with its size and SHA-256).
    read : mapping, optional
        Options the runs were read and prepared with (:func:`greybox.provenance.preparation_of`).

    Returns
    -------
    dict
        The record (:func:`greybox.provenance.training_record`), with the ``operating`` region of the runs
        (:func:`greybox.data.operating.operating_record`).
    """
    quantity = check_one_effort(runs)
    axis = check_one_axis(runs)
    tables = [metrics_table(run.effort, prediction) for run, prediction in zip(runs, predictions)]
    total = metrics_table(np.concatenate([run.effort for run in runs]), np.concatenate(predictions))
    ranges = {}
    for channel in ("position", "velocity", "acceleration"):
        values = [getattr(run, channel) for run in runs if getattr(run, channel) is not None]
        if values:
            ranges[channel] = [float(min(v.min() for v in values)), float(max(v.max() for v in values))]
    record = training_record([file_identity(path) for path in dict.fromkeys(map(os.fspath, files))],
                             preparation_of(runs, read or {}),
                             [{"name": str(name), **_figures(table)} for name, table in zip(names, tables)],
                             {**_figures(total), "unit": EFFORT_UNITS[quantity], "quantity": quantity}, ranges,
                             axis=axis, operating=operating_record(runs))
    setattr(model, TRAINING_ATTRIBUTE, record)
    return record
