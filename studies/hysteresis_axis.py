r"""An independent family of synthetic feed axes: Bouc-Wen hysteresis friction with Stribeck weakening.

The family checks the discovery workflow on a friction law it was not
developed on. Nothing here comes from greybox's friction models or its
synthetic twin: the friction law, the trajectories, the noise and the hidden
effects are written apart (``tests/studies/test_hysteresis_axis.py`` checks the
imports). The logs are returned raw (time, position, current), so a caller
prepares them with :func:`greybox.data.prepare.prepare` exactly like a real
log.

Model
-----
All forces are expressed as motor currents [A] (force / torque constant).
With position :math:`x` [mm], velocity :math:`v` [mm/s], acceleration
:math:`a` [mm/s^2] and time since the start of the log :math:`t` [s]:

.. math::

    \frac{dw}{dx} = \frac{1}{x_p}\left(1 - |w|^n \left(\gamma + \beta\,\mathrm{sign}(\dot x\, w)\right)\right),
    \qquad \beta + \gamma = 1,\ \tfrac12 \le \beta < 1

    F_{ss}(|v|) = F_c + (F_s - F_c)\, \exp\left(-(|v| / v_s)^\delta\right)

    F_f = \lambda(x, t)\, F_{ss}(|v|)\, w\, \kappa(w) + \sigma_v\, v\, \eta(v)

    i = m\, a + F_f + i_h(x, t)

- :math:`w` [-] is the hysteretic (Bouc-Wen) variable, :math:`|w| < 1`. On
  loading (:math:`\dot x\, w > 0`) it approaches :math:`\pm 1` with the knee
  set by the exponent :math:`n` [-]; on unloading its slope
  :math:`(1 + (\beta - \gamma)|w|^n) / x_p` is at least the initial one, so
  every closed position cycle dissipates energy. :math:`x_p` [mm] is the
  pre-sliding distance. Since :math:`\dot x` enters only through its sign,
  :math:`w` depends on the path of the position alone (rate independent).
- :math:`F_c` [A] is the Coulomb level, :math:`F_s` [A] the static level,
  :math:`v_s` [mm/s] the Stribeck velocity, :math:`\delta` [-] the Stribeck
  exponent, :math:`\sigma_v` [A s/mm] the viscous coefficient, :math:`m`
  [A s^2/mm] the inertia.
- :math:`\lambda` [-] (friction level factor), :math:`\kappa` [-] (factor of
  the level while :math:`w < 0`, i.e. sliding or loaded in the negative
  direction), :math:`\eta` [-] (factor of the viscous part for :math:`v < 0`)
  and the additive current :math:`i_h` [A] are 1, 1, 1 and 0 unless a hidden
  effect changes them (:data:`HIDDEN_EFFECTS`).

In steady sliding :math:`w \to \mathrm{sign}(v)` and
:math:`F_f \to \mathrm{sign}(v) F_{ss}(|v|) + \sigma_v v`.

Hidden effects
--------------
============================== ===================================================================
``direction_asymmetry``        :math:`\kappa = 1 - A`, :math:`\eta = 1 - A q`: friction level and
                               viscous part differ in negative motion (:math:`q` [-] drawn)
``constant_offset``            :math:`i_h = A` [A]: weight compensation, current bias
``position_trend``             :math:`\lambda = 1 + A (k_1 u + k_2 u^2)`, :math:`u` the position
                               in the travel window scaled to [-1, 1]
``position_periodic_friction`` :math:`\lambda = 1 + A \sin(2 \pi x / P + \varphi)`, :math:`P` [mm]
``position_periodic_force``    :math:`i_h = A \sin(2 \pi x / P + \varphi)` [A], the same in both
                               directions
``thermal_drift``              :math:`\lambda = 1 + A (1 - \exp(-t / \tau))`, :math:`\tau` [s];
                               :math:`A < 0` is a warm-up reduction
============================== ===================================================================

The shape of an effect (sign, :math:`q, k_1, k_2, P, \varphi, \tau`) is drawn
from a stream seeded by the case's seed and the effect's name
(:data:`EFFECT_RANGES`); its amplitude :math:`A` is set so that the RMS of the
hidden current (current with the effect minus current without it, both
noise-free) on the first training log is ``ratio`` times the RMS of the noise
realisation on that log. Because :math:`w` does not depend on the forces, the
current is linear in :math:`A` and one evaluation at unit amplitude fixes it.

Simulation
----------
Each log is a random sequence of point-to-point moves (raised-cosine
velocity ramps, so the acceleration is continuous), small oscillations with a
raised-cosine envelope (reversal rich) and dwells at standstill, inside a
travel window of :data:`TRAVEL_MM` around the axis' centre. Position,
velocity and acceleration are analytic on a fine grid of
:data:`SUBSTEPS` points per log sample. :math:`w` is stepped exactly: on every
stretch of monotone position it follows
:math:`w = d\,\Phi^{-1}(\Phi(d\,w_0) + |x - x_0| / x_p)` with the direction
:math:`d = \pm 1` and :math:`\Phi(w) = \int_0^w dw' / g(w')` the tabulated
integral of the loading/unloading slope :math:`g`. The log keeps every
:data:`SUBSTEPS`-th point (:data:`SAMPLE_TIME_S`), the position quantised to
the encoder resolution, and the current plus AR(1) noise.
"""

