"""A fitted model as text: its parameter table and fit figures, as ``greybox train`` and ``greybox info`` print them."""

from __future__ import annotations

import numpy as np

from ..data.effort import shown_unit

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


def parameter_lines(model, quantity: str | None = None) -> list[str]:
    """Lines ``name = value unit`` of the model's parameter table (see ``parameter_table``), aligned.

    Parameters
    ----------
    model : CurrentModel
        A fitted model.
    quantity : str, optional
        What the model's effort is (:func:`~greybox.data.effort.effort_quantity`): a motor torque shows the
        units written in A in Nm (``A s/mm`` as ``Nm s/mm``).
    """
    rows = model.parameter_table()
    width = max([14, *(len(row.name) for row in rows)])
    return [(f"  {row.name:<{width}} = {format_value(row.value)} "
             f"{shown_unit(row.unit, quantity) if row.unit != '-' else ''}".rstrip()
             + interval_text(row)) for row in rows]


def _ends(lower, upper) -> str:
    """``lower .. upper`` of one element (``-`` for none)."""
    return "-" if np.isnan(lower) or np.isnan(upper) else f"{lower:.4g} .. {upper:.4g}"


def interval_text(row) -> str:
    """``"  95 %: lower .. upper  [flag]"`` of a parameter row, ``""`` for a row without intervals.

    Parameters
    ----------
    row : Parameter
        A row of a parameter table (its ``lower``, ``upper`` and ``flag``).
    """
    if row.lower is None or row.upper is None:
        return ""
    lower = np.asarray(row.lower, dtype=float).ravel()
    upper = np.asarray(row.upper, dtype=float).ravel()
    if lower.size > _MAX_PRINTED:
        ends = f"<{lower.size} intervals>"
    elif np.all(np.isnan(lower)):
        ends = ""
    elif np.ndim(row.lower) == 0:
        ends = _ends(lower[0], upper[0])
    else:
        ends = "[" + ", ".join(_ends(a, b) for a, b in zip(lower, upper)) + "]"
    return (f"   95 %: {ends}" if ends else "") + (f"   [{row.flag}]" if row.flag else "")


def fit_lines(model) -> list[str]:
    """Lines ``name = value`` of the model's ``fit_summary``.

    Parameters
    ----------
    model : CurrentModel
        A fitted model.
    """
    return [f"  {name:<18} = {format_value(value)}" for name, value in model.fit_summary().items()]


def selection_lines(record: dict) -> list[str]:
    """The table a model chosen by ``greybox train --model auto`` was chosen from, best held-out RE first.

    Parameters
    ----------
    record : dict
        The model's ``selection_`` (:func:`greybox.identify.selection.selection_record`).
    """
    rows = sorted(record["candidates"], key=lambda c: (c["re"] is None, c["re"] if c["re"] is not None else 0.0))
    width = max(len(row["label"]) for row in rows)
    lines = [f"model choice: {len(record['candidates'])} candidates, held out in turn: {', '.join(record['folds'])}",
             f"  {'candidate':<{width}}  {'params':>6}  {'held-out RE %':>13}  {'+-SE':>6}  per fold"]
    for row in rows:
        mark = "  <- chosen" if row["label"] == record["chosen"] else ""
        if row["error"] is not None:
            lines.append(f"  {row['label']:<{width}}  {'':>6}  {'failed':>13}  {'':>6}  {row['error']}")
            continue
        spread = f"{row['re_se']:.2f}" if row["re_se"] is not None else "-"
        folds = " ".join(f"{value:.2f}" for value in row["fold_re"])
        lines.append(f"  {row['label']:<{width}}  {row['n_params']:>6d}  {row['re']:>13.2f}  {spread:>6}  "
                     f"{folds}{mark}")
    lines.append(f"  rule: {record['rule']}")
    lines.append("  (RE = RMSE / mean |effort| of the runs held out)")
    lines += [f"  note: {note}" for note in record["notes"]]
    return lines


def model_lines(model, quantity: str | None = None) -> list[str]:
    """The ``parameters:`` and ``fit:`` sections of a fitted model, as ``greybox train`` and ``info`` print them.

    Parameters
    ----------
    model : CurrentModel
        A fitted model.
    quantity : str, optional
        What the model's effort is, for the parameters' units (see :func:`parameter_lines`).
    """
    notes = model.fit_notes()
    record = getattr(model, "selection_", None)  # only a model chosen by --model auto has one
    return ["parameters:", *parameter_lines(model, quantity), "fit:", *fit_lines(model),
            *(["notes:"] + [f"  - {note}" for note in notes] if notes else []),
            *(selection_lines(record) if record is not None else [])]
