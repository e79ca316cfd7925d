"""Hidden effects that can be added to the synthetic axis current.

Each effect is a function ``effect(inputs, strength, **parameters)`` that
returns an extra current [A] from the true motion. ``strength`` [A] is the
amplitude of that current at the effect's reference condition (stated in each
docstring); the keyword parameters and their defaults are the documented knobs.
The current is added to the noise-free plant current and kept as the truth
channel ``truth_effect_A``.

:data:`EFFECTS` maps the effect names to the functions; the discovery
workflow uses the same names.
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import GreyboxError

__all__ = ["EffectInputs", "EFFECTS", "effect_current", "effect_parameters"]


@dataclass(frozen=True)
class EffectInputs:
    """True motion at the log samples, on which an effect acts.

    Parameters
    ----------
    time_s : ndarray
        Time since the start of the log [s].
    position_mm : ndarray
        True position [mm].
    velocity_mm_s : ndarray
        True velocity [mm/s].
    acceleration_mm_s2 : ndarray
        True acceleration [mm/s^2].
    travel_mm : tuple of float
        Ends [mm] of the axis travel.
    """

    time_s: np.ndarray
    position_mm: np.ndarray
    velocity_mm_s: np.ndarray
    acceleration_mm_s2: np.ndarray
    travel_mm: tuple[float, float]


def _direction(velocity_mm_s, velocity_scale_mm_s):
    return np.tanh(np.asarray(velocity_mm_s) / velocity_scale_mm_s)


def direction_asymmetry(inputs: EffectInputs, strength: float, velocity_scale_mm_s: float = 0.5) -> np.ndarray:
    """Extra friction in the positive direction only.

    ``strength * max(tanh(v / v_e), 0)``: ``strength`` [A] while moving in +x,
    nothing in -x; ``velocity_scale_mm_s`` (``v_e``) smooths the switch.
    """
    return strength * np.maximum(_direction(inputs.velocity_mm_s, velocity_scale_mm_s), 0.0)


def constant_offset(inputs: EffectInputs, strength: float) -> np.ndarray:
    """Constant current ``strength`` [A] (e.g. an unbalanced weight or a sensor offset)."""
    return np.full_like(inputs.time_s, float(strength))


def position_periodic_force(inputs: EffectInputs, strength: float, period_mm: float = 2.5,
                            phase_rad: float = 0.0) -> np.ndarray:
    """Cogging-like force, the same in both directions.

    ``strength * sin(2 pi x / period_mm + phase_rad)`` [A].
    """
    return strength * np.sin(2.0 * np.pi * inputs.position_mm / period_mm + phase_rad)


def position_periodic_friction(inputs: EffectInputs, strength: float, period_mm: float = 20.0,
                               phase_rad: float = 0.0, velocity_scale_mm_s: float = 0.5) -> np.ndarray:
    """Friction varying periodically with position; flips with the direction of motion.

    ``strength * sin(2 pi x / period_mm + phase_rad) * tanh(v / v_e)`` [A].
    """
    wave = np.sin(2.0 * np.pi * inputs.position_mm / period_mm + phase_rad)
    return strength * wave * _direction(inputs.velocity_mm_s, velocity_scale_mm_s)


def thermal_drift(inputs: EffectInputs, strength: float, time_constant_s: float = 60.0,
                  velocity_scale_mm_s: float = 0.5) -> np.ndarray:
    """Friction changing with the time since the start (warming lubricant).

    ``strength * (1 - exp(-t / time_constant_s)) * tanh(v / v_e)`` [A]:
    ``strength`` is the final change of the sliding friction (negative: friction falls).
    """
    growth = 1.0 - np.exp(-np.asarray(inputs.time_s) / time_constant_s)
    return strength * growth * _direction(inputs.velocity_mm_s, velocity_scale_mm_s)


def position_trend(inputs: EffectInputs, strength: float, same_sign: bool = False,
                   velocity_scale_mm_s: float = 0.5) -> np.ndarray:
    """Current rising linearly along the travel.

    ``strength * u(x) * tanh(v / v_e)`` [A] with ``u`` running from -1 at the
    lower to +1 at the upper end of the travel (a friction trend, e.g. a
    misaligned guideway). With ``same_sign=True`` the direction factor is
    dropped: a force trend, e.g. a cable carrier or telescopic cover.
    """
    low, high = inputs.travel_mm
    u = (2.0 * np.asarray(inputs.position_mm) - low - high) / (high - low)
    if same_sign:
        return strength * u
    return strength * u * _direction(inputs.velocity_mm_s, velocity_scale_mm_s)


def inertia_mismatch(inputs: EffectInputs, strength: float,
                     reference_acceleration_mm_s2: float = 1000.0) -> np.ndarray:
    """Inertia the nominal plant does not have (e.g. a workpiece on the table).

    ``strength * a / reference_acceleration_mm_s2`` [A].
    """
    return strength * np.asarray(inputs.acceleration_mm_s2) / reference_acceleration_mm_s2


def viscous_friction(inputs: EffectInputs, strength: float,
                     reference_velocity_mm_s: float = 2000.0 / 60.0) -> np.ndarray:
    """Extra viscous friction ``strength * v / reference_velocity_mm_s`` [A] (default reference 2000 mm/min)."""
    return strength * np.asarray(inputs.velocity_mm_s) / reference_velocity_mm_s


#: Hidden effects by name.
EFFECTS: dict[str, Callable[..., np.ndarray]] = {
    "direction_asymmetry": direction_asymmetry,
    "constant_offset": constant_offset,
    "position_periodic_force": position_periodic_force,
    "position_periodic_friction": position_periodic_friction,
    "thermal_drift": thermal_drift,
    "position_trend": position_trend,
    "inertia_mismatch": inertia_mismatch,
    "viscous_friction": viscous_friction,
}


def _lookup(name: str) -> Callable[..., np.ndarray]:
    if name not in EFFECTS:
        raise GreyboxError(f"unknown hidden effect {name!r}; choose from {', '.join(EFFECTS)}")
    return EFFECTS[name]


def effect_parameters(name: str) -> dict:
    """Keyword parameters of an effect and their defaults.

    Parameters
    ----------
    name : str
        Name of the effect, a key of :data:`EFFECTS`.

    Raises
    ------
    GreyboxError
        If the effect is unknown.
    """
    signature = inspect.signature(_lookup(name))
    return {p.name: p.default for p in list(signature.parameters.values())[2:]}


def effect_current(name: str, inputs: EffectInputs, strength: float, **parameters) -> np.ndarray:
    """Current [A] of the named effect.

    Parameters
    ----------
    name : str
        Name of the effect, a key of :data:`EFFECTS`.
    inputs : EffectInputs
        True motion at the log samples.
    strength : float
        Amplitude [A] of the effect at its reference condition.
    **parameters
        The effect's own keyword parameters (see :func:`effect_parameters`); omitted ones keep their defaults.

    Raises
    ------
    GreyboxError
        If the effect or one of the parameters is unknown.
    """
    function = _lookup(name)
    unknown = sorted(set(parameters) - set(effect_parameters(name)))
    if unknown:
        raise GreyboxError(
            f"effect {name!r} has no parameter {', '.join(unknown)}; its parameters: "
            f"{', '.join(effect_parameters(name)) or 'none besides strength'}")
    return np.asarray(function(inputs, float(strength), **parameters), dtype=float)
