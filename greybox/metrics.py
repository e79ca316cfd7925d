"""Error metrics of a modelled drive effort against the measured one.

All functions take the measured effort ``y`` and the modelled effort ``y_hat``
(motor current [A], or force [N] for drives that log force) as arrays of the
same length. Several runs may be compared at once by concatenating their
samples: none of these metrics depends on the order of the samples.

The names are the ones used in every greybox report:

=========  ==============================================  =============
name       definition                                      unit
=========  ==============================================  =============
RMSE       ``sqrt(mean((y_hat - y)**2))``                  unit of ``y``
RE         ``100 * RMSE / mean(|y|)``                      %
NMSE       ``100 * mean((y_hat - y)**2) / var(y)``         %
relerr     ``100 * ||y - y_hat|| / ||y||``                 %
max_error  ``max(|y_hat - y|)``                            unit of ``y``
=========  ==============================================  =============

RE follows Rüppel et al. (2024) except for its denominator: the paper divides
by the mean of the current, which is close to zero for an axis that moves both
ways, so the mean *absolute* current is used here. NMSE is the one of
Tjahjowidodo et al. (2005, eq. 4); predicting the mean of ``y`` gives 100 %.
relerr is the figure of merit of the EMPS benchmark (Janot et al., 2019).

A metric whose denominator is zero (``y`` all zero, or constant for NMSE) is
``nan``, and so is every metric of an empty selection.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "METRIC_NAMES",
    "rmse",
    "relative_error",
    "nmse",
    "relerr",
    "max_error",
    "metrics_table",
]

#: Keys of the dictionary returned by :func:`metrics_table`, besides ``"n"``.
METRIC_NAMES = ("rmse", "re", "nmse", "relerr", "max_error")


def _pair(y, y_hat) -> tuple[np.ndarray, np.ndarray]:
    """Return ``y`` and ``y_hat`` as flat float arrays of equal length."""
    y = np.asarray(y, dtype=np.float64).ravel()
    y_hat = np.asarray(y_hat, dtype=np.float64).ravel()
    if y.shape != y_hat.shape:
        raise ValueError(f"measured and modelled effort differ in length: {y.size} != {y_hat.size}")
    return y, y_hat


def _ratio(numerator: float, denominator: float) -> float:
    """``numerator / denominator``, or nan when the denominator is zero or undefined."""
    if not np.isfinite(denominator) or denominator == 0.0:
        return float("nan")
    return float(numerator / denominator)


def rmse(y, y_hat) -> float:
    """Root-mean-square error, in the unit of ``y`` (A or N).

    Parameters
    ----------
    y : array_like, shape (n,)
        Measured effort [A or N].
    y_hat : array_like, shape (n,)
        Modelled effort, same unit.

    Returns
    -------
    float
        ``sqrt(mean((y_hat - y)**2))``; nan for ``n == 0``.
    """
    y, y_hat = _pair(y, y_hat)
    if y.size == 0:
        return float("nan")
    return float(np.sqrt(np.mean((y_hat - y) ** 2)))


def relative_error(y, y_hat) -> float:
    """Relative error ``RE = RMSE / mean(|y|)``, in %.

    The denominator is the mean *absolute* measured effort, not the mean of
    the signed effort printed by Rüppel et al. (2024), which is close to zero
    for an axis that moves in both directions.

    Parameters
    ----------
    y : array_like, shape (n,)
        Measured effort [A or N].
    y_hat : array_like, shape (n,)
        Modelled effort, same unit.

    Returns
    -------
    float
        RE [%]; nan when ``y`` is all zero or empty.
    """
    y, y_hat = _pair(y, y_hat)
    if y.size == 0:
        return float("nan")
    return _ratio(100.0 * rmse(y, y_hat), float(np.mean(np.abs(y))))


def nmse(y, y_hat) -> float:
    """Normalised mean-square error, in % (Tjahjowidodo et al., 2005, eq. 4).

    Parameters
    ----------
    y : array_like, shape (n,)
        Measured effort [A or N].
    y_hat : array_like, shape (n,)
        Modelled effort, same unit.

    Returns
    -------
    float
        ``100 * mean((y_hat - y)**2) / var(y)`` [%]; 100 % for a model that
        predicts the mean of ``y``; nan when ``y`` is constant or empty.
    """
    y, y_hat = _pair(y, y_hat)
    if y.size == 0:
        return float("nan")
    return _ratio(100.0 * float(np.mean((y_hat - y) ** 2)), float(np.var(y)))


def relerr(y, y_hat) -> float:
    """Relative error norm of the EMPS benchmark, ``100 * ||y - y_hat|| / ||y||`` in %.

    Parameters
    ----------
    y : array_like, shape (n,)
        Measured effort [A or N].
    y_hat : array_like, shape (n,)
        Modelled effort, same unit.

    Returns
    -------
    float
        relerr [%]; nan when ``y`` is all zero or empty.
    """
    y, y_hat = _pair(y, y_hat)
    if y.size == 0:
        return float("nan")
    return _ratio(100.0 * float(np.linalg.norm(y - y_hat)), float(np.linalg.norm(y)))


def max_error(y, y_hat) -> float:
    """Largest absolute error, in the unit of ``y`` (A or N); nan for ``n == 0``.

    Parameters
    ----------
    y : array_like, shape (n,)
        Measured effort [A or N].
    y_hat : array_like, shape (n,)
        Modelled effort, same unit.
    """
    y, y_hat = _pair(y, y_hat)
    if y.size == 0:
        return float("nan")
    return float(np.max(np.abs(y_hat - y)))


def metrics_table(y, y_hat) -> dict[str, float | int]:
    """All metrics of one comparison, as a JSON-ready dictionary.

    Parameters
    ----------
    y : array_like, shape (n,)
        Measured effort [A or N].
    y_hat : array_like, shape (n,)
        Modelled effort, same unit.

    Returns
    -------
    dict
        ``{"n": samples, "rmse": ..., "re": ..., "nmse": ..., "relerr": ...,
        "max_error": ...}`` with RMSE and max_error in the unit of ``y`` and the
        others in %.
    """
    y, y_hat = _pair(y, y_hat)
    return {
        "n": int(y.size),
        "rmse": rmse(y, y_hat),
        "re": relative_error(y, y_hat),
        "nmse": nmse(y, y_hat),
        "relerr": relerr(y, y_hat),
        "max_error": max_error(y, y_hat),
    }
