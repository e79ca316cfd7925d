"""Training a machine model: one model per axis of logs that hold several axes, each with its training record."""

from __future__ import annotations

import time
from typing import Callable, Mapping, Sequence

from ..data.effort import check_effort_measured, check_one_axis, check_one_effort
from ..models.machine import MachineModel, check_machine_output, save_machine
from .logs import axis_file_inertia, check_intervals, fit_runs, read_training_logs, unfitted
from .record import record_training

__all__ = ["train_machine_logs"]


def train_machine_logs(kind, logs, axes: Sequence, *, params: Mapping | None = None, name: str = "", stage2=(),
                       read: Mapping | None = None, intervals: str = "sandwich", n_bootstrap: int | None = None,
                       out=None, overwrite: bool = False, progress=None,
                       report: Callable[[str], None] | None = None, notify: Callable[[str], None] | None = None,
                       on_fit: Callable[[str, object, float], None] | None = None) -> MachineModel:
    """Train one model per axis of ``logs`` (every axis read before any is fitted) into a machine model.

    Parameters
    ----------
    kind : str or estimator
        Model kind or an unfitted model (copied for each axis), as :func:`~greybox.train.train_logs` takes it.
    logs : sequence of str or path-like
        Training logs holding every axis.
    axes : sequence of MachineAxis
        The axes to fit (:class:`~greybox.data.machine_config.MachineAxis`): each read with its channels,
        its model checked against its configuration's inertia where it gives one.
    params : mapping, optional
        Hyperparameters of a ``kind`` given by name.
    name : str, default ""
        Machine name.
    stage2 : sequence of str or path-like, default ()
        Logs of the second stage of a two-stage model.
    read : mapping, optional
        Options of reading and preparing the logs (:func:`greybox.data.reading.read_prepared`).
    intervals : {"sandwich", "bootstrap", "none"}, default "sandwich"
        95 % intervals of the identified parameters.
    n_bootstrap : int, optional
        Replicates of a bootstrap (default 100).
    out : str or path-like, optional
        Directory of the machine model to write (checked before anything is read), read back and compared.
    overwrite : bool, default False
        Replace the files of an existing machine model in ``out``.
    progress : bool or callable, optional
        Progress display of the identification.
    report : callable, optional
        ``report(line)`` with the line of each axis's intervals.
    notify : callable, optional
        ``notify(line)`` with each ``note:`` line of the reading.
    on_fit : callable, optional
        ``on_fit(axis, model, seconds)`` after each axis's model is fitted and recorded.

    Returns
    -------
    MachineModel
        The fitted models by axis, each with its ``training_record_``.
    """
    check_intervals(intervals, n_bootstrap)
    if out is not None:
        check_machine_output(out, [axis.name for axis in axes], overwrite=overwrite)
    data = {}
    for axis in axes:  # every axis read and checked before any training
        reading = {**(read or {}), "axis": axis.name}
        columns = dict(axis.channels) or None
        runs, names, files = read_training_logs(logs, reading, columns=columns, notify=notify)
        second, second_names, second_files = read_training_logs(stage2 or (), reading, columns=columns,
                                                                notify=notify)
        everything = runs + second
        check_one_effort(everything)
        check_one_axis(everything)
        check_effort_measured(everything)
        data[axis.name] = (runs, second, names + second_names, files + second_files, reading)
    models, verify = {}, {}
    for axis in axes:
        runs, second, names, files, reading = data[axis.name]
        model = unfitted(kind, params)
        started = time.perf_counter()
        everything, predictions = fit_runs(model, runs, stage2=second, intervals=intervals, n_bootstrap=n_bootstrap,
                                           progress=progress, report=report)
        expected, source = axis_file_inertia(axis.config, everything, required=False)
        if expected is not None:
            model.check_axis_inertia(expected, f"axis {axis.name} of the machine file")
        record_training(model, everything, predictions, names=names, files=files, read=reading)
        if on_fit is not None:
            on_fit(axis.name, model, time.perf_counter() - started)
        models[axis.name], verify[axis.name] = model, (everything, predictions)
    machine = MachineModel(models=models, name=name)
    if out is not None:
        save_machine(machine, out, overwrite=overwrite, verify=verify)
    return machine
