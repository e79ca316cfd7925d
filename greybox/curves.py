"""The Stribeck curve on arrays, the one NumPy copy that models, fits and initial guesses evaluate.

The compiled kernels evaluate the same curve per sample
(:func:`greybox.friction.kernels.stribeck_at`). This module imports nothing
of greybox, so that every layer (identification included) may use it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["stribeck_curve"]


def stribeck_curve(velocity, s_0: float, s_inf: float, v_s: float) -> np.ndarray:
    """Decaying Stribeck curve ``s(v) = s_inf + (s_0 - s_inf) exp(-|v| / v_s)``.

    Parameters
    ----------
    velocity : array_like
        Velocity [mm/s].
    s_0 : float
        Value at rest (static friction level, or GMS break-away deflection).
    s_inf : float
        Value at high speed (Coulomb level), same unit as ``s_0``.
    v_s : float
        Stribeck velocity [mm/s], positive.

    Returns
    -------
    ndarray
        ``s(v)`` in the unit of ``s_0``; even in ``v``.
    """
    return s_inf + (s_0 - s_inf) * np.exp(-np.abs(np.asarray(velocity, dtype=float)) / v_s)
