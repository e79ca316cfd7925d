"""Multi-sine axis motion shared by the SVR model tests."""

from __future__ import annotations

import numpy as np


def multisine_motion(rng: np.random.Generator, n: int, dt: float = 0.002):
    """Three sines with random frequencies (0.1-0.4 Hz) and phases around 200 mm.

    Draws the frequencies, then the phases, from ``rng``.

    Returns
    -------
    t, p, v, a : ndarray, shape (n,)
        Time [s], position [mm], velocity [mm/s], acceleration [mm/s^2] (exact derivatives).
    """
    t = np.arange(n) * dt
    freq = rng.uniform(0.1, 0.4, 3)
    phase = rng.uniform(0.0, 2 * np.pi, 3)
    amp = np.array([120.0, 50.0, 20.0])
    arg = 2 * np.pi * freq[:, None] * t + phase[:, None]
    p = 200.0 + (amp[:, None] * np.sin(arg)).sum(0)
    v = (amp[:, None] * 2 * np.pi * freq[:, None] * np.cos(arg)).sum(0)
    a = (-amp[:, None] * (2 * np.pi * freq[:, None]) ** 2 * np.sin(arg)).sum(0)
    return t, p, v, a
