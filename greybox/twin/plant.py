"""Truth plant of the synthetic feed axis: multi-element Maxwell-slip friction and inertia.

The plant is deliberately not one of the package's own friction models, so
that fitting those to its current is an honest test. Its friction, expressed
as motor current [A], is

    F(t) = g(x) * sum_i k_i d_i(t) + sigma_v * v(t)

with N elasto-plastic elements (N = 24 by default). Element i is a spring of
stiffness ``k_i`` [A/mm] whose deflection ``d_i`` [mm] follows the axis
displacement and is clamped at its breakaway deflection:

    d_i <- clip(d_i + dx, -D_i * r(t), +D_i * r(t)).

``D_i`` [mm] are spread logarithmically (0.1-5 um) and the breakaway currents
``k_i D_i`` follow a log-normal weighting over the elements. All breakaway
levels are weakened by a Stribeck ratio that follows the velocity through a
first-order lag of time constant ``tau`` (frictional lag)::

    rho(v) = r_c + (1 - r_c) exp(-(|v| / v_s)^delta),   tau dr/dt = rho(v) - r.

The friction depends on the position along the screw through

    g(x) = 1 + c_pre u^4 + c_tilt u + c_lead sin(2 pi x / lead + phi),
    u = (2 x - x_lo - x_hi) / (x_hi - x_lo),

a preload profile rising towards the ends of the travel, a trend along the
whole travel and a weaker component periodic with the screw lead. The motor
current without noise is ``I = J a + F + R``, with the current ``R`` that
balances the motor's cogging torque, periodic in the motor angle:

    R(x) = a_cog sin(2 pi x / lambda_cog + phi_cog),

``lambda_cog`` [mm] the table travel of one cogging period (screw lead over
motor pole pairs over the order of the cogging harmonic).

The elements are integrated at a fine internal step (0.25 ms by default,
eight steps per 2 ms log sample) by a numba kernel; the clamp makes the update
unconditionally stable. The Stribeck ratio, its lag and the element update
are compiled once (:func:`stribeck_ratio`, :func:`lagged_stribeck_ratio`,
:func:`maxwell_slip_update`) and shared by the prescribed-motion kernel
:func:`maxwell_slip_kernel` and the plant law of a position loop
(:func:`twin_plant_law`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np
from numba import njit

from ..base import PlantLaw
from ..data.axis_config import AxisConfig
from ..errors import GreyboxError
from .axes import axis_geometry
from .drive import AXIS_EFFICIENCIES, WORM_EFFICIENCIES, drive_config

__all__ = [
    "PlantParameters",
    "default_plant_parameters",
    "position_factor_at",
    "cogging_current_at",
    "stribeck_ratio",
    "lag_decay",
    "lagged_stribeck_ratio",
    "maxwell_slip_update",
    "maxwell_slip_kernel",
    "twin_plant_law",
    "twin_plant_friction",
    "twin_plant_advance",
    "PlantResponse",
    "fine_steps_per_sample",
    "fine_motion",
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
    tilt_gain : float, default 0.0
        ``c_tilt``: relative friction change from the middle to the upper end of the travel (linear in ``u``).
    cogging_A : float, default 0.0
        ``a_cog``: amplitude [A] of the current that balances the motor's cogging torque.
    cogging_period_mm : float, default 10 / 24
        ``lambda_cog``: table travel [mm] of one cogging period (10 mm lead, 4 pole pairs, 6th harmonic).
    cogging_phase_rad : float, default 0.0
        ``phi_cog``: phase [rad] of the cogging current.
    motion : {"linear", "rotary"}, default "linear"
        Kind of axis. The plant's lengths of a rotary axis are in deg (``travel_mm``, ``lead_mm``: the
        table's turn per worm revolution, deflections, ``A/mm`` as ``A/deg``); its axis file gives a torque.
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
    tilt_gain: float = 0.0
    cogging_A: float = 0.0
    cogging_period_mm: float = 10.0 / 24.0
    cogging_phase_rad: float = 0.0
    motion: str = "linear"

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
        if abs(self.tilt_gain) + abs(self.lead_gain) >= 1.0:
            raise GreyboxError("plant: |tilt_gain| + |lead_gain| must stay below 1 (friction keeps its sign)")
        if self.cogging_A < 0 or self.cogging_period_mm <= 0:
            raise GreyboxError("plant: cogging amplitude must be non-negative and its period positive")

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
        """Steady Stribeck ratio ``rho(v)`` of the breakaway levels (1 at rest), at velocities [mm/s].

        Parameters
        ----------
        velocity_mm_s : float or array_like
            Velocity [mm/s]; the ratio has its shape (a float for a scalar).
        """
        velocity = np.asarray(velocity_mm_s, dtype=float)
        flat = np.ascontiguousarray(velocity.ravel())
        ratio = _stribeck_ratios(flat, float(self.coulomb_ratio), float(self.stribeck_velocity_mm_s),
                                 float(self.stribeck_shape))
        return ratio.reshape(velocity.shape)[()]

    def _position_terms(self, position_mm):
        """Position factor ``g(x)`` and cogging current [A] at ``position_mm`` [mm], in one pass."""
        x = np.asarray(position_mm, dtype=float)
        factor, cogging = _position_term_arrays(np.ascontiguousarray(x.ravel()), *self._position_head())
        return factor.reshape(x.shape)[()], cogging.reshape(x.shape)[()]

    def _position_head(self) -> tuple:
        """``(x_lo, x_hi, c_pre, c_tilt, lead, c_lead, phi, a_cog, lambda_cog, phi_cog)`` as floats."""
        return (float(self.travel_mm[0]), float(self.travel_mm[1]), float(self.preload_gain), float(self.tilt_gain),
                float(self.lead_mm), float(self.lead_gain), float(self.lead_phase_rad), float(self.cogging_A),
                float(self.cogging_period_mm), float(self.cogging_phase_rad))

    def axis_config(self, name: str = "") -> AxisConfig:
        """The axis file of this axis: the twin's motor, this lead, the X and Y axes' (or the C axis's) efficiencies.

        Parameters
        ----------
        name : str, default ""
            Axis name written into the axis file.
        """
        efficiencies = WORM_EFFICIENCIES if self.motion == "rotary" else AXIS_EFFICIENCIES
        return drive_config(self.lead_mm, efficiencies, name, self.motion)

    def process_load(self, process_A, velocity_mm_s) -> np.ndarray:
        """Process force [N] on the table (torque [Nm] on a rotary axis) behind a process current [A] (losses
        booked in the current).

        Parameters
        ----------
        process_A : array_like
            Process current [A].
        velocity_mm_s : array_like
            Axis velocity [mm/s, deg/s on a rotary axis]; its sign against the current's tells driving from
            back-driving, which sets the efficiency used.
        """
        return self.axis_config().process_load(process_A, velocity_mm_s)

    def position_factor(self, position_mm) -> np.ndarray:
        """Position factor ``g(x)`` of the Maxwell-slip friction (dimensionless; :func:`position_factor_at`).

        Parameters
        ----------
        position_mm : float or array_like
            Position [mm]; the factor has its shape.
        """
        return self._position_terms(position_mm)[0]

    def cogging_current(self, position_mm) -> np.ndarray:
        """Current [A] balancing the motor's cogging torque (:func:`cogging_current_at`).

        Parameters
        ----------
        position_mm : float or array_like
            Position [mm]; the current has its shape.
        """
        return self._position_terms(position_mm)[1]

    def steady_friction(self, velocity_mm_s, position_mm) -> np.ndarray:
        """Friction current [A] in steady sliding at constant velocity [mm/s] and position [mm].

        Parameters
        ----------
        velocity_mm_s : float or array_like
            Constant velocity [mm/s]; the friction is 0 at rest.
        position_mm : float or array_like
            Position [mm], broadcast against the velocity.
        """
        v = np.asarray(velocity_mm_s, dtype=float)
        coulomb = self.static_friction_A * self.stribeck_ratio(v) * np.sign(v)
        return self.position_factor(position_mm) * coulomb + self.viscous_A_s_mm * v

    def simulate(self, motion, n_samples: int, sample_time_s: float = 0.002) -> "PlantResponse":
        """Motion and current at the log samples along ``motion`` (:func:`simulate_plant`).

        Parameters
        ----------
        motion : object
            Has ``evaluate(time_s) -> (x_mm, v_mm_s, a_mm_s2)``.
        n_samples : int
            Number of log samples, at times ``k * sample_time_s``.
        sample_time_s : float, default 0.002
            Log sample time [s]; a whole multiple of ``internal_step_s``.
        """
        return simulate_plant(self, motion, n_samples, sample_time_s)

    def to_dict(self) -> dict:
        """JSON-serialisable parameter dictionary."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()}

    def replace(self, **changes) -> "PlantParameters":
        """Return a copy with some parameters replaced."""
        return replace(self, **changes)


def _element_distribution(static_A: float, n: int = 24, smallest_mm: float = 1e-4, largest_mm: float = 5e-3,
                          typical_mm: float = 7e-4, spread: float = 1.0):
    deflection = np.geomspace(smallest_mm, largest_mm, n)
    weight = np.exp(-0.5 * (np.log(deflection / typical_mm) / spread) ** 2)
    breakaway = static_A * weight / weight.sum()
    return tuple(float(b) for b in breakaway), tuple(float(d) for d in deflection)


def default_plant_parameters(axis: str = "X", travel_mm=None) -> PlantParameters:
    """Default truth plant of an axis of the synthetic machine.

    Magnitudes follow the axes of Rüppel et al. (2024): about 1.1 A (X) and
    1.3 A (Y) of friction current in sliding, a few tenths of an ampere of
    inertial current at 1 m/s^2. Y carries more mass than X and has a longer
    screw whose friction changes strongly along the travel (the paper's Y
    axis has the larger position effect). The values are calibrated so that
    the paper's experiments show the pattern of its Tables 3 and 4 (see
    docs/synthetic-axis.md, 'Calibration against the paper').

    The rotary table C (not in the paper) turns through a worm gear of ratio
    90 (4 deg per worm revolution, the period of its position-periodic
    friction), with less friction and inertia per degree than X per mm, a
    weak variation of the worm's preload over the turn and the motor's
    cogging at 4/24 deg; its lengths are in deg.

    Parameters
    ----------
    axis : {"X", "Y", "C"}
        Axis name.
    travel_mm : tuple of float, optional
        Travel [mm] for the preload profile; default the axis' travel.
    """
    geometry = axis_geometry(axis)
    travel = tuple(travel_mm) if travel_mm is not None else geometry.travel_mm
    lead = 10.0
    if geometry.name == "X":
        static, viscous, inertia, phase, preload, tilt = 1.25, 0.006, 2.8e-4, 0.4, 0.2, 0.05
    elif geometry.name == "Y":
        static, viscous, inertia, phase, preload, tilt = 1.45, 0.007, 4.2e-4, 1.9, 0.35, 0.7
    else:
        static, viscous, inertia, phase, preload, tilt = 0.9, 0.004, 1.5e-4, 1.0, 0.05, 0.1
        lead = 4.0
    breakaway, deflection = _element_distribution(static)
    return PlantParameters(
        breakaway_A=breakaway,
        breakaway_deflection_mm=deflection,
        coulomb_ratio=0.9,
        stribeck_velocity_mm_s=3.0,
        stribeck_shape=2.0,
        lag_time_s=0.015,
        viscous_A_s_mm=viscous,
        inertia_A_s2_mm=inertia,
        travel_mm=travel,
        preload_gain=preload,
        lead_mm=lead,
        lead_gain=0.04,
        lead_phase_rad=phase,
        tilt_gain=tilt,
        cogging_A=0.1,
        cogging_period_mm=lead / 24.0,
        cogging_phase_rad=0.0,
        motion=geometry.motion,
    )


# ------------------------------------------------------------------ compiled laws (one copy each)
@njit(cache=True)
def stribeck_ratio(velocity_mm_s, coulomb_ratio, stribeck_velocity_mm_s, stribeck_shape):
    """Steady Stribeck ratio ``rho(v) = r_c + (1 - r_c) exp(-(|v|/v_s)^delta)`` of the twin (1 at rest).

    Parameters
    ----------
    velocity_mm_s : float
        Velocity [mm/s].
    coulomb_ratio : float
        ``r_c``, the sliding level relative to the level at rest.
    stribeck_velocity_mm_s : float
        ``v_s`` [mm/s].
    stribeck_shape : float
        ``delta``.
    """
    return coulomb_ratio + (1.0 - coulomb_ratio) * math.exp(
        -((abs(velocity_mm_s) / stribeck_velocity_mm_s) ** stribeck_shape))


@njit(cache=True)
def position_factor_at(position_mm, low_mm, high_mm, preload_gain, tilt_gain, lead_mm, lead_gain, lead_phase_rad):
    """Position factor ``g(x) = 1 + c_pre u^4 + c_tilt u + c_lead sin(2 pi x / lead + phi)`` of the twin.

    Parameters
    ----------
    position_mm : float
        Position ``x`` [mm].
    low_mm, high_mm : float
        Ends of the travel [mm]; ``u = (2x - x_lo - x_hi) / (x_hi - x_lo)``.
    preload_gain, tilt_gain : float
        ``c_pre`` and ``c_tilt``.
    lead_mm, lead_gain, lead_phase_rad : float
        Screw lead [mm], ``c_lead`` and ``phi`` [rad].
    """
    u = (2.0 * position_mm - low_mm - high_mm) / (high_mm - low_mm)
    return 1.0 + preload_gain * u ** 4 + tilt_gain * u + lead_gain * math.sin(
        2.0 * math.pi * position_mm / lead_mm + lead_phase_rad)


@njit(cache=True)
def cogging_current_at(position_mm, cogging_A, cogging_period_mm, cogging_phase_rad):
    """Cogging current ``R(x) = a_cog sin(2 pi x / lambda_cog + phi_cog)`` [A].

    Parameters
    ----------
    position_mm : float
        Position ``x`` [mm].
    cogging_A : float
        Amplitude ``a_cog`` [A].
    cogging_period_mm : float
        Period ``lambda_cog`` [mm].
    cogging_phase_rad : float
        Phase ``phi_cog`` [rad].
    """
    return cogging_A * math.sin(2.0 * math.pi * position_mm / cogging_period_mm + cogging_phase_rad)


@njit(cache=True)
def _position_term_arrays(position_mm, low_mm, high_mm, preload_gain, tilt_gain, lead_mm, lead_gain, lead_phase_rad,
                           cogging_A, cogging_period_mm, cogging_phase_rad):
    factor = np.empty(position_mm.shape[0])
    cogging = np.empty(position_mm.shape[0])
    for i in range(position_mm.shape[0]):
        factor[i] = position_factor_at(position_mm[i], low_mm, high_mm, preload_gain, tilt_gain, lead_mm,
                                       lead_gain, lead_phase_rad)
        cogging[i] = cogging_current_at(position_mm[i], cogging_A, cogging_period_mm, cogging_phase_rad)
    return factor, cogging


@njit(cache=True)
def _stribeck_ratios(velocity_mm_s, coulomb_ratio, stribeck_velocity_mm_s, stribeck_shape):
    out = np.empty(velocity_mm_s.shape[0])
    for i in range(velocity_mm_s.shape[0]):
        out[i] = stribeck_ratio(velocity_mm_s[i], coulomb_ratio, stribeck_velocity_mm_s, stribeck_shape)
    return out


@njit(cache=True)
def lag_decay(step_s, lag_time_s):
    """``exp(-h / tau)``: what remains of a deviation of the lagged ratio after a step ``h`` [s] (0 without lag).

    Parameters
    ----------
    step_s : float
        Step ``h`` [s].
    lag_time_s : float
        Time constant ``tau`` [s]; 0 for no lag.
    """
    return math.exp(-step_s / lag_time_s) if lag_time_s > 0.0 else 0.0


@njit(cache=True)
def lagged_stribeck_ratio(level, velocity_mm_s, coulomb_ratio, stribeck_velocity_mm_s, stribeck_shape, decay):
    """One step of the lagged Stribeck ratio ``tau dr/dt = rho(v) - r``, exact for ``rho`` held.

    Parameters
    ----------
    level : float
        Ratio ``r`` before the step.
    velocity_mm_s : float
        Velocity [mm/s] over the step.
    coulomb_ratio, stribeck_velocity_mm_s, stribeck_shape : float
        ``rho`` as in :func:`stribeck_ratio`.
    decay : float
        :func:`lag_decay` of the step.

    Returns
    -------
    float
        ``rho + (r - rho) decay``.
    """
    target = stribeck_ratio(velocity_mm_s, coulomb_ratio, stribeck_velocity_mm_s, stribeck_shape)
    return target + (level - target) * decay


@njit(cache=True)
def maxwell_slip_update(deflection, step_mm, level, stiffness, breakaway_deflection):
    """Move every elasto-plastic element by ``step_mm`` and clamp it; return ``sum_i k_i d_i`` [A].

    ``d_i <- clip(d_i + dx, -D_i r, +D_i r)``, summed in element order.

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
    out = np.empty((n - 1) // stride + 1)
    state = np.zeros(stiffness_A_mm.shape[0])
    decay = lag_decay(step_s, lag_time_s)
    level = stribeck_ratio(velocity_mm_s[0], coulomb_ratio, stribeck_velocity_mm_s, stribeck_shape)
    for i in range(n):
        step = 0.0
        if i > 0:
            level = lagged_stribeck_ratio(level, velocity_mm_s[i], coulomb_ratio, stribeck_velocity_mm_s,
                                          stribeck_shape, decay)
            step = position_mm[i] - position_mm[i - 1]
        force = maxwell_slip_update(state, step, level, stiffness_A_mm, deflection_mm)
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
    friction_A, inertia_A, cogging_A : ndarray
        Friction, inertia and cogging current [A].
    load_gain : float, default 0.0
        Friction current per ampere of axial load (``1 - efficiency`` of the screw); 0: friction independent
        of the load.
    friction_direction : ndarray, optional
        Friction over its largest magnitude, in [-1, 1]: the direction in which a load-dependent friction acts
        (needed when ``load_gain`` is not 0).
    """

    position_mm: np.ndarray
    velocity_mm_s: np.ndarray
    acceleration_mm_s2: np.ndarray
    friction_A: np.ndarray
    inertia_A: np.ndarray
    cogging_A: np.ndarray
    load_gain: float = 0.0
    friction_direction: np.ndarray | None = None

    @property
    def current_A(self) -> np.ndarray:
        """Inertia plus friction plus cogging current [A]."""
        return self.friction_A + self.inertia_A + self.cogging_A

    def under_load(self, process_A) -> "PlantResponse":
        """The response with a process current [A] added to the axial load of the screw.

        The friction grows by ``load_gain (|I_inertia + I_process| - |I_inertia|)`` in the friction's
        direction; the process current itself is not included (the caller adds it).

        Parameters
        ----------
        process_A : ndarray, shape (n,)
            Process current [A] at the log samples.
        """
        if self.load_gain == 0.0:
            return self
        extra = self.load_gain * (np.abs(self.inertia_A + process_A) - np.abs(self.inertia_A))
        return replace(self, friction_A=self.friction_A + extra * self.friction_direction)


def fine_steps_per_sample(params, sample_time_s: float) -> int:
    """Number of internal steps per log sample; raises if the step does not divide the sample time.

    Parameters
    ----------
    params : object
        A plant with ``internal_step_s`` [s], e.g. :class:`PlantParameters`.
    sample_time_s : float
        Log sample time [s].

    Raises
    ------
    GreyboxError
        If ``sample_time_s`` is not a whole multiple (at least 1) of the internal step.
    """
    ratio = sample_time_s / params.internal_step_s
    stride = int(round(ratio))
    if stride < 1 or abs(ratio - stride) > 1e-9 * ratio:
        raise GreyboxError(
            f"plant: internal step {params.internal_step_s} s must divide the sample time {sample_time_s} s")
    return stride


def fine_motion(plant, motion, n_samples: int, sample_time_s: float):
    """The motion on a plant's fine grid up to the last log sample: ``(stride, x_mm, v_mm_s, a_mm_s2)``.

    Parameters
    ----------
    plant : object
        Has ``internal_step_s`` [s], which must divide ``sample_time_s``.
    motion : object
        Has ``evaluate(time_s) -> (x_mm, v_mm_s, a_mm_s2)``.
    n_samples : int
        Number of log samples.
    sample_time_s : float
        Log sample time [s]; the log samples are every ``stride``-th fine point.
    """
    stride = fine_steps_per_sample(plant, sample_time_s)
    x, v, a = motion.evaluate(np.arange((n_samples - 1) * stride + 1) * plant.internal_step_s)
    return stride, x, v, a


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
    stride, x, v, a = fine_motion(params, motion, n_samples, sample_time_s)
    maxwell = maxwell_slip_kernel(
        x, v, params.internal_step_s, stride, params.stiffness_A_mm,
        np.asarray(params.breakaway_deflection_mm, float), params.coulomb_ratio,
        params.stribeck_velocity_mm_s, params.stribeck_shape, params.lag_time_s)
    x_log, v_log, a_log = x[::stride], v[::stride], a[::stride]
    factor, cogging = params._position_terms(x_log)
    friction = factor * maxwell + params.viscous_A_s_mm * v_log
    return PlantResponse(x_log, v_log, a_log, friction, params.inertia_A_s2_mm * a_log, cogging)


# ------------------------------------------------------------------ the plant of a position loop
#: Length of the head of the plant law's parameters: r_c, v_s, delta, tau, sigma_v, then the ten position
#: terms of :meth:`PlantParameters._position_head` (x_lo, x_hi, c_pre, c_tilt, lead, c_lead, phi, a_cog,
#: lambda_cog, phi_cog); then k_1..m, D_1..m.
_TWIN_HEAD = 15


@njit(cache=True)
def twin_plant_friction(parameters, state, position_mm, velocity_mm_s):
    """Friction and cogging [A] ``g(x) sum_i k_i d_i + sigma_v v + R(x)`` of the present state.

    Layout of ``parameters`` and ``state`` in :func:`twin_plant_law`.

    Parameters
    ----------
    parameters : ndarray of float64
        The law's parameters, in the layout of :func:`twin_plant_law`.
    state : ndarray of float64
        The law's state, in the layout of :func:`twin_plant_law`.
    position_mm : float
        Present position [mm].
    velocity_mm_s : float
        Present velocity [mm/s].
    """
    factor = position_factor_at(position_mm, parameters[5], parameters[6], parameters[7], parameters[8],
                                parameters[9], parameters[10], parameters[11])
    cogging = cogging_current_at(position_mm, parameters[12], parameters[13], parameters[14])
    return factor * state[1] + parameters[4] * velocity_mm_s + cogging


@njit(cache=True)
def twin_plant_advance(parameters, state, velocity_mm_s, step_s):
    """Move the lagged Stribeck ratio and the elements over one step ``step_s`` [s] at ``velocity_mm_s`` (in place).

    The element displacement over the step is ``step_s * velocity_mm_s``;
    ``state[1]`` receives ``sum_i k_i d_i`` [A] after the step.

    Parameters
    ----------
    parameters : ndarray of float64
        The law's parameters, in the layout of :func:`twin_plant_law`.
    state : ndarray of float64
        The law's state, in the layout of :func:`twin_plant_law` (updated in place).
    velocity_mm_s : float
        Velocity over the step [mm/s].
    step_s : float
        Internal step [s].
    """
    m = (parameters.shape[0] - _TWIN_HEAD) // 2
    decay = lag_decay(step_s, parameters[3])
    level = lagged_stribeck_ratio(state[0], velocity_mm_s, parameters[0], parameters[1], parameters[2], decay)
    state[0] = level
    state[1] = maxwell_slip_update(state[2:], step_s * velocity_mm_s, level, parameters[_TWIN_HEAD:_TWIN_HEAD + m],
                                   parameters[_TWIN_HEAD + m:])


def twin_plant_law(params: PlantParameters, *, friction: bool = True) -> PlantLaw:
    """The truth plant as the plant of a position loop, at rest (relaxed elements, ratio 1).

    ``parameters = (r_c, v_s, delta, tau, sigma_v, x_lo, x_hi, c_pre, c_tilt, lead, c_lead, phi,
    a_cog, lambda_cog, phi_cog, k_1..m, D_1..m)``, ``state = (r, sum_i k_i d_i, d_1..m)``; the
    friction is ``g(x) sum_i k_i d_i + sigma_v v``, plus the cogging current (see the module doc).

    Parameters
    ----------
    params : PlantParameters
        The plant.
    friction : bool, default True
        With ``False`` the stiffnesses, the viscous coefficient and the
        cogging current are zero: the plant is its inertia alone.

    Returns
    -------
    PlantLaw
        Its internal step is the plant's ``internal_step_s`` (the clamp is
        stable at any step); no constant load.
    """
    scale = 1.0 if friction else 0.0
    head = [float(params.coulomb_ratio), float(params.stribeck_velocity_mm_s), float(params.stribeck_shape),
            float(params.lag_time_s), float(params.viscous_A_s_mm) * scale, *params._position_head()]
    head[12] *= scale  # a_cog
    parameters = np.concatenate((head, np.asarray(params.stiffness_A_mm, float) * scale,
                                 np.asarray(params.breakaway_deflection_mm, float)))
    state = np.zeros(2 + len(params.breakaway_A))
    state[0] = 1.0
    return PlantLaw(twin_plant_friction, twin_plant_advance, np.ascontiguousarray(parameters), state,
                    float(params.internal_step_s), float(params.inertia_A_s2_mm), 0.0)
