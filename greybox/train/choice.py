"""Training the model ``--model auto`` chooses: the candidates scored on held-out runs, the best refitted."""

from __future__ import annotations

import os
from typing import Callable, Mapping, Sequence

from ..atomic import check_output_path
from ..data.effort import check_effort_measured, check_one_axis, check_one_effort
from ..errors import ModelFileError
from ..models.files import save_verified
from .candidates import DEFAULT_CANDIDATES, choose_model
from .logs import axis_file_inertia, check_intervals, intervals_line, read_training_logs
from .record import record_training

__all__ = ["train_auto_logs"]


def train_auto_logs(logs, *, candidates: Sequence[str] = DEFAULT_CANDIDATES, read: Mapping | None = None,
                    inertia: float | None = None, axis_config=None, workers: int | None = None,
                    intervals: str = "sandwich", n_bootstrap: int | None = None, out=None, overwrite: bool = False,
                    progress: Callable[[str], None] | None = None, report: Callable[[str], None] | None = None,
                    notify: Callable[[str], None] | None = None):
    """Choose the model by held-out runs (:func:`greybox.train.candidates.choose_model`), record it, return it.

    Parameters
    ----------
    logs : sequence of (str, path-like or AxisLog)
        Training logs; a log's runs are held out together.
    candidates : sequence of str, default :data:`~greybox.train.candidates.DEFAULT_CANDIDATES`
        Candidate specifications (``KIND[:OPTION,...]``).
    read : mapping, optional
        Options of reading and preparing the logs (:func:`greybox.data.reading.read_prepared`).
    inertia : float, optional
        Known inertia [effort s^2/length] of every candidate; it says more than ``axis_config``.
    axis_config : str, path-like or AxisConfig, optional
        Axis file whose inertia every candidate is fitted with (unless ``inertia`` is given).
    workers : int, optional
        Processes fitting the candidates (default one per core).
    intervals : {"sandwich", "bootstrap", "none"}, default "sandwich"
        95 % intervals of the chosen model's parameters.
    n_bootstrap : int, optional
        Replicates of a bootstrap (default 100).
    out : str or path-like, optional
        Model file to write (checked before anything is read), loaded back and compared.
    overwrite : bool, default False
        Replace an existing ``out``.
    progress : callable, optional
        Called with one line of text per finished fit.
    report : callable, optional
        ``report(line)`` with the inertia every candidate is fitted with and the line of the intervals.
    notify : callable, optional
        ``notify(line)`` with each ``note:`` line of the reading.

    Returns
    -------
    CurrentModel
        The chosen model fitted on all runs, with ``selection_`` and ``training_record_``.
    """
    check_intervals(intervals, n_bootstrap)
    if out is not None:
        paths = [item for item in logs if isinstance(item, (str, os.PathLike))]
        check_output_path(out, overwrite=overwrite, protect=paths, error=ModelFileError,
                          inputs_name="one of the training logs")
    runs, names, files, groups = [], [], [], []
    for item in logs:
        pieces, labels, found = read_training_logs([item], read, notify=notify)
        runs += pieces
        names += labels
        files += found
        groups += [str(found[0] if found else labels[0])] * len(pieces)
    check_one_effort(runs)
    check_one_axis(runs)
    check_effort_measured(runs)  # the held-out relative errors the choice compares would be undefined
    if inertia is None:
        inertia, source = axis_file_inertia(axis_config, runs)
        if inertia is not None and report is not None:
            unit = f"{runs[0].effort_unit} s^2/{runs[0].units.length}"
            report(f"inertia J = {inertia:.4g} {unit} from {source}: every candidate is fitted with it")
    model = choose_model(runs, groups, candidates=candidates, inertia=inertia,
                         workers=workers or os.cpu_count() or 1, progress=progress)
    intervals_line(model, runs, intervals, n_bootstrap, report)
    predictions = [model.predict(run) for run in runs]
    record_training(model, runs, predictions, names=names, files=files, read=read)
    if out is not None:
        save_verified(model, out, runs, predictions=predictions, overwrite=overwrite)
    return model