from __future__ import annotations

import dataclasses
import zlib
from dataclasses import dataclass
from functools import partial

import numpy as np
from scipy.integrate import cumulative_trapezoid
from scipy.signal import lfilter

from greybox.data.log import AxisLog

__all__ = ["HIDDEN_EFFECTS", "ROLES", "AXIS_RANGES", "EFFECT_RANGES", "SAMPLE_TIME_S", "SUBSTEPS", "TRAVEL_MM",
           "FEED_RANGE_MM_S", "ENCODER_RESOLUTION_MM", "FamilyCase", "AxisParameters", "Motion", "Modifiers",
           "draw_axis", "draw_motion", "steady_friction_A", "hysteresis_state", "axis_current", "family_logs"]

#: Hidden effects of the family; the names are those of greybox's effect library.
HIDDEN_EFFECTS = ("direction_asymmetry", "constant_offset", "position_trend",
                  "position_periodic_friction", "position_periodic_force", "thermal_drift")

#: Ranges (low, high) of the axis parameters, drawn uniformly; units in the names.
AXIS_RANGES = {
    "coulomb_A": (0.3, 1.2),
    "static_ratio": (1.1, 1.8),                   # F_s / F_c [-]
    "stribeck_velocity_mm_s": (0.5, 8.0),
    "stribeck_exponent": (0.6, 2.0),
    "presliding_mm": (0.002, 0.020),
    "hysteresis_exponent": (1.5, 3.0),
    "hysteresis_beta": (0.5, 0.9),                # gamma = 1 - beta
    "viscous_top_speed_A": (0.1, 0.6),            # viscous current at the top feed
    "inertia_reference_A": (0.3, 1.5),            # inertia current at REFERENCE_ACCELERATION_MM_S2
    "acceleration_limit_mm_s2": (500.0, 1500.0),
    "noise_std_A": (0.02, 0.06),
    "noise_correlation": (0.3, 0.8),              # lag-1 correlation of the AR(1) noise [-]
    "travel_centre_mm": (-50.0, 50.0),
}

#: Ranges of the shape parameters of the hidden effects, drawn uniformly (besides a random sign).
EFFECT_RANGES = {
    "direction_asymmetry": {"viscous_ratio": (0.5, 2.0)},
    "constant_offset": {},
    "position_trend": {"linear": (0.5, 1.0), "quadratic": (-0.5, 0.5)},
    "position_periodic_friction": {"period_mm": (5.0, 20.0), "phase_rad": (0.0, 2 * np.pi)},
    "position_periodic_force": {"period_mm": (2.0, 8.0), "phase_rad": (0.0, 2 * np.pi)},
    "thermal_drift": {"time_constant_s": (20.0, 200.0)},
}

#: The logs of a case, in the order of the per-log lists of ``info``.
ROLES = ("train1", "train2", "test1", "test2")

#: Log sample time [s] and fine integration points per sample.
SAMPLE_TIME_S = 0.002
SUBSTEPS = 8
#: Width of the travel window [mm].
TRAVEL_MM = 60.0
#: Feed range of the moves [mm/s], drawn log-uniformly.
FEED_RANGE_MM_S = (0.5, 60.0)
#: Encoder resolution: the logged position is quantised to it [mm].
ENCODER_RESOLUTION_MM = 0.001
#: Acceleration at which ``inertia_reference_A`` is the inertia current [mm/s^2].
REFERENCE_ACCELERATION_MM_S2 = 1000.0

