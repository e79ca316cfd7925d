"""Truth plant of the synthetic feed axis: multi-element Maxwell-slip friction and inertia.

The plant is deliberately not one of the package's own friction models, so
that fitting those to its current is an honest test. Its friction, expressed
as motor current [A], is

    F(t) = g(x) * sum_i k_i d_i(t) + sigma_v * v(t)

with N elasto-plastic elements (N = 24 by default). Element i is a spring of
stiffness ``k_i`` [A/mm] whose deflection ``d_i`` [mm] follows the axis
displacement and is clamped at its breakaway deflection:

    d_i <- clip(d_i + dx, -D_i * r(t), +D_i * r(t)).

``D_i`` [mm] are spread logarithmically (1-50 um) and the breakaway currents
``k_i D_i`` follow a log-normal weighting over the elements. All breakaway
levels are weakened by a Stribeck ratio that follows the velocity through a
first-order lag of time constant ``tau`` (frictional lag):

    rho(v) = r_c + (1 - r_c) exp(-(|v| / v_s)^delta),   tau dr/dt = rho(v) - r.

The friction depends on the position along the screw through

    g(x) = 1 + c_pre u^4 + c_lead sin(2 pi x / lead + phi),
    u = (2 x - x_lo - x_hi) / (x_hi - x_lo),

a preload profile rising towards the ends of the travel and a weaker
component periodic with the screw lead. The motor current without noise is
``I = J a + F``.

The elements are integrated at a fine internal step (0.25 ms by default,
eight steps per 2 ms log sample) by a numba kernel; the clamp makes the update
unconditionally stable.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np
from numba import njit

from ..errors import GreyboxError
from .axes import axis_geometry

__all__ = [
    "PlantParameters",
    "default_plant_parameters",
    "maxwell_slip_kernel",
    "PlantResponse",
    "fine_steps_per_sample",
    "simulate_plant",
]


@dataclass(frozen=True)
class PlantParameters:
    """Parameters of the truth plant (friction and inertia in units of motor current).

    Parameters
    ----------
    breakaway_A : tuple of float
        Breakaway current [A] of each Maxwell-slip element at rest.
    breakaway_deflection_mm : tuple of float
        Deflection [mm] at which each element breaks away at rest.
    coulomb_ratio : float
        Sliding (Coulomb) level relative to the static level, ``r_c`` in (0, 1].
    stribeck_velocity_mm_s : float
        Stribeck velocity ``v_s`` [mm/s].
    stribeck_shape : float
        Exponent ``delta`` of the Stribeck curve.
    lag_time_s : float
        Time constant ``tau`` [s] of the frictional lag (0 for none).
    viscous_A_s_mm : float
        Viscous coefficient ``sigma_v`` [A s/mm].
    inertia_A_s2_mm : float
        Inertia ``J`` [A s^2/mm]: current per acceleration.
    travel_mm : tuple of float
        Ends [mm] of the screw travel that shape the preload profile.
    preload_gain : float
        ``c_pre``: relative friction increase at the travel ends.
    lead_mm : float
        Screw lead [mm], the period of the periodic friction component.
    lead_gain : float
        ``c_lead``: relative amplitude of the lead-periodic friction component.
    lead_phase_rad : float
        ``phi``: phase [rad] of the lead-periodic component.
    internal_step_s : float, default 0.25e-3
        Integration step [s]; must divide the log sample time.
    """

    breakaway_A: tuple
    breakaway_deflection_mm: tuple
    coulomb_ratio: float
    stribeck_velocity_mm_s: float
    stribeck_shape: float
    lag_time_s: float
    viscous_A_s_mm: float
    inertia_A_s2_mm: float
    travel_mm: tuple
    preload_gain: float
    lead_mm: float
    lead_gain: float
    lead_phase_rad: float
    internal_step_s: float = 0.25e-3

    def __post_init__(self):
        breakaway = np.asarray(self.breakaway_A, dtype=float)
        deflection = np.asarray(self.breakaway_deflection_mm, dtype=float)
        if breakaway.shape != deflection.shape or breakaway.ndim != 1 or breakaway.size == 0:
            raise GreyboxError("plant: breakaway_A and breakaway_deflection_mm need the same, non-zero length")
        if np.any(breakaway <= 0) or np.any(deflection <= 0):
            raise GreyboxError("plant: breakaway currents and deflections must be positive")
        if not 0.0 < self.coulomb_ratio <= 1.0:
            raise GreyboxError(f"plant: coulomb_ratio must be in (0, 1], got {self.coulomb_ratio}")
        if self.stribeck_velocity_mm_s <= 0 or self.stribeck_shape <= 0 or self.lag_time_s < 0:
            raise GreyboxError("plant: Stribeck velocity and shape must be positive, lag time non-negative")
        if self.internal_step_s <= 0 or self.travel_mm[1] <= self.travel_mm[0] or self.lead_mm <= 0:
            raise GreyboxError("plant: internal step, travel length and lead must be positive")

    # ---------------------------------------------------------- derived
    @property
    def stiffness_A_mm(self) -> np.ndarray:
        """Element stiffnesses ``k_i`` [A/mm]."""
        return np.asarray(self.breakaway_A, float) / np.asarray(self.breakaway_deflection_mm, float)

    @property
    def static_friction_A(self) -> float:
        """Breakaway current of the whole plant at rest, before the position factor [A]."""
        return float(np.sum(self.breakaway_A))

    def stribeck_ratio(self, velocity_mm_s) -> np.ndarray:
        """Steady Stribeck ratio ``rho(v)`` of the breakaway levels (1 at rest)."""
        speed = np.abs(np.asarray(velocity_mm_s, dtype=float))
        r = self.coulomb_ratio
        return r + (1.0 - r) * np.exp(-((speed / self.stribeck_velocity_mm_s) ** self.stribeck_shape))

    def position_factor(self, position_mm) -> np.ndarray:
        """Position factor ``g(x)`` of the Maxwell-slip friction (dimensionless)."""
        x = np.asarray(position_mm, dtype=float)
        low, high = self.travel_mm
        u = (2.0 * x - low - high) / (high - low)
        lead = np.sin(2.0 * np.pi * x / self.lead_mm + self.lead_phase_rad)
        return 1.0 + self.preload_gain * u**4 + self.lead_gain * lead

    def steady_friction(self, velocity_mm_s, position_mm) -> np.ndarray:
        """Friction current [A] in steady sliding at constant velocity [mm/s] and position [mm]."""
        v = np.asarray(velocity_mm_s, dtype=float)
        coulomb = self.static_friction_A * self.stribeck_ratio(v) * np.sign(v)
        return self.position_factor(position_mm) * coulomb + self.viscous_A_s_mm * v

    def to_dict(self) -> dict:
        """JSON-serialisable parameter dictionary."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()}

    def replace(self, **changes) -> "PlantParameters":
        """Return a copy with some parameters replaced."""
        return replace(self, **changes)


