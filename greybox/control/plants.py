"""Plants of the closed-loop simulation: the motor current drives the axis.

:func:`greybox.twin.simulate_plant` integrates the synthetic axis along a
*prescribed* motion; in a position loop the motion is the plant's response
to the controller's current, so the plants here integrate

    J dv/dt = I_motor + I_disturbance - F_friction(x, v, state) - I_0,   dx/dt = v

at a fine internal step ``h`` (at least :data:`STEPS_PER_PERIOD` steps per
controller period; the motor current is held over the period),
semi-implicit Euler: ``v <- v + h a`` with the friction of the present
state, then ``x <- x + h v`` and the friction state follows the displacement
``h v`` of the step at the new velocity.

The friction law comes from the plant as a :class:`greybox.base.PlantLaw`:
compiled ``friction`` and ``advance`` functions, their parameters and rest
state, a stable step, the inertia and a constant load ``I_0``. One loop
kernel (:func:`position_loop`, compiled once by :func:`compiled_position_loop`)
runs the controller (:func:`greybox.control.pid.pid_step`) and any law; it
takes the law's functions as first-class function arguments, so it is
compiled once for every law and its machine code is cached on disk.

Timing: the reference and the feed-forward come at the reference's step
(e.g. 2 ms, the step the models were identified at); the controller runs
``periods`` times per reference step. Within reference sample ``k`` the
controller's set-point is ``x_k + v_k t + a_k t^2 / 2`` and the feed-forward
``I_ff[k]`` is held. The kernel records, per reference sample, the true
position and the plant's friction at the sample, the mean motor current
over the sample and the fraction of its controller periods at the current limit.

* :class:`TwinPlant`: the synthetic axis's truth plant (24 elasto-plastic
  Maxwell-slip elements, lagged Stribeck weakening, viscous friction,
  position profile; :func:`greybox.twin.plant.twin_plant_law`, the same
  compiled element update as the twin's prescribed-motion kernel), or its
  inertia alone (``friction=False``).
* :class:`ModelPlant`: a fitted current model whose class offers a plant law
  (:meth:`~greybox.base.ModelProtocol.plant_law`: GMS, LuGre). Static models
  (Coulomb, Stribeck) offer none: their friction is undefined at rest, where
  a position loop spends its time.
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np
from numba import njit, typeof, types
from sklearn.utils.validation import check_is_fitted

from ..base import PlantLaw
from ..errors import GreyboxError
from ..models.registry import model_kind
from ..twin.plant import PlantParameters, default_plant_parameters, twin_plant_law
from .pid import ControllerSettings, measure, pid_step

__all__ = [
    "STEPS_PER_PERIOD",
    "PlantTrace",
    "TwinPlant",
    "ModelPlant",
    "fine_stride",
    "position_loop",
    "compiled_position_loop",
    "run_law",
]

#: Fewest internal plant steps per controller period.
STEPS_PER_PERIOD = 4

#: Numba type of a law's ``friction(parameters, state, position_mm, velocity_mm_s) -> float``.
FRICTION_TYPE = types.FunctionType(types.float64(types.float64[::1], types.float64[::1], types.float64,
                                                 types.float64))
#: Numba type of a law's ``advance(parameters, state, velocity_mm_s, step_s) -> None``.
ADVANCE_TYPE = types.FunctionType(types.none(types.float64[::1], types.float64[::1], types.float64, types.float64))


class PlantTrace(NamedTuple):
    """What a closed-loop run of a plant records at every controller sample.

    Attributes
    ----------
    position_mm : ndarray
        True position at the sample [mm].
    current_A : ndarray
        Mean motor current command over the sample [A].
    friction_A : ndarray
        Friction current of the plant at the sample [A] (without the constant load).
    saturated : ndarray
        Fraction of the controller periods of the sample at the current limit.
    """

    position_mm: np.ndarray
    current_A: np.ndarray
    friction_A: np.ndarray
    saturated: np.ndarray


def fine_stride(period_s: float, max_step_s: float) -> int:
    """Number of internal steps per period [s]: the fewest with a step <= ``max_step_s`` [s].

    Parameters
    ----------
    period_s : float
        Controller period [s], > 0.
    max_step_s : float
        Largest internal step allowed [s], > 0.

    Raises
    ------
    GreyboxError
        If ``period_s`` is not positive and finite.
    """
    if not (np.isfinite(period_s) and period_s > 0.0):
        raise GreyboxError(f"period must be positive, got {period_s} s")
    return max(1, int(math.ceil(period_s / max_step_s * (1.0 - 1e-9))))


@njit(cache=True)
def _set_point(reference, k, offset_s):
    """Reference position [mm] ``offset_s`` after sample ``k``: ``x + v t + a t^2 / 2``."""
    return reference[k, 0] + offset_s * (reference[k, 1] + 0.5 * offset_s * reference[k, 2])


# ------------------------------------------------------------------ the one loop kernel
def position_loop(reference, feedforward, disturbance, settings, periods, friction, advance, parameters, state,
                  stride, step_s, inertia, offset, position_out, current_out, friction_out, saturated_out):
    """Position loop around a plant law, from rest at the first reference position.

    Run it compiled (:func:`compiled_position_loop`); the Python function is its source.

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
    friction, advance : compiled functions
        The law's ``friction(parameters, state, position_mm, velocity_mm_s) -> float`` [A]
        and ``advance(parameters, state, velocity_mm_s, step_s)`` (see :class:`greybox.base.PlantLaw`).
    parameters : ndarray
        The law's parameters.
    state : ndarray
        The law's state at rest (copied, not changed).
    stride : int
        Internal steps per controller period.
    step_s : float
        Internal step [s].
    inertia : float
        ``J`` [A s^2/mm].
    offset : float
        Constant load ``I_0`` [A].
    position_out, current_out, friction_out, saturated_out : ndarray, shape (n,)
        Receive the fields of :class:`PlantTrace` at every reference sample.
    """
    state = state.copy()
    x = reference[0, 0]
    v = 0.0
    memory = np.zeros(3)
    memory[2] = reference[0, 0] - measure(x, settings.resolution_mm)
    for k in range(reference.shape[0]):
        position_out[k] = x
        friction_out[k] = friction(parameters, state, x, v)
        total = 0.0
        saturated = 0
        for j in range(periods):
            error = _set_point(reference, k, j * settings.period_s) - measure(x, settings.resolution_mm)
            current = pid_step(memory, settings, error, feedforward[k])
            total += current
            saturated += abs(current) >= settings.current_limit_A
            drive = current + disturbance[k] - offset
            for _ in range(stride):
                v += step_s * (drive - friction(parameters, state, x, v)) / inertia
                x += step_s * v
                advance(parameters, state, v, step_s)
        current_out[k] = total / periods
        saturated_out[k] = saturated / periods


@functools.cache
def compiled_position_loop():
    """:func:`position_loop` compiled (once, on first use) for every plant law.

    The law's functions are typed as first-class functions
    (:data:`FRICTION_TYPE`, :data:`ADVANCE_TYPE`): one machine code serves
    every law and is cached on disk. (Passed as plain numba dispatchers they
    would specialise the loop per law, and that specialisation is recompiled
    in every process: numba's cache does not match dispatcher types.)
    """
    vector = types.float64[::1]
    signature = types.none(types.float64[:, ::1], vector, vector, typeof(ControllerSettings(*(0.0,) * 7)),
                           types.int64, FRICTION_TYPE, ADVANCE_TYPE, vector, vector, types.int64, types.float64,
                           types.float64, types.float64, vector, vector, vector, vector)
    return njit(signature, cache=True)(position_loop)


def run_law(law: PlantLaw, max_step_s: float, reference, feedforward_A, disturbance_A,
            settings: ControllerSettings, periods: int) -> PlantTrace:
    """Run the position loop around a plant law and return the recorded trace.

    Parameters
    ----------
    law : PlantLaw
        The plant.
    max_step_s : float
        Largest internal step [s]; the step is also at most the law's
        ``stable_step_s`` and a :data:`STEPS_PER_PERIOD`-th of the controller period.
    reference : Reference
        Position reference.
    feedforward_A, disturbance_A : array_like, shape (n,)
        Feed-forward and disturbance current [A] at every reference sample.
    settings : ControllerSettings
        Discretised controller.
    periods : int
        Controller periods per reference sample.
    """
    stride = fine_stride(settings.period_s, min(max_step_s, law.stable_step_s, settings.period_s / STEPS_PER_PERIOD))
    n = len(reference)
    motion = np.ascontiguousarray(np.column_stack((reference.position, reference.velocity,
                                                   reference.acceleration)), dtype=float)
    trace = PlantTrace(np.empty(n), np.empty(n), np.empty(n), np.empty(n))
    compiled_position_loop()(
        motion, np.ascontiguousarray(feedforward_A, dtype=float), np.ascontiguousarray(disturbance_A, dtype=float),
        settings, int(periods), law.friction, law.advance, np.ascontiguousarray(law.parameters, dtype=float),
        np.ascontiguousarray(law.state, dtype=float), int(stride), float(settings.period_s / stride),
        float(law.inertia), float(law.offset), *trace)
    return trace


# ------------------------------------------------------------------ plants
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
        """Default truth plant of axis ``"X"``, ``"Y"`` or ``"C"`` (rotary, deg), named ``twin-X`` / ....

        Parameters
        ----------
        axis : str
            Axis of the synthetic machine, ``"X"``, ``"Y"`` or ``"C"`` (case and surrounding spaces ignored).
        friction : bool, default True
            With ``False`` the plant is the axis's inertia alone.
        """
        key = str(axis).strip().upper()
        suffix = "" if friction else " (no friction)"
        return cls(default_plant_parameters(key), friction=friction, name=f"twin-{key}{suffix}", axis=key)

    @property
    def inertia_A_s2_mm(self) -> float:
        """Inertia ``J`` [A s^2/mm], or [A s^2/deg] for a rotary axis."""
        return float(self.params.inertia_A_s2_mm)

    @property
    def motion(self) -> str:
        """``"linear"`` or ``"rotary"``: lengths of the loop in mm or deg."""
        return self.params.motion

    def plant_law(self) -> PlantLaw:
        """The truth plant's law (:func:`greybox.twin.plant.twin_plant_law`)."""
        return twin_plant_law(self.params, friction=self.friction)

    def describe(self) -> dict:
        """JSON-serialisable description."""
        return {"plant": self.name, "kind": "twin", "axis": self.axis, "friction": self.friction,
                "parameters": self.params.to_dict()}

    def run(self, reference, feedforward_A, disturbance_A, settings: ControllerSettings, periods: int
            ) -> PlantTrace:
        """Run the loop (see :func:`position_loop` for the arguments) and return the recorded trace.

        Parameters
        ----------
        reference : Reference
            Position reference [mm, or deg on a rotary axis]; the loop starts at rest at its first position.
        feedforward_A, disturbance_A : array_like, shape (n,)
            Feed-forward and disturbance current [A] at every reference sample.
        settings : ControllerSettings
            Discretised controller.
        periods : int
            Controller periods per reference sample.
        """
        return run_law(self.plant_law(), self.params.internal_step_s, reference, feedforward_A, disturbance_A,
                       settings, periods)


class ModelPlant:
    """A fitted current model as the plant of the loop, through its plant law.

    The model's inertia, friction law and offset (a constant load) make the
    plant ``J a = I - F - I_0`` (:meth:`~greybox.base.ModelProtocol.plant_law`);
    the law is integrated at an internal step small enough for its stiffness
    and damping on its inertia (at most ``max_step_s``).

    Parameters
    ----------
    model : CurrentModel
        Fitted model whose class offers a plant law (GMS, LuGre).
    name : str, optional
        Label; default the model kind.
    max_step_s : float, default 0.25e-3
        Largest internal step [s].

    Raises
    ------
    GreyboxError
        For a model without a plant law, an unfitted model, or a non-positive inertia.
    """

    def __init__(self, model, *, name: str | None = None, max_step_s: float = 0.25e-3):
        try:
            kind = model_kind(model)
        except KeyError:
            kind = type(model).__name__
        check_is_fitted(model)
        law = model.plant_law()
        if law is None:
            raise GreyboxError(f"a {kind} model cannot serve as the plant: it has no friction law at rest, where "
                               "a position loop spends its time; use twin-X, twin-Y or a gms or lugre model")
        if not (np.isfinite(law.inertia) and law.inertia > 0.0):
            raise GreyboxError(f"the {kind} model has inertia J = {law.inertia} A s^2/mm; a plant needs J > 0")
        self.model = model
        self.law = law
        self.kind = kind
        self.name = name or kind
        self.max_step_s = float(max_step_s)
        self.effort_unit = model.effort_unit_

    @property
    def inertia_A_s2_mm(self) -> float:
        """Inertia ``J`` [A s^2/mm] (or [N s^2/mm] for force models; per deg for a rotary axis)."""
        return float(self.law.inertia)

    @property
    def motion(self) -> str:
        """``"linear"`` or ``"rotary"``, the kind of axis the model was fitted on."""
        return self.model.units_.name

    def plant_law(self) -> PlantLaw:
        """The model's plant law."""
        return self.law

    def describe(self) -> dict:
        """JSON-serialisable description."""
        return {"plant": self.name, "kind": self.kind, "inertia": self.inertia_A_s2_mm,
                "effort_unit": self.effort_unit}

    def run(self, reference, feedforward_A, disturbance_A, settings: ControllerSettings, periods: int
            ) -> PlantTrace:
        """Run the loop (see :func:`position_loop` for the arguments) and return the recorded trace.

        Parameters
        ----------
        reference : Reference
            Position reference [mm, or deg on a rotary axis]; the loop starts at rest at its first position.
        feedforward_A, disturbance_A : array_like, shape (n,)
            Feed-forward and disturbance current [A] at every reference sample.
        settings : ControllerSettings
            Discretised controller.
        periods : int
            Controller periods per reference sample.
        """
        return run_law(self.law, self.max_step_s, reference, feedforward_A, disturbance_A, settings, periods)