_FEED_BANDS = 3                     # moves take their feeds in turn from log-equal bands
_OSCILLATION_SHARE = 0.4            # probability that a segment is an oscillation
_AMPLITUDE_RANGE_MM = (0.05, 2.0)   # oscillation amplitude, log-uniform
_FREQUENCY_RANGE_HZ = (0.5, 5.0)    # oscillation frequency, log-uniform, then limited by the axis
_PERIODS_RANGE = (2, 6)             # oscillation periods (envelope ramps take one each)
_MAX_OSCILLATION_S = 5.0            # fewer periods for slow oscillations (at least the minimum)
_DWELL_RANGE_S = (0.0, 0.5)
_MAX_MOVE_TIME_S = 3.0              # a move covers at most feed * this [mm]
_MIN_MOVE_MM = 0.1
_START_MARGIN_MM = 5.0              # a log starts this far inside the window
_MIN_FRICTION_FACTOR = 0.1          # an effect may not scale friction below this
_TABLE_POINTS = 6000
_TABLE_SATURATION = 30.0            # the table ends at w = 1 - exp(-30)


@dataclass(frozen=True)
class FamilyCase:
    """One axis of the family with one hidden effect at one strength.

    Parameters
    ----------
    effect : str or None
        One of :data:`HIDDEN_EFFECTS`, or None for nothing hidden (null axis).
    ratio : float, default 1.0
        RMS of the hidden current over the RMS of the noise on the first training log [-].
    seed : int, default 0
        Seed of the axis parameters, trajectories, noise and effect shape.
    duration_s : float, default 30.0
        Length of each log [s].
    """

    effect: str | None
    ratio: float = 1.0
    seed: int = 0
    duration_s: float = 30.0

    def __post_init__(self):
        if self.effect is not None and self.effect not in HIDDEN_EFFECTS:
            raise ValueError(f"unknown hidden effect {self.effect!r}; expected one of {HIDDEN_EFFECTS} or None")
        if not self.ratio >= 0:
            raise ValueError(f"ratio must be non-negative, got {self.ratio!r}")
        if not self.duration_s >= 1.0:
            raise ValueError(f"duration_s must be at least 1 s, got {self.duration_s!r}")


@dataclass(frozen=True)
class AxisParameters:
    """Physical parameters of one axis of the family (ranges in :data:`AXIS_RANGES`).

    Attributes
    ----------
    coulomb_A : float
        Coulomb friction level :math:`F_c` [A].
    static_ratio : float
        Static over Coulomb level :math:`F_s / F_c` [-].
    stribeck_velocity_mm_s : float
        Stribeck velocity :math:`v_s` [mm/s].
    stribeck_exponent : float
        Stribeck exponent :math:`\\delta` [-].
    presliding_mm : float
        Pre-sliding distance :math:`x_p` [mm].
    hysteresis_exponent : float
        Bouc-Wen exponent :math:`n` [-].
    hysteresis_beta : float
        Bouc-Wen :math:`\\beta` [-]; :math:`\\gamma = 1 - \\beta`.
    viscous_top_speed_A : float
        Viscous current at the top feed [A].
    inertia_reference_A : float
        Inertia current at :data:`REFERENCE_ACCELERATION_MM_S2` [A].
    acceleration_limit_mm_s2 : float
        Largest acceleration of the trajectories [mm/s^2].
    noise_std_A : float
        Standard deviation of the current noise [A].
    noise_correlation : float
        Lag-1 correlation of the AR(1) current noise [-].
    travel_centre_mm : float
        Centre of the travel window [mm].
    """

    coulomb_A: float
    static_ratio: float
    stribeck_velocity_mm_s: float
    stribeck_exponent: float
    presliding_mm: float
    hysteresis_exponent: float
    hysteresis_beta: float
    viscous_top_speed_A: float
    inertia_reference_A: float
    acceleration_limit_mm_s2: float
    noise_std_A: float
    noise_correlation: float
    travel_centre_mm: float

    @property
    def static_A(self) -> float:
        """Static friction level :math:`F_s` [A]."""
        return self.coulomb_A * self.static_ratio

    @property
    def viscous_A_s_mm(self) -> float:
        """Viscous coefficient :math:`\\sigma_v` [A s/mm]."""
        return self.viscous_top_speed_A / FEED_RANGE_MM_S[1]

    @property
    def inertia_A_s2_mm(self) -> float:
        """Inertia :math:`m` [A s^2/mm]."""
        return self.inertia_reference_A / REFERENCE_ACCELERATION_MM_S2


