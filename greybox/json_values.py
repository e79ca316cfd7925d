"""Values made fit for strict JSON: NumPy types as Python ones, NaN and infinities as null."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["jsonable"]


def jsonable(value, *, other=None):
    """``value`` with NumPy types turned into Python ones and non-finite floats into None.

    The one sanitiser of values written as JSON (reports, records, messages): strict JSON has no NaN
    or infinity, and :func:`json.dumps` does not know NumPy types.

    Parameters
    ----------
    value : object
        A scalar, array, or dict / list / tuple nesting them (dict keys become str).
    other : callable, optional
        Applied to any other object (e.g. :func:`repr` to describe a hyperparameter that is a model);
        without it, other objects pass unchanged.

    Returns
    -------
    object
        Python None, bool, int, float, str, list and dict (and what ``other`` returns).

    Examples
    --------
    >>> import numpy as np
    >>> jsonable({"rmse": np.float64(0.5), "re": float("nan"), "n": np.int64(3), "v": np.array([1.0, np.inf])})
    {'rmse': 0.5, 're': None, 'n': 3, 'v': [1.0, None]}
    """
    if isinstance(value, dict):
        return {str(key): jsonable(item, other=other) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(item, other=other) for item in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist(), other=other)
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if value is None or isinstance(value, str) or other is None:
        return value
    return other(value)
