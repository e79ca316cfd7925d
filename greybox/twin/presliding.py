"""Pre-sliding excitation of Tjahjowidodo et al. (2005).

A band-limited random velocity (cut-off 4 Hz) multiplied by the first three
non-zero Fourier terms of a rectangular wave of period 10 s,

    e(t) = (4 / pi) (sin(w t) + sin(3 w t) / 3 + sin(5 w t) / 5),  w = 2 pi / 10 s.

Where the envelope is near zero the motion stays in the pre-sliding regime
(displacements of a few um with frequent reversals); where it is large the
axis slides back and forth.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.interpolate import CubicSpline

__all__ = ["band_limited_noise", "rectangular_envelope", "PreslidingExcitation"]


def band_limited_noise(rng: np.random.Generator, n: int, step_s: float, low_hz: float, high_hz: float) -> np.ndarray:
    """Gaussian noise of unit RMS whose spectrum is confined to ``[low_hz, high_hz]`` (ideal band-pass).

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the white noise that is filtered.
    n : int
        Number of samples.
    step_s : float
        Sample spacing [s].
    low_hz, high_hz : float
        Lower and upper band edge [Hz]; FFT bins outside are set to zero.
    """
    spectrum = np.fft.rfft(rng.standard_normal(n))
    frequency = np.fft.rfftfreq(n, step_s)
    spectrum[(frequency < low_hz) | (frequency > high_hz)] = 0.0
    noise = np.fft.irfft(spectrum, n)
    return noise / np.sqrt(np.mean(noise**2))


def rectangular_envelope(time_s, period_s: float = 10.0) -> np.ndarray:
    """First three non-zero Fourier terms of a unit rectangular wave of period ``period_s`` [s].

    Parameters
    ----------
    time_s : array_like
        Times [s].
    period_s : float, default 10.0
        Period [s] of the rectangular wave.
    """
    w = 2.0 * np.pi / period_s
    t = np.asarray(time_s, dtype=float)
    return 4.0 / np.pi * (np.sin(w * t) + np.sin(3.0 * w * t) / 3.0 + np.sin(5.0 * w * t) / 5.0)


class PreslidingExcitation:
    """A velocity given on a uniform knot grid, interpolated by a cubic spline.

    Parameters
    ----------
    centre_mm : float
        Position [mm] at time 0.
    knot_step_s : float
        Spacing [s] of the velocity knots.
    velocity_knots_mm_s : array_like
        Velocity [mm/s] at the knots; the first and last are zero.
    settings : dict, optional
        Description of how the knots were made (kept for :meth:`description`).

    Notes
    -----
    Position is the spline's antiderivative and acceleration its derivative,
    so the three are consistent on any time grid.
    """

    def __init__(self, centre_mm: float, knot_step_s: float, velocity_knots_mm_s, settings: dict | None = None):
        velocity = np.asarray(velocity_knots_mm_s, dtype=float)
        knots = np.arange(velocity.size) * knot_step_s
        self.centre_mm = float(centre_mm)
        self.duration_s = float(knots[-1])
        self._velocity = CubicSpline(knots, velocity)
        self._position = self._velocity.antiderivative()
        self._acceleration = self._velocity.derivative()
        self._settings = dict(settings or {})

    @classmethod
    def random(cls, rng: np.random.Generator, centre_mm: float, duration_s: float = 60.0,
               velocity_rms_mm_s: float = 0.2, cutoff_hz: float = 4.0, envelope_period_s: float = 10.0,
               highpass_hz: float = 0.1, max_excursion_mm: float = 20.0,
               knot_step_s: float = 0.005) -> "PreslidingExcitation":
        """Draw an excitation.

        Parameters
        ----------
        rng : numpy.random.Generator
            Source of the random velocity.
        centre_mm : float
            Start position [mm].
        duration_s : float, default 60.0
            Length [s], rounded up to whole envelope periods so the motion ends at rest.
        velocity_rms_mm_s : float, default 0.2
            RMS [mm/s] of the random velocity before the envelope.
        cutoff_hz : float, default 4.0
            Cut-off frequency [Hz] of the random velocity (ideal band-pass by FFT).
        envelope_period_s : float, default 10.0
            Period [s] of the rectangular envelope.
        highpass_hz : float, default 0.1
            Lower band edge [Hz] that keeps the position from drifting.
        max_excursion_mm : float, default 20.0
            The velocity is scaled down if the position would leave ``centre +- max_excursion``.
        knot_step_s : float, default 0.005
            Spacing [s] of the velocity knots.
        """
        periods = max(1, math.ceil(duration_s / envelope_period_s - 1e-9))
        n = int(round(periods * envelope_period_s / knot_step_s)) + 1
        time = np.arange(n) * knot_step_s
        random_velocity = velocity_rms_mm_s * band_limited_noise(rng, n, knot_step_s, highpass_hz, cutoff_hz)
        velocity = random_velocity * rectangular_envelope(time, envelope_period_s)
        velocity[0] = velocity[-1] = 0.0
        excursion = np.max(np.abs(np.concatenate(([0.0], np.cumsum(velocity[1:] + velocity[:-1]) * 0.5 * knot_step_s))))
        scale = min(1.0, 0.95 * max_excursion_mm / excursion) if excursion > 0 else 1.0
        settings = {
            "velocity_rms_mm_s": velocity_rms_mm_s * scale,
            "cutoff_hz": cutoff_hz,
            "highpass_hz": highpass_hz,
            "envelope_period_s": envelope_period_s,
            "knot_step_s": knot_step_s,
        }
        return cls(centre_mm, knot_step_s, velocity * scale, settings)

    def description(self) -> dict:
        """JSON-serialisable summary of the excitation."""
        return {"duration_s": self.duration_s, "centre_mm": self.centre_mm, **self._settings}

    def evaluate(self, time_s) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position [mm], velocity [mm/s] and acceleration [mm/s^2] at times [s]; at rest after the end.

        Parameters
        ----------
        time_s : array_like
            Times [s], in any order; times before 0 are evaluated at 0.
        """
        t = np.clip(np.asarray(time_s, dtype=float), 0.0, self.duration_s)
        moving = np.asarray(time_s) < self.duration_s
        x = self.centre_mm + self._position(t)
        v = np.where(moving, self._velocity(t), 0.0)
        a = np.where(moving, self._acceleration(t), 0.0)
        return x, v, a
