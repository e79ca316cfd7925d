"""Noise like a measured residual, for simulating data in which nothing is missing.

:class:`ResidualNoise` describes a residual as an autoregressive (AR) process
of unit variance scaled by a slowly varying local level:

    e[k] = s[k] u[k],   u[k] = phi_1 u[k-1] + ... + phi_p u[k-p] + w[k],

with ``s`` the moving RMS of the residual over a window (``level_window_s``,
1 s by default) and ``phi`` fitted to ``r / s`` by the Yule-Walker equations
(Levinson-Durbin recursion), the order ``p`` chosen by Akaike's criterion.
Simulated series therefore keep the residual's autocorrelation and where in
the log it is large (near reversals, say). Runs are simulated separately,
each from the stationary state.

The coefficients fitted to a finite residual are uncertain; their
large-sample distribution is normal with covariance ``sigma_w^2 Gamma_p^-1 / n``
(``Gamma_p`` the autocovariance matrix of order ``p``, ``n`` the number of
samples). Each simulated series draws its own coefficients from it, so that
the simulated noise varies as much as noise consistent with the residual
does (a fixed estimate would make the simulated low-frequency power too
certain, and tests calibrated on it slightly too eager).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
import scipy.linalg
from scipy.ndimage import uniform_filter1d
from scipy.signal import lfilter

__all__ = ["ResidualNoise", "levinson_durbin"]

#: Local level never below this fraction of the overall RMS (keeps r / s finite).
_LEVEL_FLOOR = 0.05


def levinson_durbin(autocovariance: np.ndarray, order: int) -> tuple[list[np.ndarray], np.ndarray]:
    """AR coefficients of every order up to ``order`` from an autocovariance sequence.

    Parameters
    ----------
    autocovariance : ndarray, shape (>= order + 1,)
        ``c[0], c[1], ...`` (``c[0] > 0``).
    order : int
        Highest order.

    Returns
    -------
    coefficients : list of ndarray
        ``coefficients[p]`` holds ``phi_1..phi_p`` (empty for p = 0).
    innovation_variance : ndarray, shape (order + 1,)
        Variance of the innovation ``w`` at each order.
    """
    c = np.asarray(autocovariance, dtype=float)
    phi = np.empty(0)
    coefficients = [phi]
    variance = np.empty(order + 1)
    variance[0] = c[0]
    for p in range(1, order + 1):
        reflection = (c[p] - phi @ c[p - 1:0:-1]) / variance[p - 1]
        phi = np.concatenate((phi - reflection * phi[::-1], [reflection]))
        variance[p] = variance[p - 1] * (1.0 - reflection * reflection)
        coefficients.append(phi)
    return coefficients, variance


def _autocovariance(series: Sequence[np.ndarray], max_lag: int) -> np.ndarray:
    """Autocovariance at lags 0..max_lag pooled over series (biased estimate, means removed)."""
    total = np.zeros(max_lag + 1)
    count = 0
    for values in series:
        x = values - values.mean()
        for lag in range(min(max_lag, x.size - 1) + 1):
            total[lag] += x[lag:] @ x[:x.size - lag]
        count += x.size
    return total / count


@dataclass(frozen=True)
class ResidualNoise:
    """AR noise with a local level, fitted to residuals of one or several runs.

    Attributes
    ----------
    ar : ndarray, shape (p,)
        AR coefficients ``phi_1..phi_p`` of the normalised residual.
    innovation_std : float
        Standard deviation of ``w`` (the normalised process has unit variance).
    levels : tuple of ndarray
        Local level ``s`` of each run, in the unit of the residual (A for a current log, N or Nm for a load log).
    ar_covariance : ndarray, shape (p, p)
        Covariance of the fitted coefficients (zeros: treat them as exact).
    """

    ar: np.ndarray
    innovation_std: float
    levels: tuple
    ar_covariance: np.ndarray | None = None

    @classmethod
    def fit(cls, residuals: Sequence[np.ndarray], sample_times: Sequence[float], *, max_order: int = 20,
            level_window_s: float = 1.0) -> "ResidualNoise":
        """Fit to the residual of each run (in the log's effort unit: A, N or Nm).

        Parameters
        ----------
        residuals : sequence of ndarray
            Residual of each run.
        sample_times : sequence of float
            Sample time of each run [s].
        max_order : int, default 20
            Highest AR order tried.
        level_window_s : float, default 1.0
            Window of the moving RMS that gives the local level [s].
        """
        overall = float(np.sqrt(np.mean(np.concatenate(residuals) ** 2)))
        if not overall > 0.0:
            raise ValueError("the residual is zero: no noise to describe")
        levels, normalised = [], []
        for r, step in zip(residuals, sample_times):
            width = max(1, min(r.size, int(round(level_window_s / step))))
            level = np.sqrt(uniform_filter1d(r * r, width, mode="nearest"))
            level = np.maximum(level, _LEVEL_FLOOR * overall)
            levels.append(level)
            normalised.append(r / level)
        order = min(max_order, min(r.size for r in residuals) // 10)
        covariance = _autocovariance(normalised, order)
        coefficients, variance = levinson_durbin(covariance, order)
        n = sum(r.size for r in residuals)
        aic = n * np.log(np.maximum(variance, np.finfo(float).tiny)) + 2.0 * np.arange(order + 1)
        best = int(np.argmin(aic))
        # unit variance of the normalised process
        innovation_std = float(np.sqrt(variance[best] / covariance[0]))
        gamma = scipy.linalg.toeplitz(covariance[:best]) if best else np.zeros((0, 0))
        ar_covariance = variance[best] * np.linalg.inv(gamma) / n if best else np.zeros((0, 0))
        return cls(coefficients[best].copy(), innovation_std, tuple(levels), ar_covariance)

    @property
    def lag1_correlation(self) -> float:
        """Correlation of consecutive samples of the normalised process."""
        if self.ar.size == 0:
            return 0.0
        return float(_ar_autocorrelation(self.ar, 1)[1])

    def draw_coefficients(self, n_replicates: int, rng: np.random.Generator) -> np.ndarray:
        """AR coefficients of each replicate, shape ``(n_replicates, p)``: stationary draws around ``ar``.

        Parameters
        ----------
        n_replicates : int
            Number of coefficient sets to draw.
        rng : numpy.random.Generator
            Source of the draws (not used when ``ar_covariance`` is None or the order is 0).
        """
        if self.ar_covariance is None or self.ar.size == 0:
            return np.tile(self.ar, (n_replicates, 1))
        draws = np.empty((n_replicates, self.ar.size))
        root = np.linalg.cholesky(self.ar_covariance + 1e-15 * np.eye(self.ar.size))
        for i in range(n_replicates):
            for _ in range(20):
                candidate = self.ar + root @ rng.standard_normal(self.ar.size)
                if _stationary(candidate):
                    break
            else:
                candidate = self.ar
            draws[i] = candidate
        return draws

    def simulate(self, n_replicates: int, rng: np.random.Generator) -> list[np.ndarray]:
        """Simulated noise, one array ``(n_i, n_replicates)`` per run, in the unit of the fitted residual.

        Each replicate has its own coefficients (:meth:`draw_coefficients`),
        the same in every run, and unit variance before the level is applied.

        Parameters
        ----------
        n_replicates : int
            Number of independent noise series per run.
        rng : numpy.random.Generator
            Source of the coefficients and innovations.
        """
        coefficients = self.draw_coefficients(n_replicates, rng)
        burn_in = 10 * self.ar.size + 200
        out = []
        for level in self.levels:
            innovation = rng.standard_normal((level.size + burn_in, n_replicates))
            series = np.empty((level.size, n_replicates))
            for j, phi in enumerate(coefficients):
                scale = _unit_variance_innovation(phi)
                series[:, j] = lfilter([scale], np.concatenate(([1.0], -phi)), innovation[:, j])[burn_in:]
            out.append(series * level[:, None])
        return out

    def describe(self) -> dict:
        """Summary for reports: AR order, lag-1 correlation, RMS of the level (unit of the residual)."""
        level = np.concatenate(self.levels)
        return {"ar_order": int(self.ar.size), "lag1_correlation": self.lag1_correlation,
                "rms": float(np.sqrt(np.mean(level ** 2)))}


def _stationary(ar: np.ndarray) -> bool:
    """True if the roots of the characteristic polynomial lie inside the unit circle (stationary AR)."""
    return bool(np.all(np.abs(np.roots(np.concatenate(([1.0], -ar)))) < 1.0 - 1e-6)) if ar.size else True


def _unit_variance_innovation(ar: np.ndarray) -> float:
    """Innovation standard deviation that gives the AR process unit variance."""
    if ar.size == 0:
        return 1.0
    response = lfilter([1.0], np.concatenate(([1.0], -ar)), np.r_[1.0, np.zeros(4000)])
    return float(1.0 / np.sqrt(response @ response))


def _ar_autocorrelation(ar: np.ndarray, max_lag: int) -> np.ndarray:
    """Autocorrelation of a stationary AR process at lags 0..max_lag (from a long impulse response)."""
    response = lfilter([1.0], np.concatenate(([1.0], -ar)), np.r_[1.0, np.zeros(4000)])
    c = np.array([response[lag:] @ response[:response.size - lag] for lag in range(max_lag + 1)])
    return c / c[0]