@dataclass(frozen=True)
class Motion:
    """Analytic motion of the axis on a time grid.

    Attributes
    ----------
    time : ndarray
        Time since the start of the log [s].
    position, velocity, acceleration : ndarray
        Position [mm], velocity [mm/s], acceleration [mm/s^2].
    """

    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


@dataclass(frozen=True)
class Modifiers:
    """What a hidden effect changes in the current (module notes, "Model").

    Attributes
    ----------
    level : float or ndarray
        Friction level factor :math:`\\lambda` [-], scalar or per point.
    negative_level : float
        Level factor :math:`\\kappa` while :math:`w < 0` [-].
    negative_viscous : float
        Viscous factor :math:`\\eta` for :math:`v < 0` [-].
    offset_A : float or ndarray
        Additive current :math:`i_h` [A], scalar or per point.
    """

    level: float | np.ndarray = 1.0
    negative_level: float = 1.0
    negative_viscous: float = 1.0
    offset_A: float | np.ndarray = 0.0


# ----------------------------------------------------------------------------- axis and friction law
def draw_axis(seed: int) -> AxisParameters:
    """Draw the parameters of the family's axis ``seed`` uniformly from :data:`AXIS_RANGES`.

    Parameters
    ----------
    seed : int
        Seed of the axis; the same seed gives the same axis.
    """
    rng = np.random.default_rng([seed, 0])
    return AxisParameters(**{name: float(rng.uniform(*AXIS_RANGES[name]))
                             for name in (f.name for f in dataclasses.fields(AxisParameters))})


def steady_friction_A(speed_mm_s, axis: AxisParameters) -> np.ndarray:
    """Stribeck curve :math:`F_{ss}(|v|)` [A] at the speed [mm/s] (its absolute value is taken).

    Parameters
    ----------
    speed_mm_s : float or array_like
        Speed or velocity [mm/s]; only its magnitude counts.
    axis : AxisParameters
        The axis, giving the Coulomb and static levels [A], Stribeck velocity [mm/s] and exponent.
    """
    ratio = np.abs(np.asarray(speed_mm_s, dtype=float)) / axis.stribeck_velocity_mm_s
    return axis.coulomb_A + (axis.static_A - axis.coulomb_A) * np.exp(-ratio ** axis.stribeck_exponent)


def _hysteresis_table(exponent: float, beta: float) -> tuple[np.ndarray, np.ndarray]:
    """Tabulate :math:`\\Phi(w) = \\int_0^w dw' / g(w')` for a positive step, with :math:`x_p = 1`.

    Returns
    -------
    phi, w : ndarray
        Strictly increasing; ``w`` covers [-1, 1 - exp(-30)].
    """
    gamma = 1.0 - beta
    # Unloading branch, w in [-1, 0]: g = 1 + (beta - gamma) |w|^n.
    w_neg = np.linspace(-1.0, 0.0, _TABLE_POINTS)
    phi_neg = cumulative_trapezoid(1.0 / (1.0 + (beta - gamma) * np.abs(w_neg) ** exponent), w_neg, initial=0.0)
    phi_neg -= phi_neg[-1]
    # Loading branch, w = 1 - exp(-u): g = 1 - w^n, dphi/du = (1 - w) / (1 - w^n), 1 at u = 0.
    u = np.linspace(0.0, _TABLE_SATURATION, _TABLE_POINTS)
    w_pos = -np.expm1(-u)
    slope = np.ones_like(u)
    slope[1:] = np.exp(-u[1:]) / -np.expm1(exponent * np.log(w_pos[1:]))
    phi_pos = cumulative_trapezoid(slope, u, initial=0.0)
    return np.concatenate((phi_neg[:-1], phi_pos)), np.concatenate((w_neg[:-1], w_pos))


def _held_sign(step: np.ndarray) -> np.ndarray:
    """Sign of each step, a zero step taking the sign of the last non-zero one (0 before any)."""
    sign = np.sign(step)
    index = np.where(sign != 0, np.arange(sign.size), 0)
    return sign[np.maximum.accumulate(index)]


