"""Shared base of the current models: inertia plus friction (plus offset).

A current model predicts the drive effort of a feed axis from its prepared
motion,

    I = J * a + I_friction(v, history) + offset,

in A (or in N when the logs carry force; the models are unit-agnostic and
remember the unit they were fitted on). A fit may use several runs: each run is
simulated from its own initial state, and predictions of a list of runs are
concatenated in order, never carrying a state across the seam between runs.
"""

from __future__ import annotations

from typing import Iterable

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from ..data.log import AxisLog, as_log_list
from ..errors import LogError
from ..identify.progress import make_progress

__all__ = ["CurrentModel", "check_runs"]


def check_runs(logs: AxisLog | Iterable[AxisLog]) -> list[AxisLog]:
    """Return ``logs`` as a list of prepared runs, or raise :class:`LogError`.

    Parameters
    ----------
    logs : AxisLog or iterable of AxisLog
        One run or several runs.

    Raises
    ------
    LogError
        If a run has no velocity or acceleration (not prepared), too few
        samples (fewer than 2), non-finite motion or effort values, or the runs mix effort
        units. The message names the run's source file.
    """
    runs = as_log_list(logs)
    unit = runs[0].effort_unit
    for run in runs:
        source = run.source or None
        if not run.is_prepared:
            missing = [name for name in ("velocity", "acceleration") if getattr(run, name) is None]
            raise LogError(source, f"log is not prepared: no {' and no '.join(missing)} channel "
                                   "(derive them with greybox.data.prepare first)")
        if len(run) < 2:
            raise LogError(source, f"log has {len(run)} sample(s), a model needs at least 2 (one time step)")
        for name in ("velocity", "acceleration", "effort"):
            values = getattr(run, name)
            if not np.all(np.isfinite(values)):
                bad = int(np.flatnonzero(~np.isfinite(values))[0])
                raise LogError(source, f"channel '{name}' is not finite at sample {bad} "
                                       f"(t = {run.time[bad]:.6g} s)")
        if not np.isfinite(run.sample_time) or run.sample_time <= 0.0:
            raise LogError(source, "time is not increasing: no positive sample time")
        if run.effort_unit != unit:
            raise LogError(source, f"runs mix effort units: {unit} and {run.effort_unit}")
    return runs


class CurrentModel(BaseEstimator):
    """Base class of the current models (scikit-learn estimator conventions).

    Subclasses store their hyperparameters in ``__init__`` and implement

    - ``_fit_runs(runs, progress)``: identify the parameters from prepared
      runs and set the learned attributes (ending in ``_``), among them
      ``J_`` [A s^2/mm] and ``offset_`` [A];
    - ``_friction_run(run)``: the friction current of one run [A];
    - ``_n_params()``: the number of identified parameters.

    Learned attributes set here: ``effort_unit_`` ("A" or "N"),
    ``sample_time_`` (median step of the fitted runs [s]) and
    ``n_samples_fit_``.
    """

    def fit(self, logs: AxisLog | Iterable[AxisLog], progress=None) -> "CurrentModel":
        """Identify the model from one or several prepared runs.

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs (velocity [mm/s] and acceleration [mm/s^2] present).
        progress : None, bool or callable, optional
            ``None``/``False``: silent. ``True``: print progress to stderr.
            A callable receives :class:`greybox.identify.progress.ProgressEvent`.

        Returns
        -------
        self
        """
        runs = check_runs(logs)
        self.effort_unit_ = runs[0].effort_unit
        self.sample_time_ = float(np.median([run.sample_time for run in runs]))
        self.n_samples_fit_ = int(sum(len(run) for run in runs))
        self._fit_runs(runs, make_progress(progress))
        return self

    def predict(self, logs: AxisLog | Iterable[AxisLog]) -> np.ndarray:
        """Predicted effort ``J a + friction + offset`` [A, or N].

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs; the state of a dynamic model restarts at each run.

        Returns
        -------
        ndarray, shape (n_samples,)
            The prediction of each run, concatenated in order.
        """
        runs = self._check_predict_runs(logs)
        return np.concatenate([self.J_ * run.acceleration + self._friction_run(run) + self.offset_
                               for run in runs])

    def friction(self, logs: AxisLog | Iterable[AxisLog]) -> np.ndarray:
        """Friction part of the prediction (no inertia, no offset) [A, or N].

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs; the state of a dynamic model restarts at each run.

        Returns
        -------
        ndarray, shape (n_samples,)
        """
        runs = self._check_predict_runs(logs)
        return np.concatenate([self._friction_run(run) for run in runs])

    @property
    def n_params(self) -> int:
        """Number of identified parameters of the fitted model."""
        check_is_fitted(self)
        return self._n_params()

    def _check_predict_runs(self, logs) -> list[AxisLog]:
        check_is_fitted(self)
        runs = check_runs(logs)
        for run in runs:
            if run.effort_unit != self.effort_unit_:
                raise LogError(run.source or None,
                               f"log carries effort in {run.effort_unit}, the model was fitted on {self.effort_unit_}")
        return runs

    def _fit_runs(self, runs: list[AxisLog], progress) -> None:
        raise NotImplementedError

    def _friction_run(self, run: AxisLog) -> np.ndarray:
        raise NotImplementedError

    def _n_params(self) -> int:
        raise NotImplementedError
