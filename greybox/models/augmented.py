"""A base current model plus named effect terms, fitted jointly.

:class:`AugmentedModel` adds terms of the effect library
(:mod:`greybox.models.effects`) to a friction model and fits them together:

1. the base model is identified by its own ``fit`` (its nonlinear shape:
   Stribeck velocity, GMS element fractions, ...);
2. with that shape held, the base's linear parameters
   (:meth:`~greybox.base.ModelProtocol.linear_part`: inertia, friction levels or
   stiffnesses, viscous coefficient, offset) and the coefficients of all terms
   are solved by one bounded least-squares fit, and the terms' own shape
   parameters (period, time constant, Stribeck velocity) are refined by a
   bounded scalar search of that fit's residual, one grid step around their
   start value;
3. with ``refit_base``, the base is identified again on the effort minus the
   terms (its shape may now move), and step 2 is repeated; the new shape is
   kept if the joint fit is then better.

Friction terms scale the friction of the base as identified in step 1 (or
3) less its viscous part, over its level
(:meth:`~greybox.models.effects.EffectContext.friction_shape`): a friction
that changes along the travel or with time is the base's sliding friction law
scaled, its Stribeck curve and pre-sliding included, not the lubricant's
viscous drag. That base is held
(``friction_shape_base_``) while the joint solve moves the base's linear
parameters, so that the solve stays one linear least-squares problem.

The prediction is ``J a + base friction + sum of terms + offset``. A
``constant_offset`` term is reported in ``offset_`` and an
``inertia_mismatch`` term in ``J_``; every other term belongs to what
:meth:`~greybox.models.estimator.CurrentModel.friction` returns (so does a
cogging-like ``position_periodic_force``, which is not friction strictly).
"""

from __future__ import annotations

import copy
from dataclasses import replace
from typing import Iterable, Sequence

import numpy as np
from scipy.optimize import minimize_scalar
from sklearn.base import clone
from sklearn.utils.validation import check_is_fitted
from threadpoolctl import threadpool_limits

from ..base import EFFORT, LinearPart, Parameter
from ..data.log import AxisLog
from ..errors import GreyboxError, ParameterError
from ..identify.linear import bounded_lstsq
from ..identify.progress import make_progress
from ..identify.projection import Nuisance, PositionScan, added_squares
from .effects import (
    BASE_FRICTION,
    PERIOD_SEPARATION_STEPS,
    Effect,
    EffectContext,
    effect,
    period_scan,
    presliding_states,
)
from .estimator import CurrentModel, check_runs
from .friction.directions import viscous_columns
from .friction.gms import GMSModel

__all__ = ["AugmentedModel", "normalise_effects"]

#: Terms reported in the model's inertia and offset rather than in its friction.
_INERTIA_TERM = "inertia_mismatch"
_OFFSET_TERM = "constant_offset"
#: The base refinement whose play-operator states carry over from chunk to chunk.
_PRESLIDING_TERM = "presliding_hysteresis"
#: Names of the interval coordinates (:meth:`AugmentedModel.interval_coordinates`): the base's, a term's shape.
_BASE_PREFIX = "base."
_SHAPE_SUFFIX = ".shape"


def normalise_effects(effects) -> list[tuple[str, float | None]]:
    """``effects`` as a list of ``(name, shape)`` pairs, checked against the library.

    Parameters
    ----------
    effects : iterable
        Items ``"name"`` or ``(name, shape)``; the shape (period [mm], time
        constant [s] or Stribeck velocity [mm/s]) may be None for an effect
        that has one, to let the fit choose it.

    Raises
    ------
    GreyboxError
        For an unknown effect, a bad shape, or an effect without a shape
        parameter given twice.
    """
    pairs = []
    for item in effects or ():
        name, shape = (item, None) if isinstance(item, str) else tuple(item)
        term = effect(name)
        if shape is not None:
            term.check_shape(shape)
            shape = float(shape)
        if term.shape is None and any(existing == name for existing, _ in pairs):
            raise GreyboxError(f"effect {name!r} is given twice; only periodic effects may repeat")
        pairs.append((name, shape))
    return pairs


