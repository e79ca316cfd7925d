"""Multi-sine runs of axes with known friction (Coulomb-viscous or GMS), inertia, offset and position ripple,
shared by the SVR and GMS+SVR tests."""

from __future__ import annotations

import numpy as np
from multisine import multisine_motion

from greybox.data.log import AxisLog
from greybox.models.friction.gms import GMSModel, simulate_gms

J_TRUE = 2e-4  # A s^2/mm
OFFSET_TRUE = 0.1  # A


def sweep_run(seed, n=6000, dt=0.002, ripple=0.3, noise=0.02):
    """Multi-sine motion over ~0..400 mm; current = inertia + friction + ripple(p) + offset."""
    rng = np.random.default_rng(seed)
    t, p, v, a = multisine_motion(rng, n, dt)
    friction = 0.8 * np.tanh(v / 30.0) + 0.003 * v + ripple * np.sin(2 * np.pi * p / 150.0)
    current = J_TRUE * a + friction + OFFSET_TRUE + noise * rng.standard_normal(n)
    return AxisLog(time=t, position=p, effort=current,
                   velocity=v, acceleration=a, extras={"truth_friction_A": friction})


FIXED = dict(C=3.0, epsilon=0.01, gamma=5.0, optimize=False, n_subset=800)


TRUTH_GMS = dict(alpha=np.array([0.1, 0.2, 0.3, 0.4]), k=np.full(4, 80.0), C=2.0, sigma=0.01,
                 s_0=0.01, s_inf=0.006, v_s=5.0, mu=0.003)
RIPPLE_A = 0.3  # amplitude of the position-dependent friction the GMS model cannot represent


def gms_run(seed, n=20000, ripple=RIPPLE_A, noise=0.02):
    """Multi-sine motion; current = inertia + GMS friction + ripple(position) + noise."""
    rng = np.random.default_rng(seed)
    t, p, v, a = multisine_motion(rng, n)
    friction, _ = simulate_gms(v, 0.002, **TRUTH_GMS)
    current = 2e-4 * a + friction + ripple * np.sin(2 * np.pi * p / 150.0) + noise * rng.standard_normal(n)
    return AxisLog(time=t, position=p, effort=current, velocity=v, acceleration=a)


def quick_gms():
    return GMSModel(n_starts=1, max_iter=60)


SVR_FIXED = dict(C=3.0, epsilon=0.01, gamma=1.0, optimize=False, n_subset=800)