def _element_distribution(static_A: float, n: int = 24, smallest_mm: float = 1e-3, largest_mm: float = 5e-2,
                          typical_mm: float = 8e-3, spread: float = 1.0):
    deflection = np.geomspace(smallest_mm, largest_mm, n)
    weight = np.exp(-0.5 * (np.log(deflection / typical_mm) / spread) ** 2)
    breakaway = static_A * weight / weight.sum()
    return tuple(float(b) for b in breakaway), tuple(float(d) for d in deflection)


def default_plant_parameters(axis: str = "X", travel_mm=None) -> PlantParameters:
    """Default truth plant of an axis of the synthetic machine.

    Magnitudes follow the axes of Rüppel et al. (2024): about 1 A of friction
    current in sliding, a few tenths of an ampere of inertial current at
    1 m/s^2. Y carries more mass than X and has a longer screw.

    Parameters
    ----------
    axis : {"X", "Y"}
        Axis name.
    travel_mm : tuple of float, optional
        Travel [mm] for the preload profile; default the axis' travel.
    """
    geometry = axis_geometry(axis)
    travel = tuple(travel_mm) if travel_mm is not None else geometry.travel_mm
    if geometry.name == "X":
        static, coulomb_ratio, viscous, inertia, phase = 1.25, 0.72, 0.006, 2.8e-4, 0.4
    else:
        static, coulomb_ratio, viscous, inertia, phase = 1.45, 0.70, 0.007, 4.2e-4, 1.9
    breakaway, deflection = _element_distribution(static)
    return PlantParameters(
        breakaway_A=breakaway,
        breakaway_deflection_mm=deflection,
        coulomb_ratio=coulomb_ratio,
        stribeck_velocity_mm_s=3.0,
        stribeck_shape=2.0,
        lag_time_s=0.015,
        viscous_A_s_mm=viscous,
        inertia_A_s2_mm=inertia,
        travel_mm=travel,
        preload_gain=0.35,
        lead_mm=10.0,
        lead_gain=0.04,
        lead_phase_rad=phase,
    )