class AugmentedModel(CurrentModel):
    """Base current model plus effect terms, refitted jointly.

    Parameters
    ----------
    base : CurrentModel, optional
        Settings of the base model (unfitted, cloned before fitting);
        ``GMSModel()`` by default. To start from a base already fitted to the
        same runs, pass it to :meth:`fit_terms` instead.
    effects : sequence, default ()
        Terms to add: effect names or ``(name, shape)`` pairs, see
        :func:`normalise_effects`. A periodic effect may appear more than once
        (with different periods).
    refine_shapes : bool, default True
        Refine each term's shape parameter by least squares within one grid
        step of its start value; otherwise keep it as given.
    refit_base : bool, default True
        After the first joint fit, identify the base model again on the
        effort minus the terms, then fit jointly once more.
    velocity_scale_mm_s : float, optional
        ``v_e`` of the direction factor ``tanh(v / v_e)`` of the terms [mm/s];
        1 % of the 99th percentile of the training speed by default.

    Attributes
    ----------
    base_ : CurrentModel
        The fitted base model, holding the jointly fitted linear parameters.
    effects_ : list of dict
        One entry per term: ``name``, ``shape`` (or None), ``coefficients``
        (one per column of the effect) and ``parameters`` (physical values,
        names ending in their unit).
    friction_level_ : float or None
        Level of the base model's friction on the training runs [A, or N]
        (90th percentile of ``|F|``, viscous part taken off): friction terms scale the friction of
        ``friction_shape_base_`` over this level (see
        :meth:`EffectContext.friction_shape`). None in files written before it
        existed: the terms then scale the direction of motion.
    friction_shape_base_ : CurrentModel or None
        The base model as identified (before the joint solve moved its linear
        parameters), whose friction less its viscous part the friction terms scale.
    friction_shape_viscous_ : dict
        That base's viscous coefficients (``viscous`` or ``viscous_pos``,
        ``viscous_neg``) [A s/mm, or N s/mm], taken off its friction.
    velocity_scale_mm_s_ : float
        ``v_e`` used [mm/s].
    position_range_mm_ : tuple of float
        Position range of the training runs [mm], the scale of ``position_trend``.
    J_ : float
        Inertia [A s^2/mm]: the base's plus an ``inertia_mismatch`` term.
    offset_ : float
        Offset [A]: the base's plus a ``constant_offset`` term.
    effort_unit_ : str
        "A" or "N".
    """

    def __init__(self, *, base=None, effects=(), refine_shapes: bool = True, refit_base: bool = True,
                 velocity_scale_mm_s: float | None = None):
        self.base = base
        self.effects = effects
        self.refine_shapes = refine_shapes
        self.refit_base = refit_base
        self.velocity_scale_mm_s = velocity_scale_mm_s

    # ---------------------------------------------------------------- fitting
    def _check_params(self) -> None:
        self._check_flags("refine_shapes", "refit_base")
        if self.base is not None and (not isinstance(self.base, CurrentModel) or isinstance(self.base, AugmentedModel)):
            raise ParameterError(f"base must be a current model other than AugmentedModel, "
                                 f"got {type(self.base).__name__}")
        normalise_effects(self.effects)
        scale = self.velocity_scale_mm_s
        if scale is not None and not (isinstance(scale, (int, float, np.number)) and np.isfinite(scale) and scale > 0):
            raise ParameterError(f"velocity_scale_mm_s must be a positive speed, got {scale!r} mm/s")

    def _template(self):
        return GMSModel() if self.base is None else self.base

    def _fit_runs(self, runs, progress) -> None:
        base = clone(self._template()).fit(runs, progress=progress)
        self._fit_terms(runs, base, progress)

    def fit_terms(self, logs: AxisLog | Iterable[AxisLog], base, progress=None) -> "AugmentedModel":
        """Fit the terms jointly with a base model already fitted to the same runs.

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs the base was fitted on.
        base : CurrentModel
            The fitted base (a copy is kept; its settings should match ``self.base``,
            which is used when ``refit_base`` identifies it again).
        progress : None, bool or callable, optional
            Passed to the base's ``fit`` when it is identified again.

        Returns
        -------
        self
        """
        self._check_params()
        check_is_fitted(base)
        runs = check_runs(logs)
        self._set_fit_info(runs)
        self._fit_terms(runs, copy.deepcopy(base), make_progress(progress))
        return self

    def _fit_terms(self, runs: list[AxisLog], base, progress) -> None:
        viscous = _viscous_coefficients(base, runs[0])
        context = replace(EffectContext.from_runs(runs, self.velocity_scale_mm_s),
                          friction_level=_friction_level(runs, base, viscous))
        terms = [(effect(name), shape) for name, shape in normalise_effects(self.effects)]
        target = np.concatenate([run.effort for run in runs])
        with threadpool_limits(limits=1, user_api="blas"):
            shape_base = copy.deepcopy(base)
            carried = _with_friction(runs, shape_base, viscous)
            shapes, coefficients = self._joint_fit(carried, base, context, terms, [s for _, s in terms], target)
            if self.refit_base and terms:
                term_current = self._term_currents(carried, context, terms, shapes, coefficients)
                shifted = [run.replace(effort=run.effort - part) for run, part in zip(runs, term_current)]
                new_base = clone(self._template()).fit(shifted, progress=progress)
                new_shape_base, new_viscous = copy.deepcopy(new_base), _viscous_coefficients(new_base, runs[0])
                new_carried = _with_friction(runs, new_shape_base, new_viscous)
                new_shapes, new_coefficients = self._joint_fit(new_carried, new_base, context, terms, shapes, target)
                # the base's new shape also changes the friction the terms scale: keep it only if it fits better
                before = _squares(base, carried, context, terms, shapes, coefficients, target)
                if _squares(new_base, new_carried, context, terms, new_shapes, new_coefficients, target) <= before:
                    base, shape_base, shapes, coefficients = new_base, new_shape_base, new_shapes, new_coefficients
                    viscous = new_viscous
        self.friction_shape_base_ = shape_base if context.friction_level is not None else None
        self.friction_shape_viscous_ = viscous
        self._store(base, context, terms, shapes, coefficients[base.linear_coefficients().size:])

    def _joint_fit(self, runs, base, context, terms, shapes, target) -> tuple[list, np.ndarray]:
        """Shapes and the joint coefficients (base's linear parameters first) at the base's present shape.

        The base's linear parameters are written into ``base``.
        """
        part = _joined([base.linear_part(run) for run in runs])
        shapes = [self._start_shape(term, shape, runs, context, part, target)
                  for (term, _), shape in zip(terms, shapes)]
        _check_separation(terms, shapes, runs, context)
        if self.refine_shapes:
            shapes = self._refine(runs, context, terms, shapes, part, target)
        coefficients = self._solve(runs, context, terms, shapes, part, target)[0]
        base.set_linear_coefficients(coefficients[:part.columns.shape[1]])
        return shapes, coefficients

    def _start_shape(self, term: Effect, shape, runs, context, part: LinearPart, target) -> float | None:
        """The given shape, or the best of the effect's grid against the base's residual."""
        if term.shape is None or shape is not None:
            return shape
        grid = term.shape_grid(runs, context)
        nuisance = Nuisance(part.columns)
        residual = nuisance.project((target - part.fixed)[:, None])
        if term.shape.scale == "frequency":
            weight = np.concatenate([term.weight(run, context) for run in runs])
            position = np.concatenate([run.position for run in runs])
            step = period_scan(runs, context)[0]
            scan = PositionScan(position, weight, nuisance, residual, step, 1.0 / float(np.min(grid)))
            scores = scan.reductions(grid)[:, 0]
        else:
            scores = [added_squares(np.concatenate([term.columns(run, context, g) for run in runs]),
                                    residual, nuisance)[0] for g in grid]
        return float(grid[int(np.argmax(scores))])

    def _design(self, runs, context, terms, shapes) -> np.ndarray:
        blocks = [np.concatenate([term.columns(run, context, shape) for run in runs])
                  for (term, _), shape in zip(terms, shapes)]
        return np.hstack(blocks) if blocks else np.empty((sum(len(run) for run in runs), 0))

    def _solve(self, runs, context, terms, shapes, part: LinearPart, target):
        extra = self._design(runs, context, terms, shapes)
        matrix = np.hstack((part.columns, extra))
        lower = np.concatenate((part.lower, np.full(extra.shape[1], -np.inf)))
        upper = np.concatenate((part.upper, np.full(extra.shape[1], np.inf)))
        if matrix.shape[1] == 0:
            residual = part.fixed - target
            return np.empty(0), float(residual @ residual)
        x, residual = bounded_lstsq(matrix, target - part.fixed, lower, upper)
        return x, float(residual @ residual)

    def _refine(self, runs, context, terms, shapes, part, target) -> list:
        shapes = list(shapes)
        for i, (term, _) in enumerate(terms):
            if term.shape is None:
                continue
            grid = term.shape_grid(runs, context)
            low, high = term.shape_bracket(shapes[i], grid)
            frequency = term.shape.scale == "frequency"
            if frequency:
                others = [shapes[j] for j, (other, _) in enumerate(terms) if j != i and other is term]
                low, high = _apart(shapes[i], low, high, others, period_scan(runs, context)[0])
            to_shape = (lambda s: 1.0 / s) if frequency else np.exp
            bounds = (1.0 / high, 1.0 / low) if frequency else (np.log(low), np.log(high))

            def cost(s, i=i, to_shape=to_shape):
                trial = shapes[:i] + [float(to_shape(s))] + shapes[i + 1:]
                return self._solve(runs, context, terms, trial, part, target)[1]

            start = 1.0 / shapes[i] if frequency else np.log(shapes[i])
            result = minimize_scalar(cost, bounds=bounds, method="bounded",
                                     options={"xatol": 1e-4 * abs(bounds[1] - bounds[0])})
            if result.fun < cost(start):
                shapes[i] = float(to_shape(result.x))
        return shapes

    @staticmethod
    def _term_currents(runs, context, terms, shapes, coefficients) -> list[np.ndarray]:
        """Sum of the terms' currents per run, from the joint solution's term coefficients."""
        n_base = len(coefficients) - sum(term.n_columns for term, _ in terms)
        out = []
        for run in runs:
            total = np.zeros(len(run))
            start = n_base
            for (term, _), shape in zip(terms, shapes):
                total += term.current(run, context, coefficients[start:start + term.n_columns], shape)
                start += term.n_columns
            out.append(total)
        return out

    def _store(self, base, context, terms, shapes, coefficients) -> None:
        self.base_ = base
        self.friction_level_ = context.friction_level
        self.velocity_scale_mm_s_ = float(context.velocity_scale_mm_s)
        self.position_range_mm_ = tuple(float(value) for value in context.position_range_mm)
        self.effects_ = []
        start = 0
        for (term, _), shape in zip(terms, shapes):
            values = coefficients[start:start + term.n_columns]
            start += term.n_columns
            self.effects_.append({
                "name": term.name,
                "shape": shape,
                "coefficients": [float(value) for value in values],
                "parameters": term.parameters(values, context, shape, self.effort_unit_),
            })
        self.J_ = float(base.J_) + sum(e["coefficients"][0] for e in self.effects_ if e["name"] == _INERTIA_TERM)
        self.offset_ = float(base.offset_) + sum(e["coefficients"][0] for e in self.effects_
                                                 if e["name"] == _OFFSET_TERM)

    # ---------------------------------------------------------------- prediction
    @property
    def context(self) -> EffectContext:
        """Scales of the effect regressors, fixed at fit time."""
        check_is_fitted(self, "effects_")
        return EffectContext(self.velocity_scale_mm_s_, tuple(self.position_range_mm_),
                             friction_level=getattr(self, "friction_level_", None))

    def with_base_friction(self, logs: AxisLog | Iterable[AxisLog]) -> list[AxisLog]:
        """The runs with the fitted base model's friction as their :data:`BASE_FRICTION` channel.

        The effect columns of :meth:`linear_part` and of the discovery's
        scores are built from such runs (friction effects scale the base's friction).

        Parameters
        ----------
        logs : AxisLog or iterable of AxisLog
            Prepared runs, of the effort unit and kind of axis the model was fitted on.
        """
        runs = self._check_predict_runs(logs)
        shape_base = getattr(self, "friction_shape_base_", None)
        return _with_friction(runs, shape_base, self.friction_shape_viscous_) if shape_base is not None else runs

    def initial_state(self):
        """``(base model's initial state, the scaled friction's, None, None)``: the run's start time and the
        pre-sliding states' start come from its first chunk."""
        shape_base = getattr(self, "friction_shape_base_", None)
        return self.base_.initial_state(), None if shape_base is None else shape_base.initial_state(), None, None

    def _simulate(self, run: AxisLog, state, sample_time):
        base_state, shape_state, run_start_s, presliding_start = state
        if run_start_s is None:
            run_start_s = float(run.time[0])
        base_friction, base_end = self.base_.friction_chunk(run, base_state, sample_time=sample_time)
        context = replace(self.context, run_start_s=run_start_s, presliding_start=presliding_start)
        if any(entry["name"] == _PRESLIDING_TERM for entry in self.effects_):
            presliding_start = presliding_states(run, context)[1]
        shape_base = getattr(self, "friction_shape_base_", None)
        if shape_base is not None:
            scaled, shape_state = shape_base.friction_chunk(run, shape_state, sample_time=sample_time)
            scaled = _without_viscous(scaled, run.velocity, self.friction_shape_viscous_)
            run = run.replace(extras={**run.extras, BASE_FRICTION: scaled})
        return base_friction + self._effect_friction(run, context), (base_end, shape_state, run_start_s,
                                                                     presliding_start)

    def _own_parameters(self) -> list[Parameter]:
        base = [Parameter(f"base.{p.name}", p.value, p.unit, f"base model: {p.description}")
                for p in self.base_.parameter_table()]
        relabel = self.units_.relabel  # names end in their unit, written in mm: deg for a rotary axis
        terms = [Parameter(f"{i + 1}:{e['name']}.{relabel(name)}", value, "(in the name)", f"added effect {e['name']}")
                 for i, e in enumerate(self.effects_) for name, value in e["parameters"].items()]
        level = getattr(self, "friction_level_", None)
        if level is not None:
            terms.append(Parameter("friction_level", level, EFFORT, "level of the base's sliding friction that "
                                   "friction terms scale (90th percentile of its magnitude on the training runs)"))
        return base + terms

    def _effect_friction(self, run: AxisLog, context: EffectContext) -> np.ndarray:
        """Friction of the effect terms (all but inertia and offset) over one run [A, or N]."""
        total = np.zeros(len(run))
        for entry in self.effects_:
            if entry["name"] not in (_INERTIA_TERM, _OFFSET_TERM):
                total += effect(entry["name"]).current(run, context, entry["coefficients"], entry["shape"])
        return total

    def _n_params(self) -> int:
        own = sum(effect(e["name"]).n_columns + (e["shape"] is not None) for e in self.effects_)
        return self.base_.n_params + own

    def term_currents(self, logs: AxisLog | Iterable[AxisLog]) -> dict[str, np.ndarray]:
        """The current of each term over the runs, concatenated [A, or N].

        Parameters
        ----------
        logs : AxisLog or iterable of AxisLog
            Prepared runs to evaluate the terms on.

        Returns
        -------
        dict
            ``"<index>:<name>"`` (1-based, in the order of ``effects_``) -> current.
        """
        runs = self.with_base_friction(logs)
        return {f"{i + 1}:{e['name']}": np.concatenate([effect(e["name"]).current(run, self.context,
                                                                                  e["coefficients"], e["shape"])
                                                        for run in runs])
                for i, e in enumerate(self.effects_)}

    def linear_part(self, logs: AxisLog | Sequence[AxisLog]) -> LinearPart:
        """The whole prediction as ``columns @ coefficients() + fixed`` at the fitted shapes.

        Columns: the base's linear parameters, then every term's columns
        (named ``"<effect>.<column>"``).

        Parameters
        ----------
        logs : AxisLog or sequence of AxisLog
            Prepared runs; unlike the base class's single run, several are stacked in order.
        """
        runs = self.with_base_friction(logs)
        part = _joined([self.base_.linear_part(run) for run in runs])
        names, blocks = list(part.names), [part.columns]
        for entry in self.effects_:
            term = effect(entry["name"])
            blocks.append(np.concatenate([term.columns(run, self.context, entry["shape"]) for run in runs]))
            names += [f"{term.name}.{column}" for column in term.column_names]
        n_extra = sum(block.shape[1] for block in blocks[1:])
        return LinearPart(np.hstack(blocks), part.fixed, tuple(names),
                          np.concatenate((part.lower, np.full(n_extra, -np.inf))),
                          np.concatenate((part.upper, np.full(n_extra, np.inf))))

    def linear_coefficients(self) -> np.ndarray:
        """Coefficients of :meth:`linear_part`'s columns: the base's, then every term's."""
        check_is_fitted(self, "effects_")
        return np.concatenate([self.base_.linear_coefficients()] + [e["coefficients"] for e in self.effects_])

    def set_linear_coefficients(self, values) -> None:
        """Write ``values`` (order of :meth:`linear_coefficients`) into the base model and the terms.

        Parameters
        ----------
        values : array_like, shape (p,)
            The base's linear parameters followed by every term's coefficients, as in the base class.
        """
        check_is_fitted(self, "effects_")
        x = np.asarray(values, dtype=float)
        n_base = self.base_.linear_coefficients().size
        self.base_.set_linear_coefficients(x[:n_base])
        start = n_base
        for entry in self.effects_:
            n = effect(entry["name"]).n_columns
            entry["coefficients"] = [float(value) for value in x[start:start + n]]
            entry["parameters"] = effect(entry["name"]).parameters(entry["coefficients"], self.context,
                                                                  entry["shape"], self.effort_unit_)
            start += n
        self.J_ = float(self.base_.J_) + sum(e["coefficients"][0] for e in self.effects_
                                             if e["name"] == _INERTIA_TERM)
        self.offset_ = float(self.base_.offset_) + sum(e["coefficients"][0] for e in self.effects_
                                                       if e["name"] == _OFFSET_TERM)

    # ---------------------------------------------------------------- parameter intervals
    def interval_coordinates(self) -> dict[str, str]:
        """The base's nonlinear parameters (``"base.<attribute>"``) and, when ``refine_shapes``, every term's
        shape parameter (``"<index>:<effect>.shape"``: period, time constant or Stribeck velocity, log scale).

        With ``refine_shapes`` false a term's shape is given or picked from its grid, not identified: it is
        not varied, and its row is flagged as held fixed.
        """
        check_is_fitted(self, "effects_")
        base = {f"{_BASE_PREFIX}{name}": kind for name, kind in self.base_.interval_coordinates().items()}
        terms = {f"{i + 1}:{e['name']}{_SHAPE_SUFFIX}": "log" for i, e in enumerate(self.effects_)
                 if e["shape"] is not None and self.refine_shapes}
        return {**base, **terms}

    def interval_value(self, name: str):
        """Present value of a coordinate of :meth:`interval_coordinates` (the base's attribute, or a term's shape).

        Parameters
        ----------
        name : str
            ``"base.<attribute>"`` or ``"<index>:<effect>.shape"``.
        """
        if name.startswith(_BASE_PREFIX):
            return self.base_.interval_value(name[len(_BASE_PREFIX):])
        return self.effects_[self._term_index(name)]["shape"]

    def set_interval_value(self, name: str, value) -> None:
        """Write a coordinate of :meth:`interval_coordinates`, with what is derived from it.

        A base parameter moves both the base and the friction the friction terms scale
        (``friction_shape_base_``: the base as identified, of the same shape); a term's shape moves
        that term's physical parameters too. ``friction_level_`` (the terms' scale) stays.

        Parameters
        ----------
        name : str
            ``"base.<attribute>"`` or ``"<index>:<effect>.shape"``.
        value : float or ndarray
            The new value, in the parameter's own unit ([mm], [s], [mm/s], or fractions for a simplex).
        """
        if name.startswith(_BASE_PREFIX):
            attribute = name[len(_BASE_PREFIX):]
            self.base_.set_interval_value(attribute, value)
            shape_base = getattr(self, "friction_shape_base_", None)
            if shape_base is not None:
                shape_base.set_interval_value(attribute, np.array(value) if np.ndim(value) else value)
            return
        entry = self.effects_[self._term_index(name)]
        entry["shape"] = float(value)
        entry["parameters"] = effect(entry["name"]).parameters(entry["coefficients"], self.context, entry["shape"],
                                                               self.effort_unit_)

    def _term_index(self, name: str) -> int:
        """Index into ``effects_`` of a term coordinate ``"<index>:<effect>.shape"`` (1-based index)."""
        index = int(name.split(":", 1)[0]) - 1
        if not (name.endswith(_SHAPE_SUFFIX) and 0 <= index < len(self.effects_)
                and name == f"{index + 1}:{self.effects_[index]['name']}{_SHAPE_SUFFIX}"):
            raise ValueError(f"no interval coordinate {name!r} in this model")
        return index


