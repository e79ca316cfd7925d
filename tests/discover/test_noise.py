"""Noise like a measured residual: AR fit by Levinson-Durbin, local level, simulation."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.discover.noise import ResidualNoise, levinson_durbin
from greybox.twin import CurrentNoise


def test_levinson_durbin_recovers_an_ar2_from_its_exact_autocovariance():
    phi1, phi2 = 0.6, 0.25
    # Yule-Walker: rho1 = phi1 / (1 - phi2), rho_k = phi1 rho_{k-1} + phi2 rho_{k-2}
    rho = [1.0, phi1 / (1.0 - phi2)]
    for _ in range(6):
        rho.append(phi1 * rho[-1] + phi2 * rho[-2])
    coefficients, variance = levinson_durbin(np.array(rho), 6)
    np.testing.assert_allclose(coefficients[2], [phi1, phi2], atol=1e-12)
    np.testing.assert_allclose(coefficients[6], [phi1, phi2, 0, 0, 0, 0], atol=1e-12)
    # innovation variance of a unit-variance AR(2): 1 - phi1 rho1 - phi2 rho2
    assert variance[2] == pytest.approx(1.0 - phi1 * rho[1] - phi2 * rho[2])
    assert variance[6] == pytest.approx(variance[2])


def test_fit_recovers_the_twin_noise_and_simulates_alike():
    rng = np.random.default_rng(0)
    noise = CurrentNoise(std_A=0.05, lag1_correlation=0.7)
    runs = [noise.sample(40000, rng), noise.sample(25000, rng)]
    model = ResidualNoise.fit(runs, [0.002, 0.002])
    assert model.lag1_correlation == pytest.approx(0.7, abs=0.02)
    assert model.describe()["rms"] == pytest.approx(0.05, rel=0.03)
    simulated = model.simulate(3, rng)
    assert [s.shape for s in simulated] == [(40000, 3), (25000, 3)]
    series = simulated[0][:, 0]
    assert np.std(series) == pytest.approx(0.05, rel=0.05)
    assert np.corrcoef(series[1:], series[:-1])[0, 1] == pytest.approx(0.7, abs=0.03)


def test_local_level_follows_a_residual_that_grows():
    rng = np.random.default_rng(1)
    level = np.where(np.arange(20000) < 10000, 0.02, 0.1)
    residual = rng.normal(size=level.size) * level
    model = ResidualNoise.fit([residual], [0.002])
    simulated = model.simulate(1, rng)[0][:, 0]
    assert np.std(simulated[:9000]) == pytest.approx(0.02, rel=0.1)
    assert np.std(simulated[11000:]) == pytest.approx(0.1, rel=0.1)
    assert model.ar.size <= 2  # white noise needs (almost) no AR terms


def test_zero_residual_is_refused():
    with pytest.raises(ValueError, match="zero"):
        ResidualNoise.fit([np.zeros(100)], [0.002])
