r"""Dahl-type hysteresis: rate-independent friction that follows the position path.

.. math::

    \frac{dF}{dx} = \sigma_0 \left|1 - \frac{F}{F_c} s\right|^{\alpha}
    \operatorname{sign}\left(1 - \frac{F}{F_c} s\right), \qquad s = \operatorname{sign}(\dot x)

with Coulomb level :math:`F_c` [A], rest stiffness :math:`\sigma_0` [A/mm] and
shape exponent :math:`\alpha` [-]. There is no Stribeck weakening: the
friction depends on the path of the position, not on the speed. With
:math:`y = 1 - F s / F_c` (in :math:`[0, 2]`) the law reads
:math:`dy/d|x| = -k y^\alpha`, :math:`k = \sigma_0 / F_c`, whose exact solution
over a monotone step :math:`|\Delta x|` is

.. math::

    y = y_0 e^{-k |\Delta x|} \ (\alpha = 1), \qquad
    y = \max\left(0,\ y_0^{1-\alpha} - (1 - \alpha) k |\Delta x|\right)^{1/(1-\alpha)} \ (\alpha \ne 1),

used as the update (for :math:`\alpha < 1` the friction reaches :math:`F_c` after a finite travel).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from .base import TruthLaw, log_uniform

__all__ = ["DahlLaw", "dahl_update", "dahl_kernel"]


@njit(cache=True)
def dahl_update(force_A, step_mm, level_A, stiffness_A_mm, exponent):
    """Exact Dahl friction [A] after a monotone displacement.

    Parameters
    ----------
    force_A : float
        Friction before the displacement [A].
    step_mm : float
        Displacement [mm] (its sign is the direction of motion).
    level_A : float
        Coulomb level ``F_c`` [A].
    stiffness_A_mm : float
        Rest stiffness ``sigma_0`` [A/mm].
    exponent : float
        Shape ``alpha``.
    """
    if step_mm == 0.0:
        return force_A
    sign = 1.0 if step_mm > 0.0 else -1.0
    y = 1.0 - force_A * sign / level_A
    if y <= 0.0:
        return sign * level_A
    rate = stiffness_A_mm / level_A * abs(step_mm)
    if exponent == 1.0:
        y = y * math.exp(-rate)
    else:
        w = y ** (1.0 - exponent) - (1.0 - exponent) * rate
        y = w ** (1.0 / (1.0 - exponent)) if w > 0.0 else 0.0
    return sign * level_A * (1.0 - y)


@njit(cache=True)
def dahl_kernel(position_mm, stride, level_A, stiffness_A_mm, exponent):
    """Dahl friction [A] at every ``stride``-th point of a position path on a fine grid (0 at the start).

    Parameters
    ----------
    position_mm : ndarray, shape (n,)
        Position path [mm] on the fine grid.
    stride : int
        Fine steps per output sample.
    level_A, stiffness_A_mm, exponent : float
        ``F_c`` [A], ``sigma_0`` [A/mm] and ``alpha``, as in :func:`dahl_update`.

    Returns
    -------
    ndarray, shape ((n - 1) // stride + 1,)
    """
    n = position_mm.shape[0]
    out = np.empty((n - 1) // stride + 1)
    force = 0.0
    for i in range(n):
        if i > 0:
            force = dahl_update(force, position_mm[i] - position_mm[i - 1], level_A, stiffness_A_mm, exponent)
        if i % stride == 0:
            out[i // stride] = force
    return out


@dataclass(frozen=True)
class DahlLaw(TruthLaw):
    """Dahl-type rate-independent hysteresis friction.

    Parameters
    ----------
    level_A : float
        Coulomb level ``F_c`` [A].
    presliding_mm : float
        ``F_c / sigma_0`` [mm]: the travel over which the friction builds up after a reversal.
    exponent : float
        Shape ``alpha``.
    """

    level_A: float
    presliding_mm: float
    exponent: float

    name = "dahl"
    RANGES = {
        "level_A": (0.6, 1.6, "A", "uniform"),
        "presliding_mm": (1e-3, 2e-2, "mm", "log-uniform; F_c / sigma_0"),
        "exponent": (0.5, 2.0, "-", "uniform"),
    }

    @classmethod
    def draw(cls, rng: np.random.Generator) -> "DahlLaw":
        """A law with parameters drawn from :attr:`RANGES`.

        Parameters
        ----------
        rng : numpy.random.Generator
            Source of randomness.
        """
        r = cls.RANGES
        return cls(rng.uniform(*r["level_A"][:2]), log_uniform(rng, *r["presliding_mm"][:2]),
                   rng.uniform(*r["exponent"][:2]))

    @property
    def peak_friction_A(self) -> float:
        return float(self.level_A)

    def friction_samples(self, position_mm, velocity_mm_s, step_s, stride):
        """Dahl friction [A] at every ``stride``-th point of a motion (as :meth:`TruthLaw.friction_samples`).

        Parameters
        ----------
        position_mm : ndarray, shape (n,)
            Position [mm] on the fine grid.
        velocity_mm_s : ndarray, shape (n,)
            Velocity [mm/s] on the fine grid; not used, the law is rate-independent.
        step_s : float
            Fine integration step [s]; not used, the law follows the position path only.
        stride : int
            Fine steps per log sample.
        """
        return dahl_kernel(np.ascontiguousarray(position_mm, float), int(stride), float(self.level_A),
                           float(self.level_A / self.presliding_mm), float(self.exponent))