def _apart(period, low, high, others, step) -> tuple[float, float]:
    """Shrink the period bracket ``[low, high]`` [mm] around ``period`` so that its frequencies stay
    :data:`PERIOD_SEPARATION_STEPS` steps ``step`` [1/mm] away from the ``others``' frequencies."""
    f, f_low, f_high = 1.0 / period, 1.0 / high, 1.0 / low
    gap = PERIOD_SEPARATION_STEPS * step
    for other in others:
        g = 1.0 / other
        if g <= f:
            f_low = max(f_low, min(g + gap, f))
        else:
            f_high = min(f_high, max(g - gap, f))
    return 1.0 / f_high, 1.0 / f_low


def _check_separation(terms, shapes, runs, context) -> None:
    """Refuse two terms of one periodic effect whose periods are too close to be told apart."""
    step = None
    for i, (term, _) in enumerate(terms):
        for j in range(i):
            if terms[j][0] is term and term.shape is not None and term.shape.scale == "frequency":
                step = step or period_scan(runs, context)[0]
                if abs(1.0 / shapes[i] - 1.0 / shapes[j]) < PERIOD_SEPARATION_STEPS * step - 1e-12:
                    raise GreyboxError(
                        f"two {term.name} terms with periods {shapes[j]:.6g} and {shapes[i]:.6g} mm: "
                        f"closer than {PERIOD_SEPARATION_STEPS} steps of the period scan "
                        f"({step:.4g} 1/mm), the data cannot tell them apart")


