"""The library of candidate effects: named parametric terms with physical regressors.

The terms of the augmented model kind (:mod:`greybox.models.augmented`), the
candidates that ``greybox discover`` (:mod:`greybox.discover`) searches.

Each :class:`Effect` turns a prepared run into regressor columns, so that the
effect's current is ``columns @ coefficients`` [A, or N for force logs]. Some
effects also have one *shape* parameter that enters nonlinearly (a period in
position, a time constant, a Stribeck velocity); the discovery workflow scans
it over :meth:`Effect.shape_grid` and refines it by least squares.

With the direction of motion ``d = tanh(v / v_e)`` (``v_e`` the
:class:`EffectContext`'s velocity scale), ``f`` the friction the effects
modulate (:meth:`EffectContext.friction_shape`: the base model's own friction
less its viscous part, over its level, so that a friction changing along the travel or with time is
the base's friction law scaled, pre-sliding and Stribeck curve included;
``d`` when there is no base model), ``u`` the position scaled to
``[-1, 1]`` over the position range of the training data (and held at its end
values beyond: a trend is not extrapolated), ``t`` the time since
the start of the run and ``x``, ``v``, ``a`` position [mm], velocity [mm/s]
and acceleration [mm/s^2]:

========================== ============================================== ================
name                       columns                                        shape
========================== ============================================== ================
direction_asymmetry        ``max(f, 0)``, ``v max(d, 0)``                 -
constant_offset            ``1``                                          -
position_trend             ``u f``, ``(3 u^2 - 1) / 2 * f``               -
position_periodic_friction ``sin(2 pi x / P) f``, ``cos(2 pi x / P) f``   ``P`` [mm]
position_periodic_force    ``sin(2 pi x / P)``, ``cos(2 pi x / P)``       ``P`` [mm]
thermal_drift              ``(1 - exp(-t / tau)) f``                      ``tau`` [s]
inertia_mismatch           ``a``                                          -
viscous_friction           ``v``                                          -
stribeck                   ``exp(-|v| / v_s) d``                          ``v_s`` [mm/s]
load_dependent_friction    ``|a| f``                                      -
========================== ============================================== ================

The names are those of the synthetic axis's hidden effects
(:data:`greybox.twin.EFFECTS`), plus ``stribeck`` and
``load_dependent_friction`` (friction growing with the axial load, here the
inertial load ``|a|``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from ..data.log import AxisLog
from ..errors import GreyboxError
from .friction.kernels import play_operator_kernel

__all__ = ["BASE_FRICTION", "EffectContext", "Effect", "EFFECTS", "EFFECT_NAMES", "REFINEMENTS", "VELOCITY_ONLY",
           "VELOCITY_CURVE_SCALES", "PRESLIDING_WIDTHS_MM", "presliding_states",
           "PERIOD_SEPARATION_STEPS", "effect", "period_grid", "period_scan", "scan_periods",
           "default_velocity_scale"]

#: Periods are scanned at this many points per periodogram resolution ``1 / range``.
_PERIOD_OVERSAMPLING = 4
#: Longest period: the position range holds this many periods.
_MIN_PERIODS_IN_RANGE = 2
#: Shortest period: this many samples per period at the median moving speed.
_SAMPLES_PER_PERIOD = 4
#: Most periods a scan tries (the shortest period grows beyond that).
_MAX_PERIODS = 4000
#: Two terms of one periodic effect keep their spatial frequencies at least this many scan steps apart
#: (closer, their columns are nearly the same and their amplitudes are not identifiable).
PERIOD_SEPARATION_STEPS = 2
#: Points of the logarithmic grids of time constants and Stribeck velocities.
_LOG_GRID_POINTS = 24
#: Extra channel of a run holding the base model's friction less its viscous part [A, or N]
#: (see :meth:`EffectContext.friction_shape`).
BASE_FRICTION = "base_friction"


def default_velocity_scale(runs: Sequence[AxisLog]) -> float:
    """Velocity scale ``v_e`` [mm/s] of the direction factor ``tanh(v / v_e)``.

    1 % of the 99th percentile of ``|v|`` over all runs: small against the
    feed speeds, large against velocity noise at rest.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs; their velocities [mm/s] are pooled.
    """
    speed = np.concatenate([np.abs(run.velocity) for run in runs])
    scale = 0.01 * float(np.percentile(speed, 99.0))
    if not scale > 0.0:
        raise GreyboxError("the velocity is zero throughout: effects cannot be scaled to the motion")
    return scale


@dataclass(frozen=True)
class EffectContext:
    """Scales the effect regressors depend on, fixed from the training runs.

    Parameters
    ----------
    velocity_scale_mm_s : float
        ``v_e`` of the direction factor ``d = tanh(v / v_e)`` [mm/s].
    position_range_mm : tuple of float
        Lower and upper position [mm] mapped to ``u = -1`` and ``u = +1``.
    run_start_s : float, optional
        Time [s] at which the run started, for effects of the time since the
        start of the run; ``None``: the first sample of the log passed. Set it
        when a log is a part of a run (a chunk of a long run).
    friction_level : float, optional
        Level of the base model's friction less its viscous part [A, or N]
        (its 90th percentile ``|F|`` on the training runs) that the friction
        effects scale; the runs then carry that friction as the extra channel
        :data:`BASE_FRICTION`.
        ``None``: no base model, friction effects scale the direction of motion.
    presliding_start : tuple, optional
        ``(states, position_mm)``: the pre-sliding refinement's play-operator
        states (:func:`presliding_states`) at the position [mm] of the sample
        before the log passed, for a log that is a chunk of a run. ``None``:
        the run starts with the log, the states at 0.
    """

    velocity_scale_mm_s: float
    position_range_mm: tuple[float, float]
    run_start_s: float | None = None
    friction_level: float | None = None
    presliding_start: tuple | None = None

    @classmethod
    def from_runs(cls, runs: Sequence[AxisLog], velocity_scale_mm_s: float | None = None) -> "EffectContext":
        """Context of prepared training runs (``v_e`` by :func:`default_velocity_scale` unless given).

        Parameters
        ----------
        runs : sequence of AxisLog
            Prepared training runs; their lowest and highest position [mm] give ``position_range_mm``.
        velocity_scale_mm_s : float, optional
            ``v_e`` [mm/s]; None: :func:`default_velocity_scale` of ``runs``.
        """
        low = float(min(np.min(run.position) for run in runs))
        high = float(max(np.max(run.position) for run in runs))
        if not high > low:
            raise GreyboxError("the position does not change: position effects cannot be scaled")
        scale = default_velocity_scale(runs) if velocity_scale_mm_s is None else float(velocity_scale_mm_s)
        if not scale > 0.0:
            raise GreyboxError(f"velocity scale must be positive, got {scale} mm/s")
        return cls(scale, (low, high))

    def direction(self, run: AxisLog) -> np.ndarray:
        """Smoothed direction of motion ``tanh(v / v_e)`` (-1 ... 1).

        Parameters
        ----------
        run : AxisLog
            One prepared run.
        """
        return np.tanh(run.velocity / self.velocity_scale_mm_s)

    def friction_shape(self, run: AxisLog) -> np.ndarray:
        """What friction effects scale: the base's friction less its viscous part over its level, or ``d``.

        Parameters
        ----------
        run : AxisLog
            One prepared run; with a ``friction_level`` it must carry the :data:`BASE_FRICTION` channel.
        """
        if self.friction_level is None:
            return self.direction(run)
        if BASE_FRICTION not in run.extras:
            raise GreyboxError(f"the run carries no '{BASE_FRICTION}' channel: friction effects scale the base "
                               "model's friction (see AugmentedModel.with_base_friction)")
        return run.extras[BASE_FRICTION] / self.friction_level

    def elapsed(self, run: AxisLog) -> np.ndarray:
        """Time since the start of the run [s] (see ``run_start_s``).

        Parameters
        ----------
        run : AxisLog
            One prepared run, or a chunk of one.
        """
        start = run.time[0] if self.run_start_s is None else self.run_start_s
        return run.time - start

    def unit_position(self, run: AxisLog) -> np.ndarray:
        """Position scaled to ``u`` in [-1, 1] over the context's range, held at -1 / +1 beyond it.

        Parameters
        ----------
        run : AxisLog
            One prepared run.
        """
        low, high = self.position_range_mm
        return np.clip((2.0 * run.position - low - high) / (high - low), -1.0, 1.0)


@dataclass(frozen=True)
class ShapeParameter:
    """The nonlinear parameter of an effect.

    Parameters
    ----------
    name : str
        Name with its unit, e.g. ``"period_mm"``.
    scale : {"frequency", "log"}
        How the scan steps: uniformly in ``1 / shape`` or in ``log(shape)``.
    grid : callable
        ``grid(runs, context) -> ndarray`` of the scanned values.
    """

    name: str
    scale: str
    grid: Callable[[Sequence[AxisLog], EffectContext], np.ndarray]


@dataclass(frozen=True)
class Effect:
    """A named candidate effect: regressor columns and the physical parameters they give.

    Parameters
    ----------
    name : str
        Name users see (see the module table).
    summary : str
        One line saying what the effect is physically.
    column_names : tuple of str
        Names of the regressor columns.
    build : callable
        ``build(run, context, shape) -> ndarray (n, n_columns)``.
    describe : callable
        ``describe(coefficients, context, shape, unit) -> dict`` of physical parameters.
    shape : ShapeParameter or None
        The nonlinear parameter, if any.
    weight : callable or None
        Periodic effects only: ``weight(run, context) -> ndarray (n,)``, the
        factor of their sine and cosine (1 for a force, the direction for a
        friction), for scans over the period.
    """

    name: str
    summary: str
    column_names: tuple[str, ...]
    build: Callable[[AxisLog, EffectContext, float | None], np.ndarray]
    describe: Callable[[np.ndarray, EffectContext, float | None, str], dict]
    shape: ShapeParameter | None = None
    weight: Callable[[AxisLog, EffectContext], np.ndarray] | None = None

    @property
    def n_columns(self) -> int:
        """Number of linear coefficients."""
        return len(self.column_names)

    def check_shape(self, shape: float | None) -> float | None:
        """Return ``shape`` as a float (None for effects without one), or raise :class:`GreyboxError`.

        Parameters
        ----------
        shape : float or None
            Value of the shape parameter, in its unit (period [mm], time constant [s] or
            Stribeck velocity [mm/s]); must be positive, or None for an effect without one.
        """
        if self.shape is None:
            if shape is not None:
                raise GreyboxError(f"effect {self.name!r} has no shape parameter, got {shape!r}")
            return None
        if shape is None or not np.isfinite(shape) or shape <= 0.0:
            raise GreyboxError(f"effect {self.name!r} needs a positive {self.shape.name}, got {shape!r}")
        return float(shape)

    def columns(self, run: AxisLog, context: EffectContext, shape: float | None = None) -> np.ndarray:
        """Regressor columns of one prepared run, shape ``(n, n_columns)``.

        Parameters
        ----------
        run : AxisLog
            One prepared run.
        context : EffectContext
            Scales of the regressors.
        shape : float, optional
            Value of the shape parameter in its unit; None for an effect without one.
        """
        columns = self.build(run, context, self.check_shape(shape))
        return np.asarray(columns, dtype=float).reshape(len(run), self.n_columns)

    def current(self, run: AxisLog, context: EffectContext, coefficients, shape: float | None = None
                ) -> np.ndarray:
        """The effect's current ``columns @ coefficients`` over one run [A, or N].

        Parameters
        ----------
        run : AxisLog
            One prepared run.
        context : EffectContext
            Scales of the regressors.
        coefficients : array_like, shape (n_columns,)
            Linear coefficients of the columns.
        shape : float, optional
            Value of the shape parameter in its unit; None for an effect without one.
        """
        return self.columns(run, context, shape) @ np.asarray(coefficients, dtype=float)

    def parameters(self, coefficients, context: EffectContext, shape: float | None = None,
                   unit: str = "A") -> dict[str, float]:
        """Physical parameters from fitted coefficients; names end in their unit (``unit`` = A or N).

        Parameters
        ----------
        coefficients : array_like, shape (n_columns,)
            Fitted linear coefficients of the columns.
        context : EffectContext
            Scales the columns were built with.
        shape : float, optional
            Value of the shape parameter in its unit; None for an effect without one.
        unit : str, default "A"
            Effort unit of the coefficients, "A" or "N"; used in the parameter names.
        """
        return self.describe(np.asarray(coefficients, dtype=float), context, self.check_shape(shape), unit)

    def shape_grid(self, runs: Sequence[AxisLog], context: EffectContext) -> np.ndarray | None:
        """Values of the shape parameter a scan tries (None without one).

        Parameters
        ----------
        runs : sequence of AxisLog
            Prepared training runs.
        context : EffectContext
            Scales of the regressors.
        """
        return None if self.shape is None else self.shape.grid(runs, context)

    def shape_bracket(self, shape: float, grid: np.ndarray) -> tuple[float, float]:
        """Interval around ``shape`` one grid step wide on either side (in the grid's own scale), inside the grid.

        Parameters
        ----------
        shape : float
            Centre of the interval, in the shape parameter's unit.
        grid : ndarray, shape (m,)
            Scanned values of the shape parameter (:meth:`shape_grid`).
        """
        if self.shape.scale == "frequency":
            frequencies = 1.0 / grid
            step = float(np.max(np.abs(np.diff(frequencies)))) if grid.size > 1 else 0.5 / shape
            low_f = max(1.0 / shape - step, float(frequencies.min()))
            high_f = min(1.0 / shape + step, float(frequencies.max()))
            return 1.0 / high_f, 1.0 / low_f
        ratio = float(np.exp(np.max(np.abs(np.diff(np.log(grid)))))) if grid.size > 1 else 2.0
        return max(shape / ratio, float(grid.min())), min(shape * ratio, float(grid.max()))


# ----------------------------------------------------------------- grids
def period_scan(runs: Sequence[AxisLog], context: EffectContext) -> tuple[float, np.ndarray]:
    """Spatial frequency step [1/mm] and periods [mm] scanned for the position-periodic effects.

    The frequencies ``1 / P`` are the integer multiples of the step
    ``1 / (4 R)`` (four points per periodogram resolution ``1 / R``, ``R``
    the position range of the training data) from ``2 / R`` (two periods in
    the range: a slower variation is a trend, not something periodic) up to
    ``1 / P_min``, ``P_min`` giving 4 samples per period at the median moving
    speed, but at most 4000 periods (``P_min >= R / 1000``). Periods come
    longest first.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared training runs; their position steps give the median moving speed per sample.
    context : EffectContext
        Its ``position_range_mm`` is ``R``.
    """
    low, high = context.position_range_mm
    span = high - low
    steps = np.concatenate([np.abs(np.diff(run.position)) for run in runs])
    moving = steps[steps > 0.0]
    p_min = _SAMPLES_PER_PERIOD * float(np.median(moving)) if moving.size else span / 4.0
    step = 1.0 / (_PERIOD_OVERSAMPLING * span)
    first = int(round(_MIN_PERIODS_IN_RANGE / (span * step)))
    last = min(int(np.floor(1.0 / (min(p_min, span / 4.0) * step) + 1e-9)), first + _MAX_PERIODS - 1)
    return step, 1.0 / (np.arange(first, last + 1) * step)


def scan_periods(runs: Sequence[AxisLog], context: EffectContext, excluded: Sequence[float] = ()
                 ) -> tuple[float, np.ndarray]:
    """:func:`period_scan` without the periods within :data:`PERIOD_SEPARATION_STEPS` steps of ``excluded`` [mm].

    Those periods are in the model already (a periodic effect named again takes another period).

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared training runs.
    context : EffectContext
        Scales of the regressors.
    excluded : sequence of float, default ()
        Periods already in the model [mm].
    """
    step, grid = period_scan(runs, context)
    if len(excluded):
        distance = np.abs(1.0 / grid[:, None] - 1.0 / np.asarray(excluded, dtype=float)[None, :])
        grid = grid[np.all(distance > PERIOD_SEPARATION_STEPS * step, axis=1)]
    return step, grid


def period_grid(runs: Sequence[AxisLog], context: EffectContext) -> np.ndarray:
    """Periods [mm] scanned for the position-periodic effects (see :func:`period_scan`).

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared training runs.
    context : EffectContext
        Scales of the regressors.
    """
    return period_scan(runs, context)[1]


def _time_constant_grid(runs, context) -> np.ndarray:
    longest = max(run.time[-1] - run.time[0] for run in runs)
    return np.geomspace(longest / 50.0, 10.0 * longest, _LOG_GRID_POINTS)


def _stribeck_velocity_grid(runs, context) -> np.ndarray:
    """Stribeck velocities [mm/s] from three velocity scales ``v_e`` to the top speed.

    Below ``3 v_e`` a Stribeck term would only mimic the smoothing of the direction factor.
    """
    speed = np.concatenate([np.abs(run.velocity) for run in runs])
    top = float(np.percentile(speed, 99.9))
    return np.geomspace(min(max(1e-3 * top, 3.0 * context.velocity_scale_mm_s), 0.5 * top), top, _LOG_GRID_POINTS)


# ----------------------------------------------------------------- columns and parameters
def _legendre_2(u):
    return 0.5 * (3.0 * u * u - 1.0)


def _friction_weight(run, context):
    return context.friction_shape(run)


def _force_weight(run, context):
    return np.ones(len(run))


def _periodic(weight):
    def build(run, context, period):
        phase = 2.0 * np.pi * run.position / period
        return np.column_stack((np.sin(phase), np.cos(phase))) * weight(run, context)[:, None]
    return build


def _amplitude_phase(coefficients, context, period, unit):
    sine, cosine = coefficients
    return {"period_mm": period, f"amplitude_{unit}": float(np.hypot(sine, cosine)),
            "phase_rad": float(np.arctan2(cosine, sine))}


def _trend_parameters(coefficients, context, shape, unit):
    low, high = context.position_range_mm
    linear, quadratic = coefficients
    return {f"slope_{unit}_per_mm": float(2.0 * linear / (high - low)),
            f"change_over_range_{unit}": float(2.0 * linear),
            f"end_rise_{unit}": float(1.5 * quadratic),
            "range_low_mm": low, "range_high_mm": high}


def _asymmetry_parameters(coefficients, context, shape, unit):
    level, viscous = coefficients
    return {f"level_difference_{unit}": float(level), f"viscous_difference_{unit}_s_per_mm": float(viscous)}


def _single(key):
    def describe(coefficients, context, shape, unit):
        return {key.format(E=unit): float(coefficients[0])}
    return describe


def _with_shape(key, shape_key):
    def describe(coefficients, context, shape, unit):
        return {key.format(E=unit): float(coefficients[0]), shape_key: shape}
    return describe


_PERIOD = ShapeParameter("period_mm", "frequency", period_grid)

_LIBRARY = (
    Effect("direction_asymmetry", "friction differs with the direction of motion (level and viscous part)",
           ("positive_level", "positive_viscous"),
           lambda run, c, s: np.column_stack((np.maximum(c.friction_shape(run), 0.0),
                                              run.velocity * np.maximum(c.direction(run), 0.0))),
           _asymmetry_parameters),
    Effect("constant_offset", "constant effort: gravity, weight compensation or a current bias",
           ("one",),
           lambda run, c, s: np.ones(len(run)),
           _single("offset_{E}")),
    Effect("position_trend", "friction changing smoothly along the travel",
           ("trend_linear", "trend_quadratic"),
           lambda run, c, s: np.column_stack((c.unit_position(run), _legendre_2(c.unit_position(run))))
           * c.friction_shape(run)[:, None],
           _trend_parameters),
    Effect("position_periodic_friction", "friction periodic in position, flipping with the direction "
           "(ball-screw preload ripple)",
           ("sin_friction", "cos_friction"),
           _periodic(_friction_weight), _amplitude_phase, _PERIOD, _friction_weight),
    Effect("position_periodic_force", "force periodic in position, the same in both directions (cogging)",
           ("sin_force", "cos_force"),
           _periodic(_force_weight), _amplitude_phase, _PERIOD, _force_weight),
    Effect("thermal_drift", "friction changing with the time since the start of the run",
           ("drift",),
           lambda run, c, s: (1.0 - np.exp(-c.elapsed(run) / s)) * c.friction_shape(run),
           _with_shape("change_{E}", "time_constant_s"),
           ShapeParameter("time_constant_s", "log", _time_constant_grid)),
    Effect("inertia_mismatch", "inertia the model lacks (e.g. a workpiece on the table)",
           ("acceleration",),
           lambda run, c, s: run.acceleration,
           _single("extra_inertia_{E}_s2_per_mm")),
    Effect("viscous_friction", "friction proportional to the velocity",
           ("velocity",),
           lambda run, c, s: run.velocity,
           _single("extra_viscous_{E}_s_per_mm")),
    Effect("stribeck", "friction excess at low speed, decaying with the speed",
           ("stribeck",),
           lambda run, c, s: np.exp(-np.abs(run.velocity) / s) * c.direction(run),
           _with_shape("excess_at_rest_{E}", "v_s_mm_s"),
           ShapeParameter("v_s_mm_s", "log", _stribeck_velocity_grid)),
    Effect("load_dependent_friction", "friction growing with the axial (inertial) load",
           ("load",),
           lambda run, c, s: np.abs(run.acceleration) * c.friction_shape(run),
           _single("friction_per_acceleration_{E}_s2_per_mm")),
)

#: The candidate effects by name.
EFFECTS: dict[str, Effect] = {e.name: e for e in _LIBRARY}

#: Effect names in library order.
EFFECT_NAMES: tuple[str, ...] = tuple(EFFECTS)

#: Speeds of the velocity curve's columns, in units of ``v_e`` (``v_e`` is 1 % of the 99th percentile speed,
#: so the last is about the top speed).
VELOCITY_CURVE_SCALES = (3.0, 7.0, 17.0, 40.0, 100.0)


def _velocity_curve(run, context, shape):
    speed = np.abs(run.velocity)[:, None]
    scales = context.velocity_scale_mm_s * np.asarray(VELOCITY_CURVE_SCALES)[None, :]
    return np.exp(-speed / scales) * context.direction(run)[:, None]


def _curve_parameters(coefficients, context, shape, unit):
    def excess(speed):
        return float(np.exp(-speed / (context.velocity_scale_mm_s * np.asarray(VELOCITY_CURVE_SCALES)))
                     @ coefficients)
    top = context.velocity_scale_mm_s * VELOCITY_CURVE_SCALES[-1]
    return {f"excess_at_rest_{unit}": excess(0.0), f"excess_at_tenth_top_speed_{unit}": excess(0.1 * top),
            f"excess_at_top_speed_{unit}": excess(top), "top_speed_mm_s": float(top)}


#: Break-away displacements [mm] of the pre-sliding refinement's play operators: 1 um to 0.1 mm, the range of
#: the pre-sliding displacements of the rolling contacts of feed drives (ball screws, linear guides).
PRESLIDING_WIDTHS_MM = (0.001, 0.003, 0.01, 0.03, 0.1)


def presliding_states(run: AxisLog, context: EffectContext) -> tuple[np.ndarray, tuple]:
    """States of the pre-sliding refinement's play operators over a run, and where they end.

    Parameters
    ----------
    run : AxisLog
        One prepared run, or a chunk of one.
    context : EffectContext
        Its ``presliding_start`` gives the states before the first sample.

    Returns
    -------
    states : ndarray, shape (n, len(PRESLIDING_WIDTHS_MM))
        The states (-1 ... 1) at every sample, from ``context.presliding_start`` (zeros when None).
    end : tuple
        ``(states at the last sample, its position [mm])``: the ``presliding_start`` of the next chunk.
    """
    widths = np.asarray(PRESLIDING_WIDTHS_MM, dtype=float)
    position = np.ascontiguousarray(run.position, dtype=float)
    if context.presliding_start is None:
        state, previous = np.zeros(widths.size), float(position[0])
    else:
        state, previous = np.array(context.presliding_start[0], dtype=float), float(context.presliding_start[1])
    states = np.empty((position.size, widths.size))
    play_operator_kernel(position, widths, state, previous, states)
    return states, (tuple(float(value) for value in state), float(position[-1]))


def _presliding(run, context, shape):
    states = presliding_states(run, context)[0]
    held = states[:, :1]
    return np.hstack((held - context.direction(run)[:, None], states[:, 1:] - held))


def _presliding_parameters(coefficients, context, shape, unit):
    coefficients = np.asarray(coefficients, dtype=float)
    return {f"held_excess_at_rest_{unit}": float(coefficients[0]),
            f"excess_just_after_reversal_{unit}": float(-2.0 * coefficients[1:].sum())}


#: Refinements of the base model, not named effects; the workflow fits them before naming anything and
#: reports them as *base misfit*:
#:
#: - ``velocity_curve``: a flexible friction curve along the speed, the same in both directions, that any
#:   velocity-only friction law the base model lacks projects onto (a Stribeck curve of another shape,
#:   viscous friction that is not linear);
#: - ``presliding_hysteresis``: friction held at rest and pre-sliding hysteresis of another shape than the
#:   base's. With ``s_k`` the states of play operators (:func:`greybox.models.friction.kernels.play_operator_kernel`)
#:   of break-away displacements :data:`PRESLIDING_WIDTHS_MM`, the first (1 um) being the direction of the
#:   last motion ``h``: the columns ``h - d`` (friction held at rest beyond what the velocity curve gives
#:   there; zero once moving) and ``s_k - h`` for the wider operators (pre-sliding transients over the first
#:   ``2 w_k`` of travel after a reversal; zero once they have passed). Zero in steady sliding, so they do not
#:   compete with the base's and the velocity curve's friction levels. The states start at 0 at the first
#:   sample of a run (its history before is unknown; they forget it within 0.2 mm of travel) and carry over
#:   from chunk to chunk of a run (``EffectContext.presliding_start``).
#:
#: Both are odd in the motion, the same law in both directions, and depend on the velocity and the
#: position's recent path only: none can stand in for an effect of the position, the time or a direction.
REFINEMENTS: dict[str, Effect] = {
    "velocity_curve": Effect("velocity_curve", "friction along the speed that the base model's own curve "
                             "misses (the same in both directions)",
                             tuple(f"curve_{i}" for i in range(len(VELOCITY_CURVE_SCALES))),
                             _velocity_curve, _curve_parameters),
    "presliding_hysteresis": Effect(
        "presliding_hysteresis", "friction held at rest and pre-sliding hysteresis the base model misses (the "
        "same in both directions)",
        ("held_at_rest",) + tuple(f"transient_{i}" for i in range(1, len(PRESLIDING_WIDTHS_MM))),
        _presliding, _presliding_parameters),
}

#: Library effects that depend on the velocity alone: the velocity curve spans them (base misfit, not a
#: missing effect).
VELOCITY_ONLY = ("viscous_friction", "stribeck")


def effect(name: str) -> Effect:
    """Return the library effect or base refinement (:data:`REFINEMENTS`) ``name``.

    Parameters
    ----------
    name : str
        Name of a library effect (:data:`EFFECT_NAMES`) or of a refinement.

    Raises
    ------
    GreyboxError
        If there is no such effect.
    """
    if name in REFINEMENTS:
        return REFINEMENTS[name]
    if name not in EFFECTS:
        raise GreyboxError(f"unknown effect {name!r}; the library has {', '.join(EFFECT_NAMES)}")
    return EFFECTS[name]
