"""Trajectories of the synthetic datasets (Rüppel et al. 2024, Table 1).

* A, C: random velocity steps and sinusoidal movements between 100 and
  2000 mm/min inside the 50 mm measurement window (different seeds),
* B: constant 600 and 1800 mm/min, once back and forth over the whole travel,
* D: constant 1200 mm/min, once back and forth over the whole travel,
* P: the pre-sliding excitation of Tjahjowidodo et al. (2005), see
  :mod:`greybox.twin.presliding`.

All motions are jerk limited, start and end at rest and contain reversals
and short dwells; velocities are in mm/s internally, mm/min in descriptions.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import GreyboxError
from .axes import AxisGeometry
from .motion import MotionLimits, MotionProfile
from .presliding import PreslidingExcitation

__all__ = [
    "Trajectory",
    "DATASETS",
    "DEFAULT_DATASETS",
    "MIN_DURATION_S",
    "random_window_trajectory",
    "constant_speed_trajectory",
    "presliding_trajectory",
    "dataset_trajectory",
]

MM_MIN = 1.0 / 60.0  # one mm/min in mm/s


@dataclass(frozen=True)
class Trajectory:
    """A commanded motion with its description.

    Parameters
    ----------
    motion : MotionProfile or PreslidingExcitation
        Object with ``duration_s`` and ``evaluate(time_s) -> (x_mm, v_mm_s, a_mm_s2)``.
    description : dict
        JSON-serialisable summary (kind, window or travel, speeds in mm/min, ...).
    """

    motion: object
    description: dict = field(default_factory=dict)

    @property
    def duration_s(self) -> float:
        """Length of the motion [s]."""
        return float(self.motion.duration_s)


def _log_uniform(rng, low, high, size=None):
    return np.exp(rng.uniform(np.log(low), np.log(high), size))


def _fitting_speed(limits: MotionLimits, distance_mm: float, speed_mm_s: float) -> float:
    """Largest speed <= ``speed_mm_s`` whose ramps up and down fit into ``distance_mm``."""
    if limits.ramps_distance([speed_mm_s]) <= distance_mm:
        return speed_mm_s
    low, high = 0.0, speed_mm_s
    for _ in range(60):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if limits.ramps_distance([mid]) <= distance_mm else (low, mid)
    return low


def _random_leg(profile: MotionProfile, rng, low_mm, high_mm, speeds_mm_s, dwell) -> bool:
    """Append one move through 1-3 random speed levels and maybe a short dwell; False if none fits.

    ``dwell = (probability, shortest_s, longest_s)`` of the dwell after the move.
    """
    room_up, room_down = high_mm - profile.position_mm, profile.position_mm - low_mm
    direction = 1.0 if rng.uniform() < room_up / (room_up + room_down) else -1.0
    room = room_up if direction > 0 else room_down
    if room < 1.0:
        direction, room = -direction, max(room_up, room_down)
    levels = _log_uniform(rng, *speeds_mm_s, size=int(rng.integers(1, 4)))
    cruise_s = rng.uniform(0.3, 2.0, size=levels.size)
    distance = min(profile.limits.ramps_distance(levels) + float(np.sum(levels * cruise_s)),
                   room * rng.uniform(0.4, 1.0))
    if profile.limits.ramps_distance(levels) > distance:
        levels = np.array([_fitting_speed(profile.limits, distance, float(levels.max()))])
        cruise_s = np.ones(1)
        if levels[0] < speeds_mm_s[0]:
            return False
    profile.move(direction * distance, levels, levels * cruise_s)
    if rng.uniform() < dwell[0]:
        profile.hold(rng.uniform(dwell[1], dwell[2]))
    return True


def _oscillation(profile: MotionProfile, rng, low_mm, high_mm, speeds_mm_s, dwell) -> None:
    """Oscillate a few periods around the present position (after a move to the centre if near an edge).

    ``speeds_mm_s`` bounds the peak speed; ``dwell`` as in :func:`_random_leg`.
    """
    centre, half = 0.5 * (low_mm + high_mm), 0.5 * (high_mm - low_mm)
    room = min(profile.position_mm - low_mm, high_mm - profile.position_mm)
    if room < 0.4 * half:
        offset = centre - profile.position_mm
        profile.move(offset, [_fitting_speed(profile.limits, abs(offset), float(_log_uniform(rng, *speeds_mm_s)))])
        if rng.uniform() < dwell[0]:
            profile.hold(rng.uniform(dwell[1], dwell[2]))
        room = half
    peak_speed = float(_log_uniform(rng, *speeds_mm_s))
    angular_frequency = max(2.0 * np.pi * rng.uniform(0.2, 1.0), peak_speed / (0.9 * room))
    profile.oscillate(peak_speed, angular_frequency, periods=float(rng.integers(3, 7)), ramp_periods=0.5)
    if rng.uniform() < dwell[0]:
        profile.hold(rng.uniform(dwell[1], dwell[2]))


def random_window_trajectory(geometry: AxisGeometry, rng: np.random.Generator, duration_s: float = 120.0,
                             speeds_mm_min=(100.0, 2000.0), limits: MotionLimits | None = None,
                             margin_mm: float = 1.0, dwell_probability: float = 0.02,
                             dwell_s=(0.02, 0.1), sine_peak_mm_min=(300.0, 2000.0)) -> Trajectory:
    """Random velocity steps alternating with sinusoidal movements inside the window (datasets A, C).

    Blocks of 15-30 s of random moves (1-3 speed levels each, log-uniform in
    ``speeds_mm_min``, reversals) alternate with sine oscillations around the
    present position (0.2-1 Hz or slower when the amplitude would not fit, 3-6
    periods, a sin^2 envelope rising and falling over half a period, peak speed
    log-uniform in ``sine_peak_mm_min``); near an edge the axis first moves to
    the window centre. After a move or an oscillation the axis dwells with
    probability ``dwell_probability``; it rests 0.5 s at the start and 0.1 s at
    the end.

    Parameters
    ----------
    geometry : AxisGeometry
        Axis whose measurement window bounds the motion.
    rng : numpy.random.Generator
        Source of randomness.
    duration_s : float, default 120.0
        Approximate length [s]; the motion ends at rest after the block that crosses it.
    speeds_mm_min : tuple of float, default (100, 2000)
        Range of cruise speeds and oscillation peak speeds [mm/min].
    limits : MotionLimits, optional
        Acceleration and jerk limits.
    margin_mm : float, default 1.0
        Distance [mm] kept from the window edges.
    dwell_probability : float, default 0.02
        Probability of a dwell after a random move or an oscillation.
    dwell_s : tuple of float, default (0.02, 0.1)
        Shortest and longest dwell [s], drawn uniformly.
    sine_peak_mm_min : tuple of float, default (300, 2000)
        Range of the oscillations' peak speeds [mm/min] (a sine of lower peak
        spends most of its time below the paper's lowest feed of 100 mm/min).
    """
    low, high = geometry.window_mm[0] + margin_mm, geometry.window_mm[1] - margin_mm
    dwell = (float(dwell_probability), float(dwell_s[0]), float(dwell_s[1]))
    speeds = (speeds_mm_min[0] * MM_MIN, speeds_mm_min[1] * MM_MIN)
    sine_peaks = (sine_peak_mm_min[0] * MM_MIN, sine_peak_mm_min[1] * MM_MIN)
    profile = MotionProfile(geometry.window_centre_mm, limits)
    profile.hold(0.5)
    legs = oscillations = 0
    random_steps = True
    while profile.time_s < duration_s - 1.0:
        if random_steps:
            block_end = min(profile.time_s + rng.uniform(15.0, 30.0), duration_s - 1.0)
            while profile.time_s < block_end:
                legs += _random_leg(profile, rng, low, high, speeds, dwell)
        else:
            _oscillation(profile, rng, low, high, sine_peaks, dwell)
            oscillations += 1
        random_steps = not random_steps
    profile.hold(0.1)
    limits = profile.limits
    return Trajectory(profile, {
        "kind": "random velocity steps and sinusoidal movements",
        "window_mm": list(geometry.window_mm),
        "speeds_mm_min": list(speeds_mm_min),
        "sine_peak_mm_min": list(sine_peak_mm_min),
        "duration_s": profile.duration_s,
        "moves": legs,
        "oscillations": oscillations,
        "dwell_probability": dwell[0],
        "dwell_s": [dwell[1], dwell[2]],
        "max_acceleration_mm_s2": limits.max_acceleration_mm_s2,
        "max_jerk_mm_s3": limits.max_jerk_mm_s3,
    })


def constant_speed_trajectory(geometry: AxisGeometry, speeds_mm_min, limits: MotionLimits | None = None,
                              dwell_s: float = 0.2) -> Trajectory:
    """Once back and forth over the whole travel at each constant speed (datasets B, D).

    The axis starts at the upper end of the travel, moves to the lower end and
    back, dwelling ``dwell_s`` [s] at each end, then repeats at the next speed [mm/min].

    Parameters
    ----------
    geometry : AxisGeometry
        Axis whose whole travel is crossed.
    speeds_mm_min : sequence of float
        Positive constant speeds [mm/min], in the order run.
    limits : MotionLimits, optional
        Acceleration and jerk limits; default :class:`MotionLimits`.
    dwell_s : float, default 0.2
        Dwell [s] at the start and after every move.
    """
    low, high = geometry.travel_mm
    profile = MotionProfile(high, limits)
    profile.hold(dwell_s)
    for speed in speeds_mm_min:
        for distance in (low - high, high - low):
            profile.move(distance, [speed * MM_MIN])
            profile.hold(dwell_s)
    limits = profile.limits
    return Trajectory(profile, {
        "kind": "constant speed back and forth",
        "travel_mm": list(geometry.travel_mm),
        "speeds_mm_min": [float(s) for s in speeds_mm_min],
        "duration_s": profile.duration_s,
        "dwell_s": dwell_s,
        "max_acceleration_mm_s2": limits.max_acceleration_mm_s2,
        "max_jerk_mm_s3": limits.max_jerk_mm_s3,
    })


def presliding_trajectory(geometry: AxisGeometry, rng: np.random.Generator, duration_s: float = 60.0,
                          **options) -> Trajectory:
    """Pre-sliding excitation around the window centre (dataset P); see :class:`PreslidingExcitation`.

    Parameters
    ----------
    geometry : AxisGeometry
        Axis whose measurement window centres the motion; the excursion from the centre is limited to
        0.4 times the window's width.
    rng : numpy.random.Generator
        Source of the random velocity.
    duration_s : float, default 60.0
        Length [s], rounded up to whole envelope periods.
    **options
        Further keyword arguments of :meth:`PreslidingExcitation.random` (``velocity_rms_mm_s``, ``cutoff_hz``,
        ``envelope_period_s``, ``highpass_hz``, ``knot_step_s``).
    """
    excitation = PreslidingExcitation.random(rng, geometry.window_centre_mm, duration_s=duration_s,
                                             max_excursion_mm=0.4 * (geometry.window_mm[1] - geometry.window_mm[0]),
                                             **options)
    return Trajectory(excitation, {
        "kind": "pre-sliding excitation (Tjahjowidodo et al. 2005)",
        "window_mm": list(geometry.window_mm),
        **excitation.description(),
    })


#: Dataset ids and what they contain.
DATASETS = {
    "A": "random velocity steps and sines, 100-2000 mm/min, inside the window",
    "B": "constant 600 and 1800 mm/min, back and forth over the travel",
    "C": "like A with another seed",
    "D": "constant 1200 mm/min, back and forth over the travel",
    "P": "pre-sliding excitation: 4 Hz band-limited random velocity, 10 s rectangular envelope",
}

#: Datasets of the paper's Table 1, generated by default.
DEFAULT_DATASETS = ("A", "B", "C", "D")

#: Shortest useful ``duration_s`` [s] of the datasets that take one. A and C rest 0.5 s at the start
#: and 0.1 s at the end and move only while time < duration - 1 s (below 1.5 s they do not move at all; at 2 s they make
#: at least one move), ending at rest after the move that crosses that time, so their length is
#: approximate. P runs whole periods of its 10 s rectangular envelope (the duration is rounded up to
#: them). B and D take no duration: they cross the travel once back and forth per speed.
MIN_DURATION_S = {"A": 2.0, "C": 2.0, "P": 10.0}


def dataset_trajectory(geometry: AxisGeometry, dataset: str, rng: np.random.Generator,
                       duration_s: float | None = None) -> Trajectory:
    """Trajectory of a dataset id on an axis.

    Parameters
    ----------
    geometry : AxisGeometry
        The axis.
    dataset : {"A", "B", "C", "D", "P"}
        Dataset id.
    rng : numpy.random.Generator
        Source of randomness (unused by B and D).
    duration_s : float, optional
        Length [s] of the random datasets A, C (default 120 s) and P (default
        60 s); B and D always cross the travel once back and forth per speed.

    Raises
    ------
    GreyboxError
        If the dataset id is unknown or the duration is not positive.
    """
    key = str(dataset).strip().upper()
    if key not in DATASETS:
        raise GreyboxError(f"unknown dataset {dataset!r}; choose from {', '.join(DATASETS)}")
    if duration_s is not None and not duration_s > 0:
        raise GreyboxError(f"duration must be positive, got {duration_s} s")
    if key in ("A", "C"):
        return random_window_trajectory(geometry, rng, duration_s=duration_s or 120.0)
    if key == "B":
        return constant_speed_trajectory(geometry, (600.0, 1800.0))
    if key == "D":
        return constant_speed_trajectory(geometry, (1200.0,))
    return presliding_trajectory(geometry, rng, duration_s=duration_s or 60.0)
