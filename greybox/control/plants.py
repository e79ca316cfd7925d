"""Plants of the closed-loop simulation: the motor current drives the axis.

:func:`greybox.twin.simulate_plant` integrates the synthetic axis along a
*prescribed* motion; in a position loop the motion is the plant's response
to the controller's current, so the plants here integrate

    J dv/dt = I_motor + I_disturbance - F_friction(x, v, state),   dx/dt = v

at a fine internal step ``h`` (at least :data:`STEPS_PER_PERIOD` steps per
controller period; the motor current is held over the period),
semi-implicit Euler: ``v <- v + h a`` with the friction of the present
state, then ``x <- x + h v`` and the friction state follows the displacement
``h v`` of the step at the new velocity.

Timing: the reference and the feed-forward come at the reference's step
(e.g. 2 ms, the step the models were identified at); the controller runs
``periods`` times per reference step. Within reference sample ``k`` the
controller's set-point is ``x_k + v_k t + a_k t^2 / 2`` and the feed-forward
``I_ff[k]`` is held. The kernels record, per reference sample, the true
position and the plant's friction at the sample, the mean motor current
over the sample and the fraction of its controller periods at the current limit.

* :class:`TwinPlant`: the synthetic axis's truth plant (24 elasto-plastic
  Maxwell-slip elements, lagged Stribeck weakening, viscous friction,
  position profile; :mod:`greybox.twin.plant`), with the same element update
  as the twin's kernel, or its inertia alone (``friction=False``).
* :class:`ModelPlant`: an identified GMS or LuGre model (inertia, friction,
  offset) as the plant. Static models (Coulomb, Stribeck) are not usable as
  plants: their friction is undefined at rest, where a position loop spends
  its time.

Each plant's loop kernel runs the controller (:func:`greybox.control.pid.pid_step`)
and the plant together, compiled with numba.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..errors import GreyboxError
from ..friction.kernels import _gms_element_step
from ..twin.plant import PlantParameters, default_plant_parameters
from .pid import ControllerSettings, measure, pid_step

__all__ = [
    "STEPS_PER_PERIOD",
    "PlantTrace",
    "TwinPlant",
    "ModelPlant",
    "fine_stride",
    "stribeck_ratio",
    "maxwell_slip_update",
    "twin_loop_kernel",
    "gms_loop_kernel",
    "lugre_loop_kernel",
]

#: Fewest internal plant steps per controller period.
STEPS_PER_PERIOD = 4

#: Largest ``omega h`` (natural frequency of the stiffest friction spring with
#: the inertia, times the internal step) and ``c h / J`` (friction damping)
#: the internal step is chosen for; semi-implicit Euler is stable below 2.
_MAX_STEP_RATIO = 0.25


class PlantTrace(NamedTuple):
    """What a closed-loop run of a plant records at every controller sample.

    Attributes
    ----------
    position_mm : ndarray
        True position at the sample [mm].
    current_A : ndarray
        Mean motor current command over the sample [A].
    friction_A : ndarray
        Friction current of the plant at the sample [A].
    saturated : ndarray
        Fraction of the controller periods of the sample at the current limit.
    """

    position_mm: np.ndarray
    current_A: np.ndarray
    friction_A: np.ndarray
    saturated: np.ndarray


def fine_stride(period_s: float, max_step_s: float) -> int:
    """Number of internal steps per period [s]: the fewest with a step <= ``max_step_s`` [s]."""
    if not (np.isfinite(period_s) and period_s > 0.0):
        raise GreyboxError(f"period must be positive, got {period_s} s")
    return max(1, int(math.ceil(period_s / max_step_s * (1.0 - 1e-9))))


@njit(cache=True)
def _set_point(reference, k, offset_s):
    """Reference position [mm] ``offset_s`` after sample ``k``: ``x + v t + a t^2 / 2``."""
    return reference[k, 0] + offset_s * (reference[k, 1] + 0.5 * offset_s * reference[k, 2])


def _stable_step(inertia: float, stiffness: float, damping: float) -> float:
    """Largest internal step [s] for the friction stiffness [A/mm] and damping [A s/mm] on the inertia."""
    limits = [np.inf]
    if stiffness > 0.0:
        limits.append(_MAX_STEP_RATIO * math.sqrt(inertia / stiffness))
    if damping > 0.0:
        limits.append(_MAX_STEP_RATIO * inertia / damping)
    return float(min(limits))


# ------------------------------------------------------------------ twin
@njit(cache=True)
def stribeck_ratio(speed, coulomb_ratio, stribeck_velocity, shape):
    """Steady Stribeck ratio ``r_c + (1 - r_c) exp(-(|v|/v_s)^delta)`` of the twin (1 at rest)."""
    return coulomb_ratio + (1.0 - coulomb_ratio) * math.exp(-((abs(speed) / stribeck_velocity) ** shape))


@njit(cache=True)
def maxwell_slip_update(deflection, step_mm, level, stiffness, breakaway_deflection):
    """Move every elasto-plastic element by ``step_mm`` and clamp it; return ``sum_i k_i d_i`` [A].

    The update of :func:`greybox.twin.plant.maxwell_slip_kernel`:
    ``d_i <- clip(d_i + dx, -D_i r, +D_i r)``.

    Parameters
    ----------
    deflection : ndarray, shape (m,)
        Element deflections ``d_i`` [mm], updated in place.
    step_mm : float
        Axis displacement over the step [mm].
    level : float
        Stribeck ratio ``r`` scaling the breakaway deflections.
    stiffness, breakaway_deflection : ndarray, shape (m,)
        ``k_i`` [A/mm] and ``D_i`` [mm].
    """
    force = 0.0
    for j in range(deflection.shape[0]):
        limit = breakaway_deflection[j] * level
        d = deflection[j] + step_mm
        if d > limit:
            d = limit
        elif d < -limit:
            d = -limit
        deflection[j] = d
        force += stiffness[j] * d
    return force


class _TwinArguments(NamedTuple):
    stiffness: np.ndarray
    breakaway_deflection: np.ndarray
    coulomb_ratio: float
    stribeck_velocity: float
    stribeck_shape: float
    lag_decay: float
    viscous: float
    inertia: float
    travel_low: float
    travel_high: float
    preload_gain: float
    lead_mm: float
    lead_gain: float
    lead_phase: float


@njit(cache=True)
def _twin_friction(plant, position, velocity, elastic):
    u = (2.0 * position - plant.travel_low - plant.travel_high) / (plant.travel_high - plant.travel_low)
    factor = 1.0 + plant.preload_gain * u ** 4 + plant.lead_gain * math.sin(
        2.0 * math.pi * position / plant.lead_mm + plant.lead_phase)
    return factor * elastic + plant.viscous * velocity


@njit(cache=True)
def twin_loop_kernel(reference, feedforward, disturbance, settings, periods, plant, stride, step_s,
                     position_out, current_out, friction_out, saturated_out):
    """Position loop around the twin's truth plant, from rest at the first reference position.

    Parameters
    ----------
    reference : ndarray, shape (n, 3)
        Reference position [mm], velocity [mm/s] and acceleration [mm/s^2] at every sample.
    feedforward, disturbance : ndarray, shape (n,)
        Feed-forward current [A] and disturbance current [A] (added to the
        motor current), held over each reference sample.
    settings : ControllerSettings
        Discretised controller.
    periods : int
        Controller periods per reference sample.
    plant : _TwinArguments
        Plant parameters (``lag_decay = exp(-step_s / tau)``).
    stride : int
        Internal steps per controller period.
    step_s : float
        Internal step [s].
    position_out, current_out, friction_out, saturated_out : ndarray, shape (n,)
        Receive the fields of :class:`PlantTrace` at every reference sample.
    """
    deflection = np.zeros(plant.stiffness.shape[0])
    level = 1.0
    elastic = 0.0
    x = reference[0, 0]
    v = 0.0
    memory = np.zeros(3)
    memory[2] = reference[0, 0] - measure(x, settings.resolution_mm)
    for k in range(reference.shape[0]):
        position_out[k] = x
        friction_out[k] = _twin_friction(plant, x, v, elastic)
        total = 0.0
        saturated = 0
        for j in range(periods):
            error = _set_point(reference, k, j * settings.period_s) - measure(x, settings.resolution_mm)
            current = pid_step(memory, settings, error, feedforward[k])
            total += current
            saturated += abs(current) >= settings.current_limit_A
            drive = current + disturbance[k]
            for _ in range(stride):
                v += step_s * (drive - _twin_friction(plant, x, v, elastic)) / plant.inertia
                x += step_s * v
                target = stribeck_ratio(v, plant.coulomb_ratio, plant.stribeck_velocity, plant.stribeck_shape)
                level = target + (level - target) * plant.lag_decay
                elastic = maxwell_slip_update(deflection, step_s * v, level, plant.stiffness,
                                              plant.breakaway_deflection)
        current_out[k] = total / periods
        saturated_out[k] = saturated / periods


class TwinPlant:
    """The synthetic axis's truth plant in a position loop.

    Parameters
    ----------
    params : PlantParameters
        Truth plant (:func:`greybox.twin.default_plant_parameters`).
    friction : bool, default True
        With ``False`` the plant is the inertia alone (no friction at all).
    name : str, optional
        Label; default ``"twin"``, or ``"twin (no friction)"``.
    axis : str, optional
        Axis of the synthetic machine the parameters belong to (``"X"``, ``"Y"``).

    Notes
    -----
    The internal step is the plant's ``internal_step_s`` (0.25 ms), or the
    largest divisor of the controller period below it.
    """

    effort_unit = "A"

    def __init__(self, params: PlantParameters, *, friction: bool = True, name: str | None = None,
                 axis: str | None = None):
        self.params = params
        self.friction = bool(friction)
        self.name = name or ("twin" if self.friction else "twin (no friction)")
        self.axis = axis

    @classmethod
    def for_axis(cls, axis: str, *, friction: bool = True) -> "TwinPlant":
        """Default truth plant of axis ``"X"`` or ``"Y"``, named ``twin-X`` / ``twin-Y``."""
        key = str(axis).strip().upper()
        suffix = "" if friction else " (no friction)"
        return cls(default_plant_parameters(key), friction=friction, name=f"twin-{key}{suffix}", axis=key)

    @property
    def inertia_A_s2_mm(self) -> float:
        """Inertia ``J`` [A s^2/mm]."""
        return float(self.params.inertia_A_s2_mm)

    def describe(self) -> dict:
        """JSON-serialisable description."""
        return {"plant": self.name, "kind": "twin", "axis": self.axis, "friction": self.friction,
                "parameters": self.params.to_dict()}

    def run(self, reference, feedforward_A, disturbance_A, settings: ControllerSettings, periods: int
            ) -> PlantTrace:
        """Run the loop (see :func:`twin_loop_kernel` for the arguments) and return the recorded trace."""
        p = self.params
        stride = fine_stride(settings.period_s, min(p.internal_step_s, settings.period_s / STEPS_PER_PERIOD))
        step = settings.period_s / stride
        scale = 1.0 if self.friction else 0.0
        arguments = _TwinArguments(
            np.asarray(p.stiffness_A_mm, float) * scale, np.asarray(p.breakaway_deflection_mm, float),
            float(p.coulomb_ratio), float(p.stribeck_velocity_mm_s), float(p.stribeck_shape),
            math.exp(-step / p.lag_time_s) if p.lag_time_s > 0 else 0.0, float(p.viscous_A_s_mm) * scale,
            float(p.inertia_A_s2_mm), float(p.travel_mm[0]), float(p.travel_mm[1]), float(p.preload_gain),
            float(p.lead_mm), float(p.lead_gain), float(p.lead_phase_rad))
        return _run(twin_loop_kernel, arguments, stride, step, reference, feedforward_A, disturbance_A,
                    settings, periods)


def _run(kernel, arguments, stride, step, reference, feedforward_A, disturbance_A, settings, periods
         ) -> PlantTrace:
    n = len(reference)
    motion = np.ascontiguousarray(np.column_stack((reference.position, reference.velocity,
                                                   reference.acceleration)))
    trace = PlantTrace(np.empty(n), np.empty(n), np.empty(n), np.empty(n))
    kernel(motion, np.ascontiguousarray(feedforward_A, dtype=float), np.ascontiguousarray(disturbance_A, dtype=float),
           settings, int(periods), arguments, int(stride), float(step), *trace)
    return trace


# ------------------------------------------------------------------ identified models
class _GMSArguments(NamedTuple):
    alpha: np.ndarray
    k: np.ndarray
    sigma: float
    s_0: float
    s_inf: float
    v_s: float
    c: float
    mu: float
    inertia: float
    offset: float


@njit(cache=True)
def _gms_friction(plant, velocity, rate, z):
    """``sum_i k_i z_i + sigma rate + mu v`` [A] (summed in element order)."""
    force = plant.mu * velocity + plant.sigma * rate
    for i in range(z.shape[0]):
        force += plant.k[i] * z[i]
    return force


@njit(cache=True)
def gms_loop_kernel(reference, feedforward, disturbance, settings, periods, plant, stride, step_s,
                    position_out, current_out, friction_out, saturated_out):
    """Position loop around an identified GMS model (arguments as :func:`twin_loop_kernel`).

    The elements follow the GMS law of :mod:`greybox.friction.kernels`
    (the same compiled element step) at the internal step; the friction is
    ``sum_i (k_i z_i + alpha_i sigma dz_i/dt) + mu v`` with ``dz_i/dt`` of the
    previous internal step, and the offset acts as a constant load.
    ``friction_out`` excludes the offset.
    """
    n_elements = plant.alpha.shape[0]
    z = np.zeros(n_elements)
    mode = np.zeros(n_elements, dtype=np.int8)
    rate = 0.0
    x = reference[0, 0]
    v = 0.0
    c_dt = plant.c * step_s
    memory = np.zeros(3)
    memory[2] = reference[0, 0] - measure(x, settings.resolution_mm)
    for k in range(reference.shape[0]):
        position_out[k] = x
        friction_out[k] = _gms_friction(plant, v, rate, z)
        total = 0.0
        saturated = 0
        for j in range(periods):
            error = _set_point(reference, k, j * settings.period_s) - measure(x, settings.resolution_mm)
            current = pid_step(memory, settings, error, feedforward[k])
            total += current
            saturated += abs(current) >= settings.current_limit_A
            drive = current + disturbance[k] - plant.offset
            for _ in range(stride):
                friction = _gms_friction(plant, v, rate, z)
                v += step_s * (drive - friction) / plant.inertia
                x += step_s * v
                s = plant.s_inf + (plant.s_0 - plant.s_inf) * math.exp(-abs(v) / plant.v_s)
                direction = 1 if v > 0.0 else (-1 if v < 0.0 else 0)
                rate = 0.0
                for i in range(n_elements):
                    z_new, mode[i] = _gms_element_step(z[i], mode[i], direction, v * step_s, plant.alpha[i] * s,
                                                       plant.alpha[i], c_dt, 1.0 / s)
                    rate += plant.alpha[i] * (z_new - z[i]) / step_s
                    z[i] = z_new
        current_out[k] = total / periods
        saturated_out[k] = saturated / periods


class _LuGreArguments(NamedTuple):
    sigma0: float
    sigma1: float
    sigma2: float
    coulomb: float
    static: float
    v_s: float
    inertia: float
    offset: float


@njit(cache=True)
def lugre_loop_kernel(reference, feedforward, disturbance, settings, periods, plant, stride, step_s,
                      position_out, current_out, friction_out, saturated_out):
    """Position loop around an identified LuGre model (arguments as :func:`twin_loop_kernel`).

    The bristle deflection takes the exact step of
    :func:`greybox.friction.kernels.lugre_trajectory_kernel` with the new
    velocity held over the internal step; the friction is
    ``sigma0 z + sigma1 dz/dt + sigma2 v`` with ``dz/dt`` of the previous
    internal step, and the offset acts as a constant load.
    ``friction_out`` excludes the offset.
    """
    z = 0.0
    rate = 0.0
    x = reference[0, 0]
    v = 0.0
    memory = np.zeros(3)
    memory[2] = reference[0, 0] - measure(x, settings.resolution_mm)
    for k in range(reference.shape[0]):
        position_out[k] = x
        friction_out[k] = plant.sigma0 * z + plant.sigma1 * rate + plant.sigma2 * v
        total = 0.0
        saturated = 0
        for j in range(periods):
            error = _set_point(reference, k, j * settings.period_s) - measure(x, settings.resolution_mm)
            current = pid_step(memory, settings, error, feedforward[k])
            total += current
            saturated += abs(current) >= settings.current_limit_A
            drive = current + disturbance[k] - plant.offset
            for _ in range(stride):
                friction = plant.sigma0 * z + plant.sigma1 * rate + plant.sigma2 * v
                v += step_s * (drive - friction) / plant.inertia
                x += step_s * v
                speed = abs(v)
                g = plant.coulomb + (plant.static - plant.coulomb) * math.exp(-speed / plant.v_s)
                decay = plant.sigma0 * speed / g * step_s
                if decay > 0.0:
                    z_new = z * math.exp(-decay) - v * step_s * math.expm1(-decay) / decay
                else:
                    z_new = z + v * step_s
                rate = (z_new - z) / step_s
                z = z_new
        current_out[k] = total / periods
        saturated_out[k] = saturated / periods


class ModelPlant:
    """An identified GMS or LuGre current model as the plant of the loop.

    The model's inertia ``J_`` [A s^2/mm], friction and offset ``offset_`` [A]
    (a constant load) make the plant ``J a = I - F - I_0``; the model's
    friction law is integrated at an internal step small enough for its
    stiffness and damping on its inertia (at most ``max_step_s``).

    Parameters
    ----------
    model : GMSModel or LuGreModel
        Fitted model.
    name : str, optional
        Label; default the model kind.
    max_step_s : float, default 0.25e-3
        Largest internal step [s].

    Raises
    ------
    GreyboxError
        For another model kind, an unfitted model, or a non-positive inertia.
    """

    def __init__(self, model, *, name: str | None = None, max_step_s: float = 0.25e-3):
        from sklearn.utils.validation import check_is_fitted

        from ..registry import model_kind

        kind = model_kind(model)
        if kind not in ("gms", "lugre"):
            raise GreyboxError(f"a {kind} model cannot serve as the plant: only dynamic friction models "
                               "(gms, lugre) define the friction at rest; use twin-X, twin-Y or a gms/lugre model")
        check_is_fitted(model)
        if not (np.isfinite(model.J_) and model.J_ > 0.0):
            raise GreyboxError(f"the {kind} model has inertia J = {model.J_} A s^2/mm; a plant needs J > 0")
        self.model = model
        self.kind = kind
        self.name = name or kind
        self.max_step_s = float(max_step_s)
        self.effort_unit = model.effort_unit_

    @property
    def inertia_A_s2_mm(self) -> float:
        """Inertia ``J`` [A s^2/mm] (or [N s^2/mm] for force models)."""
        return float(self.model.J_)

    def describe(self) -> dict:
        """JSON-serialisable description."""
        return {"plant": self.name, "kind": self.kind, "inertia": self.inertia_A_s2_mm,
                "effort_unit": self.effort_unit}

    def _arguments(self):
        m = self.model
        if self.kind == "gms":
            arguments = _GMSArguments(np.ascontiguousarray(m.alpha_, float), np.ascontiguousarray(m.k_, float),
                                      float(m.sigma_), float(m.s0_), float(m.s_inf_), float(m.v_s_), float(m.C_),
                                      float(m.mu_), float(m.J_), float(m.offset_))
            stiffness, damping = float(np.sum(m.k_)), float(m.sigma_ + m.mu_)
            slip_step = min(m.s0_, m.s_inf_) / m.C_  # forward-Euler slip relaxes without overshoot below it
            return gms_loop_kernel, arguments, min(_stable_step(m.J_, stiffness, damping), slip_step)
        arguments = _LuGreArguments(float(m.sigma0_), float(m.sigma1_), float(m.viscous_), float(m.coulomb_),
                                    float(m.static_), float(m.v_s_), float(m.J_), float(m.offset_))
        return lugre_loop_kernel, arguments, _stable_step(m.J_, m.sigma0_, m.sigma1_ + m.viscous_)

    def run(self, reference, feedforward_A, disturbance_A, settings: ControllerSettings, periods: int
            ) -> PlantTrace:
        """Run the loop (see :func:`gms_loop_kernel`, :func:`lugre_loop_kernel`) and return the trace."""
        kernel, arguments, stable_step = self._arguments()
        stride = fine_stride(settings.period_s, min(self.max_step_s, stable_step, settings.period_s / STEPS_PER_PERIOD))
        return _run(kernel, arguments, stride, settings.period_s / stride, reference, feedforward_A,
                    disturbance_A, settings, periods)
