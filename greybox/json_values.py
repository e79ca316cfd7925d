"""Values made fit for strict JSON: NumPy types as Python ones, NaN and infinities as null."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["jsonable"]


def jsonable(value):
    """``value`` with NumPy types turned into Python ones and non-finite floats into None.

    Parameters
    ----------
    value : object
        A scalar, array, or dict / list / tuple nesting them (dict keys become str); other objects pass unchanged.
    """
    if isinstance(value, dict):
        return {str(key): jsonable(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(item) for item in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value
