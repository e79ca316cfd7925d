"""Parameters with one value per direction of motion: the shared helpers of the asymmetric models.

A direction-dependent parameter is a pair ``(positive motion, negative
motion)``; a single number serves both directions (the symmetric models). The
viscous term ``mu(v) v`` takes ``mu+`` for ``v > 0`` and ``mu-`` for ``v < 0``;
its regressors are ``v [v > 0]`` and ``v [v < 0]``.
"""

from __future__ import annotations

import numpy as np

from ...errors import ParameterError

__all__ = ["direction_pair", "viscous_columns"]


def direction_pair(value, name: str) -> np.ndarray:
    """``value`` as a pair (positive motion, negative motion): a number is used for both directions.

    Parameters
    ----------
    value : float or (float, float)
        One value, or one per direction.
    name : str
        Name of the parameter, for the error message.

    Returns
    -------
    ndarray, shape (2,)
        A new array.

    Raises
    ------
    ParameterError
        If ``value`` is neither a number nor two numbers.
    """
    pair = np.asarray(value, dtype=float)
    if pair.ndim == 0:
        return np.full(2, float(pair))
    if pair.shape != (2,):
        raise ParameterError(f"{name} must be a number or a pair (positive, negative motion), got shape {pair.shape}")
    return pair.copy()


def viscous_columns(velocity: np.ndarray, asymmetric: bool) -> tuple[list[np.ndarray], list[str]]:
    """Regressors of the viscous term and their coefficient names.

    Parameters
    ----------
    velocity : ndarray, shape (n,)
        Velocity [mm/s].
    asymmetric : bool
        One coefficient per direction of motion.

    Returns
    -------
    columns : list of ndarray
        ``[v]``, or ``[v [v > 0], v [v < 0]]`` when ``asymmetric`` [mm/s].
    names : list of str
        ``["viscous"]``, or ``["viscous_pos", "viscous_neg"]``.
    """
    if asymmetric:
        return [np.maximum(velocity, 0.0), np.minimum(velocity, 0.0)], ["viscous_pos", "viscous_neg"]
    return [velocity], ["viscous"]
