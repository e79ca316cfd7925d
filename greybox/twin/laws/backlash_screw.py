r"""A preloaded ball screw whose table follows the motor through an axial play.

The logged position is the motor encoder's (a semi-closed loop) :math:`x`.
The screw's fixed bearing has an axial play of width :math:`b`: the table
position :math:`y` follows the motor only when the play is closed,

.. math::

    y \leftarrow \operatorname{clip}(y,\ x - b/2,\ x + b/2),

so after every reversal the motor travels :math:`b` while the table stands.
Two frictions act:

* the preloaded nut and the bearings turn with the motor: Dahl-type
  friction on :math:`x` (exponent 1, level :math:`F_n`, pre-sliding distance
  :math:`x_n`; :func:`~greybox.twin.laws.dahl.dahl_update`);
* the guideways carry the table: bristle friction with a Stribeck steady
  state on :math:`y` (:func:`~greybox.twin.laws.bristle.bristle_update`,
  without micro-damping), passed to the motor only while the play is closed.
  When it opens the guideway force relaxes to zero with the table at rest.

The table carries the share :math:`m` of the axis inertia; while the play is
open its inertia is not felt, and when the play closes on a moving motor the
table takes up the motor's velocity :math:`\Delta v` in a contact pulse of
duration :math:`T` (half-sine force of impulse :math:`m J \Delta v`, averaged over each fine step): the
current spike of a reversal through backlash.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..plant import stribeck_ratio
from .base import LawResponse, TruthLaw, log_uniform
from .bristle import bristle_update
from .dahl import dahl_update

__all__ = ["BacklashScrewLaw", "backlash_screw_kernel"]


@njit(cache=True)
def backlash_screw_kernel(position_mm, velocity_mm_s, acceleration_mm_s2, step_s, stride, play_mm, nut_A,
                          nut_presliding_mm, guide_static_A, guide_coulomb_ratio, guide_stribeck_mm_s, guide_shape,
                          guide_presliding_mm, table_inertia_A_s2_mm, pulse_s):
    """Friction and table inertia current [A] at every ``stride``-th point of a motor motion on a fine grid.

    Parameters
    ----------
    position_mm, velocity_mm_s, acceleration_mm_s2 : ndarray, shape (n,)
        Motor motion [mm, mm/s, mm/s^2] on the fine grid.
    step_s : float
        Step of the fine grid [s].
    stride : int
        Fine steps per output sample.
    play_mm : float
        Axial play ``b`` [mm]; the table starts centred in it.
    nut_A, nut_presliding_mm : float
        Level [A] and pre-sliding distance [mm] of the nut and bearing friction.
    guide_static_A, guide_coulomb_ratio, guide_stribeck_mm_s, guide_shape, guide_presliding_mm : float
        Guideway bristle law: static level [A], ``r_c``, ``v_s`` [mm/s], ``delta``, ``F_s / sigma_0`` [mm].
    table_inertia_A_s2_mm : float
        Inertia of the table [A s^2/mm].
    pulse_s : float
        Duration [s] of the contact pulse when the play closes.

    Returns
    -------
    friction, table_inertia : ndarray, shape ((n - 1) // stride + 1,)
    """
    n = position_mm.shape[0]
    m = (n - 1) // stride + 1
    friction = np.empty(m)
    table_inertia = np.empty(m)
    half = 0.5 * play_mm
    guide_stiffness = guide_static_A / guide_presliding_mm
    nut_stiffness = nut_A / nut_presliding_mm
    table = position_mm[0]
    nut = 0.0
    z = 0.0
    closed = False
    pulse_left = 0.0
    pulse_impulse = 0.0
    for i in range(n):
        x = position_mm[i]
        v = velocity_mm_s[i]
        if i > 0:
            nut = dahl_update(nut, x - position_mm[i - 1], nut_A, nut_stiffness, 1.0)
        previous = table
        if table < x - half:
            table = x - half
        elif table > x + half:
            table = x + half
        was_closed = closed
        closed = abs(x - table) >= half * (1.0 - 1e-9)
        if closed:
            steady = guide_static_A * stribeck_ratio(v, guide_coulomb_ratio, guide_stribeck_mm_s, guide_shape) \
                / guide_stiffness
            z = bristle_update(z, table - previous, steady)
            if not was_closed and i > 0:
                pulse_impulse = table_inertia_A_s2_mm * v
                pulse_left = pulse_s
        else:
            z = 0.0
        force = table_inertia_A_s2_mm * acceleration_mm_s2[i] if closed else 0.0
        if pulse_left > 0.0:  # the half-sine's mean over the step, so the steps carry the whole impulse
            elapsed = pulse_s - pulse_left
            end = min(elapsed + step_s, pulse_s)
            force += pulse_impulse * (math.cos(math.pi * elapsed / pulse_s) - math.cos(math.pi * end / pulse_s)) \
                / (2.0 * step_s)
            pulse_left -= step_s
        if i % stride == 0:
            friction[i // stride] = nut + (guide_stiffness * z if closed else 0.0)
            table_inertia[i // stride] = force
    return friction, table_inertia


@dataclass(frozen=True)
class BacklashScrewLaw(TruthLaw):
    """Preloaded screw (nut friction on the motor) with axial play before the table (guideway friction).

    Parameters
    ----------
    play_mm : float
        Axial play ``b`` [mm].
    nut_A : float
        Nut preload and bearing friction level [A].
    nut_presliding_mm : float
        Its pre-sliding distance [mm].
    guide_static_A : float
        Static level [A] of the guideway friction.
    guide_coulomb_ratio : float
        Its sliding level over the static level.
    guide_stribeck_mm_s : float
        Its Stribeck velocity [mm/s].
    guide_shape : float
        Its Stribeck exponent.
    guide_presliding_mm : float
        Its pre-sliding distance [mm].
    table_share : float
        Share of the axis inertia carried by the table (behind the play).
    pulse_s : float
        Duration [s] of the contact pulse when the play closes.
    """

    play_mm: float
    nut_A: float
    nut_presliding_mm: float
    guide_static_A: float
    guide_coulomb_ratio: float
    guide_stribeck_mm_s: float
    guide_shape: float
    guide_presliding_mm: float
    table_share: float
    pulse_s: float

    name = "backlash_screw"
    RANGES = {
        "play_mm": (2e-3, 2e-2, "mm", "log-uniform"),
        "nut_A": (0.2, 0.6, "A", "uniform"),
        "nut_presliding_mm": (1e-3, 5e-3, "mm", "log-uniform"),
        "guide_static_A": (0.4, 1.2, "A", "uniform"),
        "guide_coulomb_ratio": (0.55, 0.9, "-", "uniform"),
        "guide_stribeck_mm_s": (1.0, 10.0, "mm/s", "log-uniform"),
        "guide_shape": (1.0, 2.0, "-", "uniform"),
        "guide_presliding_mm": (5e-4, 5e-3, "mm", "log-uniform"),
        "table_share": (0.5, 0.85, "-", "uniform"),
        "pulse_s": (1e-3, 4e-3, "s", "uniform"),
    }

    @classmethod
    def draw(cls, rng: np.random.Generator) -> "BacklashScrewLaw":
        """A law with parameters drawn from :attr:`RANGES`.

        Parameters
        ----------
        rng : numpy.random.Generator
            Source of randomness.
        """
        r = cls.RANGES
        return cls(log_uniform(rng, *r["play_mm"][:2]), rng.uniform(*r["nut_A"][:2]),
                   log_uniform(rng, *r["nut_presliding_mm"][:2]), rng.uniform(*r["guide_static_A"][:2]),
                   rng.uniform(*r["guide_coulomb_ratio"][:2]), log_uniform(rng, *r["guide_stribeck_mm_s"][:2]),
                   rng.uniform(*r["guide_shape"][:2]), log_uniform(rng, *r["guide_presliding_mm"][:2]),
                   rng.uniform(*r["table_share"][:2]), rng.uniform(*r["pulse_s"][:2]))

    @property
    def peak_friction_A(self) -> float:
        return float(self.nut_A + self.guide_static_A)

    def _run(self, position_mm, velocity_mm_s, acceleration_mm_s2, step_s, stride, table_inertia):
        return backlash_screw_kernel(
            np.ascontiguousarray(position_mm, float), np.ascontiguousarray(velocity_mm_s, float),
            np.ascontiguousarray(acceleration_mm_s2, float), float(step_s), int(stride), float(self.play_mm),
            float(self.nut_A), float(self.nut_presliding_mm), float(self.guide_static_A),
            float(self.guide_coulomb_ratio), float(self.guide_stribeck_mm_s), float(self.guide_shape),
            float(self.guide_presliding_mm), float(table_inertia), float(self.pulse_s))

    def friction_samples(self, position_mm, velocity_mm_s, step_s, stride):
        """Nut and guideway friction [A] at every ``stride``-th fine point (as :meth:`TruthLaw.friction_samples`).

        Parameters
        ----------
        position_mm, velocity_mm_s : ndarray, shape (n,)
            Motor motion [mm, mm/s] on the fine grid.
        step_s : float
            Fine integration step [s]; it only times the contact pulse, which is inertia, so the friction
            does not depend on it.
        stride : int
            Fine steps per log sample.
        """
        # the friction does not depend on the acceleration; the table's inertia is left out here
        acceleration = np.zeros(np.shape(position_mm))
        return self._run(position_mm, velocity_mm_s, acceleration, step_s, stride, 0.0)[0]

    def respond(self, position_mm, velocity_mm_s, acceleration_mm_s2, step_s, stride, inertia_A_s2_mm):
        """Friction and inertial current [A] at the log samples (as :meth:`TruthLaw.respond`).

        The motor carries ``1 - table_share`` of the inertia at all times; the table's share is felt only
        while the play is closed, plus the contact pulse when it closes.

        Parameters
        ----------
        position_mm, velocity_mm_s, acceleration_mm_s2 : ndarray, shape (n,)
            Motor motion [mm, mm/s, mm/s^2] at fine steps ``step_s`` [s].
        step_s : float
            Fine integration step [s].
        stride : int
            Fine steps per log sample.
        inertia_A_s2_mm : float
            Inertia of the whole axis, motor and table [A s^2/mm].
        """
        friction, table = self._run(position_mm, velocity_mm_s, acceleration_mm_s2, step_s, stride,
                                    self.table_share * inertia_A_s2_mm)
        motor = (1.0 - self.table_share) * inertia_A_s2_mm * np.asarray(acceleration_mm_s2, float)[::stride]
        return LawResponse(friction, motor + table, np.clip(friction / self.peak_friction_A, -1.0, 1.0))