def hysteresis_state(position_mm, axis: AxisParameters, *, initial: float = 0.0) -> np.ndarray:
    """Bouc-Wen variable :math:`w` [-] along a position path, stepped exactly on every monotone stretch.

    Parameters
    ----------
    position_mm : array_like, shape (n,)
        Position path [mm]; only its sequence of values matters (rate independence).
    axis : AxisParameters
        Gives :math:`x_p`, :math:`n` and :math:`\\beta`.
    initial : float, default 0.0
        :math:`w` at the first point [-], in (-1, 1).

    Returns
    -------
    ndarray, shape (n,)
    """
    x = np.asarray(position_mm, dtype=float)
    phi_table, w_table = _hysteresis_table(axis.hysteresis_exponent, axis.hysteresis_beta)
    w = np.empty_like(x)
    w[0] = initial
    direction = _held_sign(np.diff(x))
    ends = np.append(np.flatnonzero(np.diff(direction)) + 1, direction.size)
    start = 0
    for end in ends:
        sign = direction[start] or 1.0
        phi_start = np.interp(sign * w[start], w_table, phi_table)
        travel = sign * (x[start + 1:end + 1] - x[start]) / axis.presliding_mm
        w[start + 1:end + 1] = sign * np.interp(phi_start + travel, phi_table, w_table)
        start = end
    return w


def axis_current(motion: Motion, axis: AxisParameters, modifiers: Modifiers = Modifiers(), *,
                 initial_state: float = 0.0) -> np.ndarray:
    """Noise-free motor current [A] of the axis on a motion (module notes, "Model").

    Parameters
    ----------
    motion : Motion
        Time [s], position [mm], velocity [mm/s], acceleration [mm/s^2]; the
        hysteresis follows the position point by point, so the grid should be
        fine enough to resolve the reversals.
    axis : AxisParameters
    modifiers : Modifiers, optional
        Changes made by a hidden effect; none by default.
    initial_state : float, default 0.0
        Bouc-Wen variable at the first point [-].

    Returns
    -------
    ndarray
        Inertia + friction + additive current [A] at the points of ``motion``.
    """
    w = hysteresis_state(motion.position, axis, initial=initial_state)
    v = motion.velocity
    level = modifiers.level * np.where(w < 0, modifiers.negative_level, 1.0)
    viscous = axis.viscous_A_s_mm * v * np.where(v < 0, modifiers.negative_viscous, 1.0)
    return (axis.inertia_A_s2_mm * motion.acceleration + level * steady_friction_A(v, axis) * w + viscous
            + modifiers.offset_A)


# ----------------------------------------------------------------------------------------- trajectories
def _move_profile(tau: np.ndarray, *, sign: float, feed: float, ramp: float, cruise: float):
    """Displacement [mm], velocity [mm/s], acceleration [mm/s^2] of a move with raised-cosine ramps."""
    k = np.pi / ramp
    up = np.clip(tau, 0.0, ramp)
    down = np.clip(tau - ramp - cruise, 0.0, ramp)
    x = 0.5 * feed * (up - np.sin(k * up) / k) + feed * np.clip(tau - ramp, 0.0, cruise) \
        + 0.5 * feed * (down + np.sin(k * down) / k)
    accelerating, braking = tau < ramp, tau >= ramp + cruise
    v = np.where(accelerating, 0.5 * feed * (1 - np.cos(k * up)),
                 np.where(braking, 0.5 * feed * (1 + np.cos(k * down)), feed))
    a = np.where(accelerating, 0.5 * feed * k * np.sin(k * up), np.where(braking, -0.5 * feed * k * np.sin(k * down),
                                                                          0.0))
    return sign * x, sign * v, sign * a


def _oscillation_profile(tau: np.ndarray, *, amplitude: float, omega: float, periods: int):
    """Displacement, velocity, acceleration of ``A e(t) sin(omega t)``, ``e`` a raised-cosine envelope over a period."""
    ramp = 2 * np.pi / omega
    total = periods * ramp
    rest = np.minimum(tau, total - tau)
    in_ramp = rest < ramp
    k = np.pi / ramp
    r = np.clip(rest, 0.0, ramp)
    e = 0.5 * (1 - np.cos(k * r))
    de = np.where(in_ramp, 0.5 * k * np.sin(k * r), 0.0) * np.where(tau < total - tau, 1.0, -1.0)
    dde = np.where(in_ramp, 0.5 * k * k * np.cos(k * r), 0.0)
    s, c = np.sin(omega * tau), np.cos(omega * tau)
    return (amplitude * e * s, amplitude * (de * s + e * omega * c),
            amplitude * (dde * s + 2 * de * omega * c - e * omega ** 2 * s))


