"""Jerk-limited motion profiles of a feed axis, built from analytic pieces.

A :class:`MotionProfile` is a chain of pieces with closed-form position,
velocity and acceleration, so it can be evaluated on any time grid (the
plant's fine integration step or the 2 ms log step) without numerical
integration:

* constant velocity (a dwell when the velocity is zero),
* cosine velocity ramps ``v(t) = v0 + (v1 - v0) (1 - cos(pi t / T)) / 2``,
  whose peak acceleration ``pi |dv| / (2 T)`` and peak jerk
  ``pi^2 |dv| / (2 T^2)`` are kept below :class:`MotionLimits`,
* enveloped sine oscillations ``x(t) = c + A e(t) sin(w t)`` around a centre,
  whose envelope ``e`` rises from and falls back to zero with ``sin^2`` ramps
  so that the oscillation starts and ends at rest without an acceleration step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["MotionLimits", "MotionProfile"]


@dataclass(frozen=True)
class MotionLimits:
    """Acceleration and jerk limits of the axis.

    Parameters
    ----------
    max_acceleration_mm_s2 : float, default 1500.0
        Largest acceleration [mm/s^2] of a velocity ramp.
    max_jerk_mm_s3 : float, default 60000.0
        Largest jerk [mm/s^3] of a velocity ramp.
    """

    max_acceleration_mm_s2: float = 1500.0
    max_jerk_mm_s3: float = 60000.0

    def ramp_duration(self, velocity_change_mm_s: float) -> float:
        """Shortest cosine-ramp duration [s] for a velocity change [mm/s] within the limits.

        Parameters
        ----------
        velocity_change_mm_s : float
            Velocity change [mm/s]; only its magnitude counts (0 gives 0 s).
        """
        dv = abs(velocity_change_mm_s)
        if dv == 0.0:
            return 0.0
        by_acceleration = math.pi * dv / (2.0 * self.max_acceleration_mm_s2)
        by_jerk = math.pi * math.sqrt(dv / (2.0 * self.max_jerk_mm_s3))
        return max(by_acceleration, by_jerk)

    def ramps_distance(self, speeds_mm_s) -> float:
        """Distance [mm] covered by the ramps of a move through the given speed levels.

        The move starts at rest, visits the positive speeds [mm/s] in order and
        ends at rest; the cruise phases at each level are not included.

        Parameters
        ----------
        speeds_mm_s : sequence of float
            Speed levels [mm/s] in the order visited; their magnitudes are used.
        """
        levels = np.concatenate(([0.0], np.abs(np.asarray(speeds_mm_s, dtype=float)), [0.0]))
        return float(
            sum(0.5 * (lo + hi) * self.ramp_duration(hi - lo) for lo, hi in zip(levels[:-1], levels[1:]))
        )


@dataclass(frozen=True)
class _Constant:
    start_s: float
    duration_s: float
    start_mm: float
    velocity_mm_s: float

    @property
    def end_mm(self) -> float:
        return self.start_mm + self.velocity_mm_s * self.duration_s

    def evaluate(self, tau):
        x = self.start_mm + self.velocity_mm_s * tau
        return x, np.full_like(tau, self.velocity_mm_s), np.zeros_like(tau)


@dataclass(frozen=True)
class _Ramp:
    start_s: float
    duration_s: float
    start_mm: float
    from_mm_s: float
    to_mm_s: float

    @property
    def end_mm(self) -> float:
        return self.start_mm + 0.5 * (self.from_mm_s + self.to_mm_s) * self.duration_s

    def evaluate(self, tau):
        duration, dv = self.duration_s, self.to_mm_s - self.from_mm_s
        phase = np.pi * tau / duration
        x = self.start_mm + self.from_mm_s * tau + 0.5 * dv * (tau - duration / np.pi * np.sin(phase))
        v = self.from_mm_s + 0.5 * dv * (1.0 - np.cos(phase))
        a = 0.5 * dv * np.pi / duration * np.sin(phase)
        return x, v, a


@dataclass(frozen=True)
class _Sine:
    start_s: float
    duration_s: float
    start_mm: float
    amplitude_mm: float
    angular_frequency_rad_s: float
    envelope_ramp_s: float

    @property
    def end_mm(self) -> float:
        return self.start_mm

    def _envelope(self, tau):
        ramp, total = self.envelope_ramp_s, self.duration_s
        e, de, dde = np.ones_like(tau), np.zeros_like(tau), np.zeros_like(tau)
        k = np.pi / ramp
        rising = tau < ramp
        falling = tau > total - ramp
        for mask, s, sign in ((rising, tau, 1.0), (falling, total - tau, -1.0)):
            s = s[mask]
            e[mask] = np.sin(0.5 * k * s) ** 2
            de[mask] = sign * 0.5 * k * np.sin(k * s)
            dde[mask] = 0.5 * k * k * np.cos(k * s)
        return e, de, dde

    def evaluate(self, tau):
        w, amp = self.angular_frequency_rad_s, self.amplitude_mm
        e, de, dde = self._envelope(tau)
        s, c = np.sin(w * tau), np.cos(w * tau)
        x = self.start_mm + amp * e * s
        v = amp * (de * s + e * w * c)
        a = amp * (dde * s + 2.0 * de * w * c - e * w * w * s)
        return x, v, a

    def peak_speed_per_mm(self) -> float:
        """Peak speed [mm/s] of this oscillation per mm of amplitude."""
        period = 2.0 * np.pi / self.angular_frequency_rad_s
        tau = np.linspace(0.0, self.duration_s, int(self.duration_s / period * 400) + 2)
        unit = _Sine(0.0, self.duration_s, 0.0, 1.0, self.angular_frequency_rad_s, self.envelope_ramp_s)
        return float(np.max(np.abs(unit.evaluate(tau)[1])))


class MotionProfile:
    """A chain of analytic motion pieces, built by appending moves.

    Parameters
    ----------
    start_position_mm : float
        Position [mm] at time 0; the axis starts at rest.
    limits : MotionLimits, optional
        Acceleration and jerk limits of the velocity ramps.

    Notes
    -----
    The builder tracks the end time, position and velocity of the chain.
    Every piece starts where the previous one ended, so position, velocity
    and acceleration are continuous.
    """

    def __init__(self, start_position_mm: float, limits: MotionLimits | None = None):
        self.limits = limits if limits is not None else MotionLimits()
        self._pieces: list = []
        self.time_s = 0.0
        self.position_mm = float(start_position_mm)
        self.velocity_mm_s = 0.0
        self.start_position_mm = float(start_position_mm)

    # ------------------------------------------------------------ building
    def _append(self, piece) -> None:
        if piece.duration_s <= 0.0:
            return
        self._pieces.append(piece)
        self.time_s = piece.start_s + piece.duration_s
        self.position_mm = piece.end_mm

    def hold(self, duration_s: float) -> None:
        """Keep the present velocity for ``duration_s`` [s] (a dwell when at rest).

        Parameters
        ----------
        duration_s : float
            Length [s] of the piece; nothing is appended if it is not positive.
        """
        self._append(_Constant(self.time_s, float(duration_s), self.position_mm, self.velocity_mm_s))

    def ramp(self, velocity_mm_s: float) -> None:
        """Change the velocity to ``velocity_mm_s`` [mm/s] as fast as the limits allow.

        Parameters
        ----------
        velocity_mm_s : float
            Signed target velocity [mm/s].
        """
        duration = self.limits.ramp_duration(velocity_mm_s - self.velocity_mm_s)
        self._append(_Ramp(self.time_s, duration, self.position_mm, self.velocity_mm_s, float(velocity_mm_s)))
        self.velocity_mm_s = float(velocity_mm_s)

    def move(self, distance_mm: float, speeds_mm_s, cruise_fractions=None) -> None:
        """Move by ``distance_mm`` from rest to rest through one or more speed levels.

        Parameters
        ----------
        distance_mm : float
            Signed distance [mm] of the move.
        speeds_mm_s : sequence of float
            Positive cruise speeds [mm/s], visited in order.
        cruise_fractions : sequence of float, optional
            Relative lengths of the cruise phases at each level (equal by default).

        Raises
        ------
        ValueError
            If the ramps alone between the speed levels are longer than the move.
        """
        if self.velocity_mm_s != 0.0:
            raise ValueError("a move starts at rest")
        speeds = np.asarray(speeds_mm_s, dtype=float)
        if speeds.ndim != 1 or speeds.size == 0 or np.any(speeds <= 0.0):
            raise ValueError("speeds must be a non-empty sequence of positive values")
        fractions = np.ones_like(speeds) if cruise_fractions is None else np.asarray(cruise_fractions, float)
        direction = 1.0 if distance_mm >= 0.0 else -1.0
        ramp_distance = self.limits.ramps_distance(speeds)
        cruise_distance = abs(distance_mm) - ramp_distance
        if cruise_distance < 0.0:
            raise ValueError(f"move of {abs(distance_mm):.4f} mm is shorter than its ramps ({ramp_distance:.4f} mm)")
        weights = fractions / fractions.sum()
        for speed, weight in zip(speeds, weights):
            self.ramp(direction * speed)
            self.hold(weight * cruise_distance / speed)
        self.ramp(0.0)

    def oscillate(self, amplitude_peak_speed_mm_s: float, angular_frequency_rad_s: float,
                  periods: float, ramp_periods: float = 1.0) -> float:
        """Oscillate around the present position, starting and ending at rest.

        The amplitude is chosen so that the peak speed equals
        ``amplitude_peak_speed_mm_s`` [mm/s]; it is returned [mm].

        Parameters
        ----------
        amplitude_peak_speed_mm_s : float
            Peak speed [mm/s] of the oscillation.
        angular_frequency_rad_s : float
            Angular frequency [rad/s] of the sine.
        periods : float
            Length of the oscillation in periods, envelope ramps included.
        ramp_periods : float, default 1.0
            Length of each envelope ramp in periods.
        """
        if self.velocity_mm_s != 0.0:
            raise ValueError("an oscillation starts at rest")
        period = 2.0 * np.pi / angular_frequency_rad_s
        shape = _Sine(self.time_s, periods * period, self.position_mm, 1.0, angular_frequency_rad_s,
                      ramp_periods * period)
        amplitude = amplitude_peak_speed_mm_s / shape.peak_speed_per_mm()
        self._append(_Sine(self.time_s, periods * period, self.position_mm, amplitude,
                           angular_frequency_rad_s, ramp_periods * period))
        return amplitude

    # ---------------------------------------------------------- evaluation
    @property
    def duration_s(self) -> float:
        """End time [s] of the profile."""
        return self.time_s

    def cruise_speeds_mm_s(self) -> np.ndarray:
        """Speeds [mm/s] of all constant-velocity pieces in motion and peak speeds of oscillations."""
        speeds = []
        for piece in self._pieces:
            if isinstance(piece, _Constant) and piece.velocity_mm_s != 0.0:
                speeds.append(abs(piece.velocity_mm_s))
            elif isinstance(piece, _Sine):
                speeds.append(piece.amplitude_mm * piece.peak_speed_per_mm())
        return np.asarray(speeds)

    def evaluate(self, time_s) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position [mm], velocity [mm/s] and acceleration [mm/s^2] at sorted times [s].

        Times after the end of the profile keep its final state (at rest).

        Parameters
        ----------
        time_s : array_like, shape (n,)
            Times [s] in ascending order.

        Returns
        -------
        x, v, a : ndarray, shape (n,)
            Position [mm], velocity [mm/s] and acceleration [mm/s^2].
        """
        t = np.asarray(time_s, dtype=float)
        x = np.full_like(t, self.position_mm)
        v = np.full_like(t, self.velocity_mm_s)
        a = np.zeros_like(t)
        if not self._pieces:
            return x, v, a
        starts = np.array([p.start_s for p in self._pieces])
        bounds = np.searchsorted(t, starts, side="left")
        ends = np.append(bounds[1:], np.searchsorted(t, self.time_s, side="right"))
        x[: bounds[0]] = self.start_position_mm
        v[: bounds[0]] = 0.0
        for piece, lo, hi in zip(self._pieces, bounds, ends):
            if hi > lo:
                tau = t[lo:hi] - piece.start_s
                x[lo:hi], v[lo:hi], a[lo:hi] = piece.evaluate(tau)
        return x, v, a
