r"""LuGre-type bristle friction: one elastic bristle state with a Stribeck steady state.

.. math::

    \frac{dz}{dt} = v - \frac{|v|}{g(v)} z, \qquad
    g(v) = \frac{F_s}{\sigma_0}\left(r_c + (1 - r_c) e^{-(|v|/v_s)^\delta}\right), \qquad
    F = \sigma_0 z + \sigma_1 \frac{dz}{dt}

with bristle stiffness :math:`\sigma_0` [A/mm], micro-damping :math:`\sigma_1`
[A s/mm] and static level :math:`F_s` [A]. The state is advanced exactly
over each fine step on which the displacement :math:`\Delta x` and the
steady deflection :math:`g` are held: along :math:`|x|` the equation is linear,

.. math::

    z \leftarrow s\,g + (z - s\,g)\, e^{-|\Delta x| / g}, \qquad s = \operatorname{sign}(\Delta x),

so the update is stable at any step, unlike forward Euler, whose step would
have to stay below :math:`g / |v|` (a fraction of a millisecond at feed speed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..plant import stribeck_ratio
from .base import TruthLaw, log_uniform

__all__ = ["BristleLaw", "bristle_update", "bristle_kernel"]


@njit(cache=True)
def bristle_update(state_mm, step_mm, steady_mm):
    """Exact bristle deflection [mm] after a displacement, the steady deflection held constant over it.

    Parameters
    ----------
    state_mm : float
        Bristle deflection before the displacement [mm].
    step_mm : float
        Displacement [mm] (its sign is the direction of motion).
    steady_mm : float
        Steady-state deflection at the current speed [mm], positive.
    """
    if step_mm == 0.0:
        return state_mm
    target = steady_mm if step_mm > 0.0 else -steady_mm
    return target + (state_mm - target) * math.exp(-abs(step_mm) / steady_mm)


@njit(cache=True)
def bristle_kernel(position_mm, velocity_mm_s, stride, stiffness_A_mm, damping_A_s_mm, static_A, coulomb_ratio,
                   stribeck_velocity_mm_s, stribeck_shape):
    """Bristle friction [A] at every ``stride``-th point of a motion on a fine grid (state 0 at the start).

    Parameters
    ----------
    position_mm, velocity_mm_s : ndarray, shape (n,)
        Motion [mm, mm/s] on the fine grid.
    stride : int
        Fine steps per output sample.
    stiffness_A_mm, damping_A_s_mm : float
        ``sigma_0`` [A/mm] and ``sigma_1`` [A s/mm].
    static_A, coulomb_ratio, stribeck_velocity_mm_s, stribeck_shape : float
        ``F_s`` [A], ``r_c``, ``v_s`` [mm/s] and ``delta`` of the steady state.
    """
    n = position_mm.shape[0]
    out = np.empty((n - 1) // stride + 1)
    z = 0.0
    for i in range(n):
        v = velocity_mm_s[i]
        steady = static_A * stribeck_ratio(v, coulomb_ratio, stribeck_velocity_mm_s, stribeck_shape) / stiffness_A_mm
        if i > 0:
            z = bristle_update(z, position_mm[i] - position_mm[i - 1], steady)
        if i % stride == 0:
            out[i // stride] = stiffness_A_mm * z + damping_A_s_mm * (v - abs(v) * z / steady)
    return out


@dataclass(frozen=True)
class BristleLaw(TruthLaw):
    """LuGre-type bristle friction with a Stribeck steady state.

    Parameters
    ----------
    static_A : float
        Static level ``F_s`` [A].
    coulomb_ratio : float
        Sliding level over the static level, ``r_c``.
    stribeck_velocity_mm_s : float
        ``v_s`` [mm/s].
    stribeck_shape : float
        ``delta``.
    presliding_mm : float
        Pre-sliding distance ``F_s / sigma_0`` [mm].
    damping_A_s_mm : float
        Micro-damping ``sigma_1`` [A s/mm].
    """

    static_A: float
    coulomb_ratio: float
    stribeck_velocity_mm_s: float
    stribeck_shape: float
    presliding_mm: float
    damping_A_s_mm: float

    name = "lugre_bristle"
    RANGES = {
        "static_A": (0.7, 1.8, "A", "uniform"),
        "coulomb_ratio": (0.6, 0.95, "-", "uniform"),
        "stribeck_velocity_mm_s": (1.0, 10.0, "mm/s", "log-uniform"),
        "stribeck_shape": (0.5, 2.0, "-", "uniform"),
        "presliding_mm": (5e-4, 1e-2, "mm", "log-uniform; F_s / sigma_0"),
        "damping_A_s_mm": (1e-3, 3e-2, "A s/mm", "log-uniform"),
    }

    @classmethod
    def draw(cls, rng: np.random.Generator) -> "BristleLaw":
        """A law with parameters drawn from :attr:`RANGES`.

        Parameters
        ----------
        rng : numpy.random.Generator
            Source of randomness.
        """
        r = cls.RANGES
        return cls(rng.uniform(*r["static_A"][:2]), rng.uniform(*r["coulomb_ratio"][:2]),
                   log_uniform(rng, *r["stribeck_velocity_mm_s"][:2]), rng.uniform(*r["stribeck_shape"][:2]),
                   log_uniform(rng, *r["presliding_mm"][:2]), log_uniform(rng, *r["damping_A_s_mm"][:2]))

    @property
    def stiffness_A_mm(self) -> float:
        """Bristle stiffness ``sigma_0`` [A/mm]."""
        return self.static_A / self.presliding_mm

    @property
    def peak_friction_A(self) -> float:
        return float(self.static_A)

    def friction_samples(self, position_mm, velocity_mm_s, step_s, stride):
        """Bristle friction [A] at every ``stride``-th point of a motion (as :meth:`TruthLaw.friction_samples`).

        Parameters
        ----------
        position_mm, velocity_mm_s : ndarray, shape (n,)
            Motion [mm, mm/s] on the fine grid.
        step_s : float
            Fine integration step [s]; not used: the state update is exact in the displacement.
        stride : int
            Fine steps per log sample.
        """
        return bristle_kernel(np.ascontiguousarray(position_mm, float), np.ascontiguousarray(velocity_mm_s, float),
                              int(stride), float(self.stiffness_A_mm), float(self.damping_A_s_mm),
                              float(self.static_A), float(self.coulomb_ratio), float(self.stribeck_velocity_mm_s),
                              float(self.stribeck_shape))