def _dwell_profile(tau: np.ndarray):
    """Standstill: zero displacement, velocity and acceleration."""
    zero = np.zeros_like(tau)
    return zero, zero, zero


def _log_uniform(rng: np.random.Generator, low: float, high: float) -> float:
    return float(np.exp(rng.uniform(np.log(low), np.log(high))))


def _draw_move(rng: np.random.Generator, position: float, window: tuple[float, float], axis: AxisParameters,
               feed: float):
    """A move from ``position`` towards a random target [mm]: (duration [s], profile, displacement [mm]).

    The target is uniform in the travel window; the move stops short of it after
    :data:`_MAX_MOVE_TIME_S` of travel at the ``feed`` [mm/s] (lower if the
    acceleration ramps do not fit).
    """
    target = rng.uniform(*window)
    if abs(target - position) < _MIN_MOVE_MM:
        target = position + _MIN_MOVE_MM * (1.0 if target < np.mean(window) else -1.0)
    sign = float(np.sign(target - position))
    length = min(abs(target - position), max(_MIN_MOVE_MM, feed * _MAX_MOVE_TIME_S))
    accel = axis.acceleration_limit_mm_s2
    feed = min(feed, np.sqrt(2 * accel * length / np.pi))   # two ramps must fit into the length
    ramp = np.pi * feed / (2 * accel)
    cruise = length / feed - ramp
    profile = partial(_move_profile, sign=sign, feed=feed, ramp=ramp, cruise=cruise)
    return 2 * ramp + cruise, profile, sign * length


def _draw_oscillation(rng: np.random.Generator, position: float, window: tuple[float, float],
                      axis: AxisParameters):
    """A small oscillation about ``position`` [mm] (duration [s], profile, displacement 0), or None without room."""
    room = min(position - window[0], window[1] - position)
    if room < _AMPLITUDE_RANGE_MM[0]:
        return None
    amplitude = min(_log_uniform(rng, *_AMPLITUDE_RANGE_MM), room)
    # The envelope raises the peaks to at most 1.25 A omega and 1.625 A omega^2.
    omega = min(2 * np.pi * _log_uniform(rng, *_FREQUENCY_RANGE_HZ), FEED_RANGE_MM_S[1] / (1.25 * amplitude),
                np.sqrt(axis.acceleration_limit_mm_s2 / (1.625 * amplitude)))
    periods = int(rng.integers(_PERIODS_RANGE[0], _PERIODS_RANGE[1] + 1))
    periods = max(_PERIODS_RANGE[0], min(periods, int(_MAX_OSCILLATION_S * omega / (2 * np.pi))))
    amplitude *= float(rng.choice((-1.0, 1.0)))
    profile = partial(_oscillation_profile, amplitude=amplitude, omega=omega, periods=periods)
    return periods * 2 * np.pi / omega, profile, 0.0


def _segments(axis: AxisParameters, rng: np.random.Generator, duration_s: float):
    """Start position [mm] and segments (duration [s], profile, displacement [mm]) covering ``duration_s``.

    The moves take their feeds in turn from :data:`_FEED_BANDS` log-equal bands
    of :data:`FEED_RANGE_MM_S` (log-uniform within a band), so every log has
    slow and fast moves; a dwell follows every move and oscillation.
    """
    window = (axis.travel_centre_mm - TRAVEL_MM / 2, axis.travel_centre_mm + TRAVEL_MM / 2)
    position = start = float(rng.uniform(window[0] + _START_MARGIN_MM, window[1] - _START_MARGIN_MM))
    bands = np.geomspace(*FEED_RANGE_MM_S, _FEED_BANDS + 1)
    band = int(rng.integers(_FEED_BANDS))
    segments, elapsed = [], 0.0
    while elapsed < duration_s:
        segment = _draw_oscillation(rng, position, window, axis) if rng.random() < _OSCILLATION_SHARE else None
        if segment is None:
            segment = _draw_move(rng, position, window, axis, _log_uniform(rng, bands[band], bands[band + 1]))
            band = (band + 1) % _FEED_BANDS
        segments += [segment, (float(rng.uniform(*_DWELL_RANGE_S)), _dwell_profile, 0.0)]
        elapsed += segment[0] + segments[-1][0]
        position += segment[2]
    return start, segments


