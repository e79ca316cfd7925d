"""Autocorrelated measurement noise of the motor current."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy.signal import lfilter

from ..errors import GreyboxError

__all__ = ["CurrentNoise"]


@dataclass(frozen=True)
class CurrentNoise:
    """Stationary first-order autoregressive (AR(1)) noise on the logged current.

    ``e[k] = phi e[k-1] + sqrt(1 - phi^2) std w[k]`` with white standard normal
    ``w``: a first-order low-pass of white noise, sampled at the log step.

    Parameters
    ----------
    std_A : float, default 0.09
        Standard deviation [A] of the noise.
    lag1_correlation : float, default 0.7
        Correlation ``phi`` of two consecutive samples, in [0, 1).
    """

    std_A: float = 0.09
    lag1_correlation: float = 0.7

    def __post_init__(self):
        if self.std_A < 0:
            raise GreyboxError(f"noise: standard deviation must be non-negative, got {self.std_A} A")
        if not 0.0 <= self.lag1_correlation < 1.0:
            raise GreyboxError(f"noise: lag-1 correlation must be in [0, 1), got {self.lag1_correlation}")

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """Draw ``n`` consecutive noise samples [A], stationary from the first one.

        Parameters
        ----------
        n : int
            Number of samples.
        rng : numpy.random.Generator
            Source of the white innovations.
        """
        phi = self.lag1_correlation
        innovation = rng.standard_normal(n) * self.std_A
        innovation[1:] *= np.sqrt(1.0 - phi * phi)
        return lfilter([1.0], [1.0, -phi], innovation)

    def to_dict(self) -> dict:
        """JSON-serialisable settings."""
        return asdict(self)