@njit(cache=True)
def maxwell_slip_kernel(position_mm, velocity_mm_s, step_s, stride, stiffness_A_mm, deflection_mm,
                        coulomb_ratio, stribeck_velocity_mm_s, stribeck_shape, lag_time_s):
    """Sum of the elasto-plastic element currents [A] at every ``stride``-th fine step.

    Parameters
    ----------
    position_mm, velocity_mm_s : ndarray, shape (n,)
        Motion on the fine grid of step ``step_s`` [s].
    step_s : float
        Fine integration step [s].
    stride : int
        Number of fine steps per output sample.
    stiffness_A_mm, deflection_mm : ndarray, shape (m,)
        Element stiffnesses [A/mm] and breakaway deflections at rest [mm].
    coulomb_ratio, stribeck_velocity_mm_s, stribeck_shape : float
        Stribeck ratio ``r_c + (1 - r_c) exp(-(|v|/v_s)^delta)``.
    lag_time_s : float
        Time constant [s] of the lagged Stribeck ratio (0: no lag).

    Returns
    -------
    ndarray, shape ((n - 1) // stride + 1,)
        Maxwell-slip current [A] at fine steps 0, stride, 2 stride, ...
    """
    n = position_mm.shape[0]
    m = stiffness_A_mm.shape[0]
    out = np.empty((n - 1) // stride + 1)
    state = np.zeros(m)
    decay = math.exp(-step_s / lag_time_s) if lag_time_s > 0.0 else 0.0
    level = coulomb_ratio + (1.0 - coulomb_ratio) * math.exp(
        -((abs(velocity_mm_s[0]) / stribeck_velocity_mm_s) ** stribeck_shape))
    for i in range(n):
        step = 0.0
        if i > 0:
            target = coulomb_ratio + (1.0 - coulomb_ratio) * math.exp(
                -((abs(velocity_mm_s[i]) / stribeck_velocity_mm_s) ** stribeck_shape))
            level = target + (level - target) * decay
            step = position_mm[i] - position_mm[i - 1]
        force = 0.0
        for j in range(m):
            limit = deflection_mm[j] * level
            d = state[j] + step
            if d > limit:
                d = limit
            elif d < -limit:
                d = -limit
            state[j] = d
            force += stiffness_A_mm[j] * d
        if i % stride == 0:
            out[i // stride] = force
    return out


@dataclass(frozen=True)
class PlantResponse:
    """True motion and noise-free current components at the log samples.

    Parameters
    ----------
    position_mm, velocity_mm_s, acceleration_mm_s2 : ndarray
        True motion [mm, mm/s, mm/s^2].
    friction_A, inertia_A : ndarray
        Friction and inertia current [A].
    """

    position_mm: np.ndarray
    velocity_mm_s: np.ndarray
    acceleration_mm_s2: np.ndarray
    friction_A: np.ndarray
    inertia_A: np.ndarray

    @property
    def current_A(self) -> np.ndarray:
        """Inertia plus friction current [A]."""
        return self.friction_A + self.inertia_A


def fine_steps_per_sample(params: PlantParameters, sample_time_s: float) -> int:
    """Number of internal steps per log sample; raises if the step does not divide the sample time."""
    ratio = sample_time_s / params.internal_step_s
    stride = int(round(ratio))
    if stride < 1 or abs(ratio - stride) > 1e-9 * ratio:
        raise GreyboxError(
            f"plant: internal step {params.internal_step_s} s must divide the sample time {sample_time_s} s")
    return stride


def simulate_plant(params: PlantParameters, motion, n_samples: int, sample_time_s: float = 0.002) -> PlantResponse:
    """Integrate the plant along a motion and return motion and current at the log samples.

    Parameters
    ----------
    params : PlantParameters
        The plant.
    motion : object
        Has ``evaluate(time_s) -> (x_mm, v_mm_s, a_mm_s2)``.
    n_samples : int
        Number of log samples, at times ``k * sample_time_s``.
    sample_time_s : float, default 0.002
        Log sample time [s].
    """
    stride = fine_steps_per_sample(params, sample_time_s)
    fine_time = np.arange((n_samples - 1) * stride + 1) * params.internal_step_s
    x, v, a = motion.evaluate(fine_time)
    maxwell = maxwell_slip_kernel(
        x, v, params.internal_step_s, stride, params.stiffness_A_mm,
        np.asarray(params.breakaway_deflection_mm, float), params.coulomb_ratio,
        params.stribeck_velocity_mm_s, params.stribeck_shape, params.lag_time_s)
    x_log, v_log, a_log = x[::stride], v[::stride], a[::stride]
    friction = params.position_factor(x_log) * maxwell + params.viscous_A_s_mm * v_log
    return PlantResponse(x_log, v_log, a_log, friction, params.inertia_A_s2_mm * a_log)
