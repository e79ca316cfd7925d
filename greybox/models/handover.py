"""Hand-over of a kernel model's data-driven correction to its physical part outside the training region.

An RBF expansion far from its support vectors falls back to its intercept,
and between the data and "far" it follows whatever its last kernels do: it
extrapolates on its own. The kernel models (:mod:`greybox.models.svr`,
:mod:`greybox.models.gmssvr`) therefore weigh their correction by

.. math:: w(x) = 1 - t^2 (3 - 2 t), \\qquad t = \\min(d(x) / h, 1),

where :math:`d(x)` is the Euclidean distance of the sample from the box of
the training inputs (the lowest and highest value of each input over the
training data), both in the kernel's own coordinates (standardised, times the
square root of each input's kernel weight), and :math:`h` the hand-over width
(:data:`HANDOVER_LENGTHS` kernel length scales :math:`1/\\sqrt{\\gamma}`).
Inside the box :math:`w = 1` and the prediction is the fitted one; beyond
:math:`h` from it :math:`w = 0` and the physical model alone predicts; in
between :math:`w` falls smoothly (continuous with a continuous first
derivative, the derivative zero at both ends). The weight depends on each
sample alone, so a run predicted in chunks gets the same weights as at once.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..errors import ParameterError

__all__ = ["HANDOVER_LENGTHS", "handover_width", "handover_weight", "handover_rows", "hand_over"]

#: Hand-over width in kernel length scales ``1/sqrt(gamma)``: within it the correction is handed over
#: to the physical model. Beyond one length scale from its last support vectors an RBF expansion is
#: already close to its intercept, so the taper removes only what the kernel would extrapolate.
HANDOVER_LENGTHS = 1.0


def handover_width(gamma: float) -> float:
    """Hand-over width of a kernel of parameter ``gamma``: :data:`HANDOVER_LENGTHS` ``/ sqrt(gamma)``.

    Parameters
    ----------
    gamma : float
        RBF kernel parameter [1/(standardised unit)^2], positive.

    Returns
    -------
    float
        Width [standardised unit].
    """
    return HANDOVER_LENGTHS / float(np.sqrt(gamma))


def handover_weight(X, low, high, width: float) -> np.ndarray:
    """Weight of the data-driven correction at each sample: 1 inside the box ``[low, high]``, 0 beyond ``width``.

    Parameters
    ----------
    X : array_like, shape (n, n_features)
        Samples in the kernel's coordinates [standardised unit].
    low, high : array_like, shape (n_features,)
        Corners of the box of the training inputs, same coordinates, ``low <= high``.
    width : float
        Distance from the box over which the weight falls from 1 to 0 [standardised unit], positive.

    Returns
    -------
    ndarray, shape (n,)
        ``1 - t^2 (3 - 2 t)`` with ``t = min(distance from the box / width, 1)``: in ``[0, 1]``.

    Raises
    ------
    ParameterError
        If ``width`` is not positive and finite, or the box is malformed (shapes, ``low > high``, not finite).
    """
    X = np.asarray(X, dtype=np.float64)
    low = np.asarray(low, dtype=np.float64)
    high = np.asarray(high, dtype=np.float64)
    if not (isinstance(width, (int, float, np.number)) and np.isfinite(width) and width > 0):
        raise ParameterError(f"handover_width_ must be a positive number, got {width!r}")
    if (low.shape != (X.shape[1],) or high.shape != low.shape or not np.all(np.isfinite(low))
            or not np.all(np.isfinite(high)) or np.any(low > high)):
        raise ParameterError(f"the training box of the hand-over must hold a finite (low, high) pair, low <= high, "
                             f"for each of the {X.shape[1]} inputs")
    out = np.empty(X.shape[0])
    handover_rows(np.ascontiguousarray(X), low, high, float(width), out)
    return out


@njit(cache=True, nogil=True, error_model="numpy")
def handover_rows(X, low, high, width, out):
    """Compiled :func:`handover_weight` of checked arguments, written to ``out``, shape (n,).

    Parameters
    ----------
    X : ndarray, shape (n, n_features)
        Samples in the kernel's coordinates [standardised unit].
    low, high : ndarray, shape (n_features,)
        Corners of the box of the training inputs, ``low <= high``.
    width : float
        Hand-over width [standardised unit], positive.
    out : ndarray, shape (n,)
        Receives the weights.
    """
    for i in range(X.shape[0]):
        squared = 0.0
        for f in range(X.shape[1]):
            gap = max(low[f] - X[i, f], X[i, f] - high[f], 0.0)
            squared += gap * gap
        t = min(math.sqrt(squared) / width, 1.0)
        out[i] = 1.0 - t * t * (3.0 - 2.0 * t)


def hand_over(physical, fitted, weight) -> np.ndarray:
    """The prediction handed over: ``weight fitted + (1 - weight) physical`` (exactly ``fitted`` where ``weight`` is 1).

    Parameters
    ----------
    physical : array_like, shape (n,)
        What the physical model alone predicts [A, or N].
    fitted : array_like, shape (n,)
        What the model with its data-driven correction predicts [A, or N].
    weight : array_like of shape (n,), or None
        :func:`handover_weight` of each sample; None: no hand-over (``fitted`` is returned).

    Returns
    -------
    ndarray, shape (n,)
        [A, or N]
    """
    fitted = np.asarray(fitted, dtype=np.float64)
    if weight is None:
        return fitted
    physical = np.asarray(physical, dtype=np.float64)
    return weight * fitted + (1.0 - weight) * physical
