"""What the CNC records: encoder position, actual velocity and quantised current."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..errors import GreyboxError

__all__ = ["Sensors", "quantise"]


def _decimals(step: float) -> int:
    for decimals in range(16):
        if abs(round(step, decimals) - step) <= 1e-12 * step:
            return decimals
    return 16


def quantise(values, step: float) -> np.ndarray:
    """Round ``values`` to multiples of ``step``, stored as the shortest decimal numbers.

    Parameters
    ----------
    values : array_like
        Values to round, in any unit.
    step : float
        Quantisation step, positive, in the unit of ``values``.
    """
    quantised = np.round(np.asarray(values, dtype=float) / step) * step
    return np.round(quantised, _decimals(step)) + 0.0


@dataclass(frozen=True)
class Sensors:
    """Resolution of the logged channels.

    Parameters
    ----------
    position_resolution_mm : float, default 1e-4
        Encoder resolution [mm] (0.1 um).
    current_resolution_A : float, default 1e-3
        Resolution [A] of the logged current.

    Notes
    -----
    The logged (actual) velocity is the encoder position difference over the
    previous sample interval divided by the sample time, as a CNC computes it:
    it lags the true velocity by half a sample and is quantised to
    ``position_resolution_mm / sample_time``. Acceleration is not logged.
    """

    position_resolution_mm: float = 1e-4
    current_resolution_A: float = 1e-3

    def __post_init__(self):
        if self.position_resolution_mm <= 0 or self.current_resolution_A <= 0:
            raise GreyboxError("sensors: resolutions must be positive")

    def position(self, position_mm) -> np.ndarray:
        """Encoder position [mm].

        Parameters
        ----------
        position_mm : array_like
            True position [mm]; rounded to the encoder resolution.
        """
        return quantise(position_mm, self.position_resolution_mm)

    def velocity(self, encoder_position_mm, sample_time_s: float) -> np.ndarray:
        """Actual velocity [mm/s] from encoder positions; zero at the first sample (the axis starts at rest).

        Parameters
        ----------
        encoder_position_mm : array_like, shape (n,)
            Encoder positions [mm] at the log samples (e.g. from :meth:`position`).
        sample_time_s : float
            Log sample time [s].
        """
        step = np.diff(np.asarray(encoder_position_mm, dtype=float), prepend=encoder_position_mm[0])
        return quantise(step / sample_time_s, self.position_resolution_mm / sample_time_s)

    def current(self, current_A) -> np.ndarray:
        """Logged current [A].

        Parameters
        ----------
        current_A : array_like
            Current [A] before logging; rounded to the current resolution.
        """
        return quantise(current_A, self.current_resolution_A)

    def to_dict(self) -> dict:
        """JSON-serialisable settings."""
        return asdict(self)
