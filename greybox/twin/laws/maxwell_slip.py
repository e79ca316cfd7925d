"""The twin's own law with random parameters: many elasto-plastic Maxwell-slip elements.

``F = sum_i k_i d_i`` with ``d_i <- clip(d_i + dx, -D_i r, D_i r)`` and the
breakaway levels weakened by a lagged Stribeck ratio ``r`` (see
:mod:`greybox.twin.plant`, whose compiled kernel this law runs).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..plant import _element_distribution, maxwell_slip_kernel
from .base import TruthLaw, log_uniform

__all__ = ["MaxwellSlipLaw"]


@dataclass(frozen=True)
class MaxwellSlipLaw(TruthLaw):
    """Maxwell-slip friction with a lagged Stribeck weakening.

    Parameters
    ----------
    breakaway_A : tuple of float
        Breakaway current [A] of each element at rest.
    breakaway_deflection_mm : tuple of float
        Deflection [mm] at which each element breaks away at rest.
    coulomb_ratio : float
        Sliding level over the level at rest, ``r_c``.
    stribeck_velocity_mm_s : float
        ``v_s`` [mm/s].
    stribeck_shape : float
        ``delta``.
    lag_time_s : float
        Time constant [s] of the frictional lag (0: none).
    """

    breakaway_A: tuple
    breakaway_deflection_mm: tuple
    coulomb_ratio: float
    stribeck_velocity_mm_s: float
    stribeck_shape: float
    lag_time_s: float

    name = "maxwell_slip"
    RANGES = {
        "static_A": (0.7, 1.8, "A", "uniform; breakaway current of all elements at rest"),
        "elements": (8, 32, "-", "integer, uniform"),
        "typical_deflection_mm": (3e-4, 3e-3, "mm", "log-uniform; centre of the log-normal element weights"),
        "deflection_spread": (0.7, 1.5, "-", "uniform; width of the weights in log deflection"),
        "coulomb_ratio": (0.6, 0.95, "-", "uniform"),
        "stribeck_velocity_mm_s": (1.0, 10.0, "mm/s", "log-uniform"),
        "stribeck_shape": (0.5, 2.0, "-", "uniform"),
        "lag_time_s": (0.0, 0.03, "s", "uniform"),
    }

    @classmethod
    def draw(cls, rng: np.random.Generator) -> "MaxwellSlipLaw":
        """A law with parameters drawn from :attr:`RANGES`; element deflections log-spaced from 0.1 to 10 um.

        Parameters
        ----------
        rng : numpy.random.Generator
            Source of randomness.
        """
        r = cls.RANGES
        breakaway, deflection = _element_distribution(
            rng.uniform(*r["static_A"][:2]), n=int(rng.integers(r["elements"][0], r["elements"][1] + 1)),
            smallest_mm=1e-4, largest_mm=1e-2, typical_mm=log_uniform(rng, *r["typical_deflection_mm"][:2]),
            spread=rng.uniform(*r["deflection_spread"][:2]))
        return cls(breakaway, deflection, rng.uniform(*r["coulomb_ratio"][:2]),
                   log_uniform(rng, *r["stribeck_velocity_mm_s"][:2]), rng.uniform(*r["stribeck_shape"][:2]),
                   rng.uniform(*r["lag_time_s"][:2]))

    @property
    def peak_friction_A(self) -> float:
        return float(np.sum(self.breakaway_A))

    def friction_samples(self, position_mm, velocity_mm_s, step_s, stride):
        """Maxwell-slip friction [A] at every ``stride``-th point of a motion (as :meth:`TruthLaw.friction_samples`).

        Parameters
        ----------
        position_mm, velocity_mm_s : ndarray, shape (n,)
            Motion [mm, mm/s] on the fine grid; the elements start relaxed.
        step_s : float
            Fine integration step [s]; sets the decay of the lagged Stribeck ratio.
        stride : int
            Fine steps per log sample.
        """
        deflection = np.asarray(self.breakaway_deflection_mm, float)
        stiffness = np.asarray(self.breakaway_A, float) / deflection
        return maxwell_slip_kernel(np.ascontiguousarray(position_mm, float), np.ascontiguousarray(velocity_mm_s, float),
                                   float(step_s), int(stride), stiffness, deflection, float(self.coulomb_ratio),
                                   float(self.stribeck_velocity_mm_s), float(self.stribeck_shape),
                                   float(self.lag_time_s))
