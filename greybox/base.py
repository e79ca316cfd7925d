"""The model protocol: what every current model of greybox tells its callers.

A current model predicts the drive effort of a feed axis from its prepared
motion, ``I = J a + I_friction(v, history) + I_0`` in A (or N for force logs).
Callers (chunked prediction, the discovery workflow, the position loop, the
command line, reports, model files) never ask a model what kind it is: the
model class answers through the methods documented here, and a new kind of
model is one new module that implements them plus one line in
:mod:`greybox.models.registry`.

:class:`ModelProtocol` lists the methods with their contracts and the default
answers of a model that has no state, no linear parameters and no plant law;
:class:`greybox.models.estimator.CurrentModel` implements the shared parts (fitting
template, validation of runs, prediction of one run or chunk) on top of it.
This module imports nothing else of greybox, so that every part of the
package may depend on it.

The protocol
------------
``initial_state()``
    State before the first sample of a run (``None`` for a memoryless model).
``predict_chunk(log, state, sample_time=)``
    Current of one chunk of a run from a given state, and the state after it:
    chaining the chunks of a run reproduces the one-shot prediction.
``linear_part(run)``, ``linear_coefficients()``, ``set_linear_coefficients(values)``
    The parameters the prediction is linear in, as regressor columns, so that
    added terms can be refitted jointly with them (:mod:`greybox.discover`).
``plant_law()``
    The friction law as a plant of the position loop (:mod:`greybox.control`).
``parameter_table()``
    Identified parameters with units and descriptions, for the command line,
    reports and benchmark protocols.
``interval_coordinates()``, ``interval_notes()``, ``interval_stage(runs)``
    What :mod:`greybox.identify.intervals` varies to give the parameters
    their 95 % intervals, and why a parameter gets none.
``score(logs)``
    Negative RMSE, so that scikit-learn's model selection accepts the models.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from sklearn.base import BaseEstimator

__all__ = ["EFFORT", "LENGTH", "LinearPart", "ModelProtocol", "Parameter", "PlantLaw"]

#: Placeholder for the effort unit ("A" or "N") in the units of :class:`Parameter`.
EFFORT = "{E}"

#: Placeholder for the length unit ("mm", or "deg" for a rotary axis) in the units of :class:`Parameter`.
LENGTH = "{L}"


@dataclass(frozen=True)
class Parameter:
    """One identified parameter of a fitted model, as a row of its parameter table.

    Attributes
    ----------
    name : str
        Name without the trailing underscore of the attribute (``"J"``, ``"k"``);
        a parameter of a nested model is prefixed with the stage (``"gms.k"``).
    value : float, int or ndarray
        Value in ``unit``.
    unit : str
        Unit with the effort unit written out (``"A s/mm"``, ``"N/mm"``); ``"-"``
        for a dimensionless number.
    description : str
        What the parameter is, in a few words.
    lower, upper : float, ndarray or None
        Ends of its 95 % interval in ``unit`` (the value's shape; NaN where there
        is none); ``None`` when no intervals were computed
        (:mod:`greybox.identify.intervals`).
    flag : str
        ``""``, or why the interval is missing or not to be trusted
        (``"not identifiable"``, ``"at bound"``, ``"poorly determined"``, ``"no interval: ..."``).
    """

    name: str
    value: object
    unit: str
    description: str
    lower: object = None
    upper: object = None
    flag: str = ""


@dataclass(frozen=True)
class LinearPart:
    """A prediction written as ``columns @ coefficients + fixed``.

    Attributes
    ----------
    columns : ndarray, shape (n, p)
        Regressors of the linear parameters.
    fixed : ndarray, shape (n,)
        The part of the prediction that is not linear in them [A].
    names : tuple of str
        Parameter names, one per column.
    lower, upper : ndarray, shape (p,)
        Bounds of the coefficients.
    """

    columns: np.ndarray
    fixed: np.ndarray
    names: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray

    @classmethod
    def from_columns(cls, columns, names, *, non_negative: int = 0, fixed=None) -> "LinearPart":
        """Build a part from a list of columns, the first ``non_negative`` of them bounded below by 0.

        Parameters
        ----------
        columns : list of ndarray, each shape (n,)
            Regressors; may be empty, then ``fixed`` gives the length.
        names : sequence of str
            One name per column.
        non_negative : int, default 0
            Number of leading coefficients bounded below by zero.
        fixed : ndarray, shape (n,), optional
            Part of the prediction that is not linear in the coefficients; zero by default.
        """
        matrix = np.column_stack(columns) if len(columns) else np.empty((len(fixed), 0))
        lower = np.full(matrix.shape[1], -np.inf)
        lower[:non_negative] = 0.0
        fixed = np.zeros(matrix.shape[0]) if fixed is None else np.asarray(fixed, dtype=float)
        return cls(matrix, fixed, tuple(names), lower, np.full(matrix.shape[1], np.inf))


@dataclass(frozen=True)
class PlantLaw:
    """A friction law as the plant of a position loop.

    The loop (:mod:`greybox.control.plants`) integrates ``J dv/dt = I - F - offset``
    by semi-implicit Euler: the velocity from ``friction`` of the present
    state, then the position, then ``advance`` at the new velocity. The two
    functions are compiled with numba for float64 C-contiguous ``parameters``
    and ``state`` (the loop takes them as first-class functions).

    Attributes
    ----------
    friction : callable
        Compiled ``friction(parameters, state, position_mm, velocity_mm_s) -> float``:
        the friction [A] of the present state at the position [mm] and velocity [mm/s].
    advance : callable
        Compiled ``advance(parameters, state, velocity_mm_s, step_s) -> None``: moves
        ``state`` (in place) over one internal step [s] at the given velocity [mm/s]
        (the displacement of the step is ``step_s * velocity_mm_s``).
    parameters : ndarray of float64
        Parameters of the law, in the layout ``friction`` and ``advance`` read.
    state : ndarray of float64
        State of the law at rest (copied by the loop before use).
    stable_step_s : float
        Largest internal step [s] to run the law at (stable on its inertia, accurate).
    inertia : float
        ``J`` [A s^2/mm].
    offset : float
        Constant load [A].
    """

    friction: object
    advance: object
    parameters: np.ndarray
    state: np.ndarray
    stable_step_s: float
    inertia: float
    offset: float


class ModelProtocol(BaseEstimator):
    """The methods every current model offers, with the answers of a model that offers nothing extra.

    A model overrides what applies to it: a dynamic model its
    :meth:`initial_state`, a model with linear parameters :meth:`linear_part`,
    :meth:`linear_coefficients` and :meth:`set_linear_coefficients`, a model
    that defines friction at rest :meth:`plant_law`; every model its
    :meth:`parameter_table`.
    """

    def initial_state(self):
        """State before the first sample of a run.

        Returns
        -------
        object or None
            ``None`` for a memoryless model (the default).
        """
        return None

    def linear_part(self, run) -> LinearPart:
        """Columns of the linear parameters over one prepared run.

        ``columns @ linear_coefficients() + fixed`` equals ``predict(run)``.
        The default has no columns: the whole prediction is ``fixed``.

        Parameters
        ----------
        run : AxisLog
            One prepared run.
        """
        prediction = self.predict(run)
        return LinearPart.from_columns([], (), fixed=prediction)

    def linear_coefficients(self) -> np.ndarray:
        """Present values of the linear parameters, in the order of :meth:`linear_part`'s columns."""
        return np.empty(0)

    def set_linear_coefficients(self, values) -> None:
        """Write jointly fitted values of the linear parameters into the fitted model (in place).

        Parameters
        ----------
        values : array_like, shape (p,)
            New values, in the order of :meth:`linear_part`'s columns.
        """
        if np.asarray(values).size:
            raise ValueError(f"a {type(self).__name__} has no linear parameters, got {np.asarray(values).size} values")

    def plant_law(self) -> PlantLaw | None:
        """The friction law as a plant of the position loop.

        Returns
        -------
        PlantLaw or None
            ``None`` by default: only a dynamic friction law defines the
            friction at rest, where a position loop spends its time.
        """
        return None

    def parameter_table(self) -> list[Parameter]:
        """The identified parameters with units and descriptions."""
        raise NotImplementedError

    def interval_coordinates(self) -> dict[str, str]:
        """Nonlinear identified parameters, as learned attributes to vary for the parameter intervals.

        The linear coefficients (:meth:`linear_part`) are varied anyway; this names the others:
        ``{attribute: "log"}`` for a positive number varied on a log scale, ``{attribute: "simplex"}``
        for a vector of positive fractions summing to 1 (varied in its logits).

        Returns
        -------
        dict of str to str
            Empty by default (no nonlinear parameters).
        """
        return {}

    def interval_value(self, name: str):
        """Present value of a coordinate named by :meth:`interval_coordinates`.

        Parameters
        ----------
        name : str
            A key of :meth:`interval_coordinates`.

        Returns
        -------
        float or ndarray
            The learned attribute ``name`` by default, in its own unit.
        """
        return getattr(self, name)

    def set_interval_value(self, name: str, value) -> None:
        """Write a value of a coordinate named by :meth:`interval_coordinates` (in place).

        The intervals move each coordinate by a small step and write the saved value back; a model whose
        coordinates are not plain learned attributes, or that keeps quantities derived from them, overrides
        this and :meth:`interval_value`.

        Parameters
        ----------
        name : str
            A key of :meth:`interval_coordinates`.
        value : float or ndarray
            The new value, in the coordinate's own unit (fractions summing to 1 for a simplex).
        """
        setattr(self, name, value)

    def interval_notes(self) -> dict[str, str]:
        """Rows of :meth:`parameter_table` that get no interval, with the reason in a few words.

        Returns
        -------
        dict of str to str
            ``{row name: reason}``, e.g. ``{"C": "hyperparameter chosen by cross-validation"}``; empty by default.
        """
        return {}

    def interval_stage(self, runs):
        """The fitted stage whose least-squares problem identifies this model's parameters, if another model's.

        Parameters
        ----------
        runs : list of AxisLog
            The prepared runs the model was fitted on.

        Returns
        -------
        None or (model, str, list of AxisLog)
            ``None`` (default): the model identifies its own parameters. Else the fitted stage, the prefix
            of its rows in this model's table (``"gms."``) and the runs the stage was fitted on.
        """
        return None