def draw_motion(axis: AxisParameters, rng: np.random.Generator, duration_s: float, *,
                sample_time_s: float = SAMPLE_TIME_S, substeps: int = SUBSTEPS) -> Motion:
    """A random trajectory of moves, oscillations and dwells on the fine grid.

    Parameters
    ----------
    axis : AxisParameters
        Gives the travel window and the acceleration limit.
    rng : numpy.random.Generator
    duration_s : float
        Length [s]; rounded to whole log samples.
    sample_time_s : float, default :data:`SAMPLE_TIME_S`
        Log sample time [s].
    substeps : int, default :data:`SUBSTEPS`
        Fine points per log sample.

    Returns
    -------
    Motion
        On ``round(duration_s / sample_time_s) * substeps + 1`` points from 0 s; every
        ``substeps``-th point is a log sample.
    """
    n = int(round(duration_s / sample_time_s)) * substeps + 1
    time = np.arange(n) * (sample_time_s / substeps)
    start, segments = _segments(axis, rng, time[-1])
    position, velocity, acceleration = np.full(n, start), np.zeros(n), np.zeros(n)
    begin, offset = 0.0, start
    for duration, profile, displacement in segments:
        lo, hi = np.searchsorted(time, (begin, begin + duration))
        x, velocity[lo:hi], acceleration[lo:hi] = profile(time[lo:hi] - begin)
        position[lo:hi] = offset + x
        begin, offset = begin + duration, offset + displacement
    return Motion(time, position, velocity, acceleration)


def _sampled(motion: Motion, substeps: int) -> Motion:
    return Motion(motion.time[::substeps], motion.position[::substeps], motion.velocity[::substeps],
                  motion.acceleration[::substeps])


def _ar1_noise(rng: np.random.Generator, n: int, axis: AxisParameters) -> np.ndarray:
    """Stationary AR(1) noise [A] with the axis' standard deviation and lag-1 correlation."""
    rho, std = axis.noise_correlation, axis.noise_std_A
    innovation = rng.standard_normal(n)
    first = std * innovation[0]
    rest, _ = lfilter([std * np.sqrt(1 - rho ** 2)], [1.0, -rho], innovation[1:], zi=[rho * first])
    return np.concatenate(([first], rest))


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(values))))


# --------------------------------------------------------------------------------------- hidden effects
def _draw_shape(effect: str, seed: int) -> dict:
    """Shape parameters of an effect from the stream of (seed, effect); ``sign`` is +-1 (+1 for periodic ones)."""
    rng = np.random.default_rng([seed, 1000, zlib.crc32(effect.encode())])
    periodic = effect.startswith("position_periodic")
    shape = {"sign": 1.0 if periodic else float(rng.choice((-1.0, 1.0)))}
    shape.update({name: float(rng.uniform(*bounds)) for name, bounds in EFFECT_RANGES[effect].items()})
    return shape


def _modifiers(effect: str, shape: dict, amplitude: float, motion: Motion, axis: AxisParameters) -> Modifiers:
    """What ``effect`` at the signed ``amplitude`` changes on ``motion`` (module notes, "Hidden effects")."""
    if effect == "direction_asymmetry":
        return Modifiers(negative_level=1 - amplitude, negative_viscous=1 - amplitude * shape["viscous_ratio"])
    if effect == "constant_offset":
        return Modifiers(offset_A=amplitude)
    if effect == "position_trend":
        u = (motion.position - axis.travel_centre_mm) / (TRAVEL_MM / 2)
        return Modifiers(level=1 + amplitude * (shape["linear"] * u + shape["quadratic"] * u ** 2))
    if effect == "thermal_drift":
        return Modifiers(level=1 - amplitude * np.expm1(-motion.time / shape["time_constant_s"]))
    wave = np.sin(2 * np.pi * motion.position / shape["period_mm"] + shape["phase_rad"])
    if effect == "position_periodic_friction":
        return Modifiers(level=1 + amplitude * wave)
    return Modifiers(offset_A=amplitude * wave)


def _check_physical(effect: str, modifiers: Modifiers, ratio: float):
    """Raise ValueError when the effect would scale the friction below :data:`_MIN_FRICTION_FACTOR` or negative."""
    lowest = min(np.min(modifiers.level), modifiers.negative_level)
    if lowest < _MIN_FRICTION_FACTOR or modifiers.negative_viscous < 0:
        raise ValueError(f"{effect} at ratio {ratio:g} would scale the friction by {lowest:.3g} "
                         f"(viscous by {modifiers.negative_viscous:.3g}) on this axis; use a smaller ratio")


