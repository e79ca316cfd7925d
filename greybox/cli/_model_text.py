"""A fitted model as text: its parameter table and fit figures, as ``greybox train`` and ``greybox info`` print them."""

from __future__ import annotations

import numpy as np

#: Arrays and lists longer than this are summarised by their shape, not printed.
_MAX_PRINTED = 12


def format_value(value) -> str:
    """A parameter or fit value as printed: 6 significant digits, long arrays and lists by their size.

    Parameters
    ----------
    value : object
        Number, array, sequence or anything else (printed with ``str``).
    """
    if isinstance(value, np.ndarray):
        if value.size > _MAX_PRINTED:
            return f"<array of shape {value.shape}>"
        return "[" + ", ".join(f"{v:.6g}" for v in value.ravel()) + "]"
    if isinstance(value, (list, tuple, dict)) and len(value) > _MAX_PRINTED:
        return f"<{type(value).__name__} of {len(value)} items>"
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def parameter_lines(model) -> list[str]:
    """Lines ``name = value unit`` of the model's parameter table (see ``parameter_table``), aligned.

    Parameters
    ----------
    model : CurrentModel
        A fitted model.
    """
    rows = model.parameter_table()
    width = max([14, *(len(row.name) for row in rows)])
    return [f"  {row.name:<{width}} = {format_value(row.value)} {row.unit if row.unit != '-' else ''}".rstrip()
            for row in rows]


def fit_lines(model) -> list[str]:
    """Lines ``name = value`` of the model's ``fit_summary``.

    Parameters
    ----------
    model : CurrentModel
        A fitted model.
    """
    return [f"  {name:<18} = {format_value(value)}" for name, value in model.fit_summary().items()]


def model_lines(model) -> list[str]:
    """The ``parameters:`` and ``fit:`` sections of a fitted model, as ``greybox train`` and ``info`` print them.

    Parameters
    ----------
    model : CurrentModel
        A fitted model.
    """
    return ["parameters:", *parameter_lines(model), "fit:", *fit_lines(model)]