def _squares(base, carried, context, terms, shapes, coefficients, target) -> float:
    """Residual sum of squares of the base (at its solved linear parameters) plus the terms."""
    terms_current = AugmentedModel._term_currents(carried, context, terms, shapes, coefficients)
    residual = target - base.predict(carried) - np.concatenate(terms_current)
    return float(residual @ residual)


def _friction_level(runs: Sequence[AxisLog], base, viscous: dict) -> float | None:
    """90th percentile of ``|friction|`` of the base less its viscous part over the runs [A, or N]; None if zero."""
    friction = np.concatenate([run.extras[BASE_FRICTION] for run in _with_friction(runs, base, viscous)])
    level = float(np.percentile(np.abs(friction), 90.0))
    return level if level > 0.0 and np.isfinite(level) else None


def _viscous_coefficients(base, run: AxisLog) -> dict[str, float]:
    """The base's viscous coefficients by the names of its linear part (``viscous``, or ``viscous_pos/neg``)."""
    names = base.linear_part(run).names
    values = base.linear_coefficients()
    return {name: float(value) for name, value in zip(names, values) if name.startswith("viscous")}


def _without_viscous(friction: np.ndarray, velocity: np.ndarray, viscous: dict) -> np.ndarray:
    """``friction`` minus the viscous part of the coefficients ``viscous`` (:func:`_viscous_coefficients`)."""
    if not viscous:
        return friction
    columns, names = viscous_columns(velocity, asymmetric=len(viscous) == 2)
    return friction - sum(column * viscous[name] for column, name in zip(columns, names))


def _with_friction(runs: Sequence[AxisLog], base, viscous: dict) -> list[AxisLog]:
    """The runs with ``base``'s friction less its viscous part as their :data:`BASE_FRICTION` channel."""
    return [run.replace(extras={**run.extras, BASE_FRICTION: _without_viscous(base.friction(run), run.velocity,
                                                                              viscous)})
            for run in runs]


def _joined(parts: list[LinearPart]) -> LinearPart:
    first = parts[0]
    return LinearPart(np.vstack([p.columns for p in parts]), np.concatenate([p.fixed for p in parts]),
                      first.names, first.lower, first.upper)