def _hidden_currents(case: FamilyCase, axis: AxisParameters, motions: list[Motion], base: list[np.ndarray],
                     noise_rms: float) -> tuple[list[np.ndarray], dict]:
    """Hidden current [A] per log at the case's ratio, and the effect's parameters."""
    if case.effect is None:
        return [np.zeros_like(b) for b in base], {}
    shape = _draw_shape(case.effect, case.seed)
    unit = _modifiers(case.effect, shape, 1.0, motions[0], axis)
    unit_rms = _rms(axis_current(motions[0], axis, unit)[::SUBSTEPS] - base[0])
    if unit_rms == 0:
        raise ValueError(f"{case.effect} leaves no trace on the first training log of seed {case.seed} "
                         f"({case.duration_s:g} s); use longer logs")
    strength = case.ratio * noise_rms / unit_rms
    currents = []
    for motion, current in zip(motions, base):
        modifiers = _modifiers(case.effect, shape, shape["sign"] * strength, motion, axis)
        _check_physical(case.effect, modifiers, case.ratio)
        currents.append(axis_current(motion, axis, modifiers)[::SUBSTEPS] - current)
    return currents, {**shape, "strength": strength, "amplitude": shape["sign"] * strength,
                      "amplitude_unit": "A" if case.effect in ("constant_offset", "position_periodic_force") else "1"}


def family_logs(case: FamilyCase) -> tuple[list[AxisLog], list[AxisLog], dict]:
    """Two training and two test logs of the case's axis, raw (not prepared), and what is in them.

    Parameters
    ----------
    case : FamilyCase

    Returns
    -------
    train, test : list of AxisLog
        Two logs each, of four independent random trajectories of the same
        axis: time [s] from 0 at :data:`SAMPLE_TIME_S`, position [mm] quantised
        to :data:`ENCODER_RESOLUTION_MM`, current [A] (inertia + friction +
        hidden effect + AR(1) noise); velocity and acceleration are None.
    info : dict
        ``axis`` (the :class:`AxisParameters` as a dict), ``effect``,
        ``effect_parameters`` (shape, ``strength``, signed ``amplitude`` and
        its unit; ``period_mm`` for the periodic effects; empty for None),
        ``ratio_requested``, ``ratio_achieved`` (hidden RMS / noise RMS on the
        first training log), ``noise_rms_A`` (RMS of the noise realisation on
        the first training log [A]), and per log in the order train1, train2,
        test1, test2 (``roles``): ``hidden_A`` and ``noise_A`` [A], and the
        true ``velocity_mm_s`` and ``acceleration_mm_s2``.

    Raises
    ------
    ValueError
        When the ratio asks for an effect that would make the friction level
        (nearly) vanish on this axis, or when the effect does not show on the
        first training log (e.g. direction asymmetry on a very short log
        without negative motion).
    """
    axis = draw_axis(case.seed)
    motions = [draw_motion(axis, np.random.default_rng([case.seed, 1 + k]), case.duration_s)
               for k in range(len(ROLES))]
    samples = [_sampled(m, SUBSTEPS) for m in motions]
    base = [axis_current(m, axis)[::SUBSTEPS] for m in motions]
    noise = [_ar1_noise(np.random.default_rng([case.seed, 11 + k]), len(b), axis) for k, b in enumerate(base)]
    noise_rms = _rms(noise[0])
    hidden, parameters = _hidden_currents(case, axis, motions, base, noise_rms)
    logs = [AxisLog(time=s.time, position=np.round(s.position / ENCODER_RESOLUTION_MM) * ENCODER_RESOLUTION_MM,
                    effort=b + h + e, effort_unit="A", axis="X", dataset=role,
                    attrs={"family": "hysteresis_axis", "seed": case.seed, "effect": case.effect,
                           "ratio": case.ratio, "role": role})
            for s, b, h, e, role in zip(samples, base, hidden, noise, ROLES)]
    info = {"axis": dataclasses.asdict(axis), "effect": case.effect, "effect_parameters": parameters,
            "ratio_requested": case.ratio, "ratio_achieved": _rms(hidden[0]) / noise_rms, "noise_rms_A": noise_rms,
            "roles": ROLES, "hidden_A": hidden, "noise_A": noise,
            "velocity_mm_s": [s.velocity for s in samples], "acceleration_mm_s2": [s.acceleration for s in samples]}
    return logs[:2], logs[2:], info
