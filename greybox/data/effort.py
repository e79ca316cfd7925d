"""What a log's effort is, and the unit it is shown in: a motor current, a motor torque, or the load.

A servo trace of a linear axis often logs the motor torque [Nm] instead of the current. greybox reads it as
the current of a motor with ``k_t = 1 Nm/A`` (:data:`~greybox.data.units.MOTOR_TORQUE`), so that the models
and the process force come out right; this module keeps what the numbers are:

* :func:`effort_quantity` names a log's effort (``"current"``, ``"motor torque"``, ``"force"`` or
  ``"torque"``) and :data:`EFFORT_UNITS` its unit (A, Nm, N, Nm), for every output, plot and record;
* :func:`check_one_effort` refuses training logs that mix quantities (a model fitted to both would be
  neither);
* :func:`convert_effort` turns a current log into a motor-torque log (or back) through the torque constant
  of the axis file, for a model trained on the other quantity.

This module imports only :mod:`greybox.errors` and :mod:`greybox.data.units`.
"""

from __future__ import annotations

import re
from pathlib import Path

from ..errors import GreyboxError
from .units import MOTOR_TORQUE

__all__ = ["EFFORT_UNITS", "MOTOR_TORQUE_QUANTITY", "check_effort_measured", "check_one_axis", "check_one_effort",
           "column_stem", "convert_effort", "effort_quantity", "effort_text", "shown_unit"]

#: The quantity of a linear axis's log whose effort is the motor torque read through ``k_t = 1``.
MOTOR_TORQUE_QUANTITY = "motor torque"

#: Unit of each effort quantity.
EFFORT_UNITS = {"current": "A", MOTOR_TORQUE_QUANTITY: "Nm", "force": "N", "torque": "Nm"}

#: The ampere as a word of a unit text (``"A"``, ``"A s/mm"``, ``"N/A"``), not inside another word.
_AMPERE = re.compile(r"(?<![A-Za-z])A(?![A-Za-z])")


def effort_quantity(log) -> str:
    """The quantity a log's effort is: ``"current"``, ``"motor torque"``, ``"force"`` or ``"torque"``.

    Parameters
    ----------
    log : AxisLog
        A log (or one run of it); a motor torque is told by its ``attrs``.
    """
    if log.effort_unit == "A":
        return MOTOR_TORQUE_QUANTITY if log.attrs.get(MOTOR_TORQUE) else "current"
    return log.units.load


def shown_unit(unit: str, quantity: str | None) -> str:
    """A unit text written for a current (``"A"``, ``"A s/mm"``), in the unit of ``quantity``'s effort.

    Parameters
    ----------
    unit : str
        Unit text as the package writes it for an effort in A.
    quantity : str or None
        The effort's quantity (:func:`effort_quantity`); None or ``"current"`` leaves ``unit`` as it is.
    """
    if quantity != MOTOR_TORQUE_QUANTITY:
        return unit
    return _AMPERE.sub(EFFORT_UNITS[MOTOR_TORQUE_QUANTITY], unit)


def effort_text(quantity: str) -> str:
    """The unit of an effort, with its quantity where the unit alone does not say it: ``"A"``, ``"N"``,
    ``"Nm (motor torque)"``.

    Parameters
    ----------
    quantity : str
        The effort's quantity (:func:`effort_quantity`).
    """
    unit = EFFORT_UNITS[quantity]
    return f"{unit} ({quantity})" if quantity == MOTOR_TORQUE_QUANTITY else unit


def column_stem(quantity: str) -> str:
    """The start of an output column of an effort: ``"current"``, ``"motor_torque"``, ``"force"``, ``"torque"``.

    Parameters
    ----------
    quantity : str
        The effort's quantity (:func:`effort_quantity`).
    """
    return quantity.replace(" ", "_")


def _name(run) -> str:
    return Path(run.source).name if run.source else "a log without a file name"


def check_one_axis(runs) -> str | None:
    """The one axis the ``runs`` name (None when none names one); an error naming the files when they name several.

    Parameters
    ----------
    runs : sequence of AxisLog
        The training runs (their ``axis`` and ``source``).

    Raises
    ------
    GreyboxError
        When the runs are of different axes: one model is one axis's.
    """
    found: dict[str, list[str]] = {}
    for run in runs:
        if run.axis:
            found.setdefault(str(run.axis), []).append(Path(run.source or "?").name)
    if len(found) > 1:
        listed = "; ".join(f"axis {axis}: {', '.join(dict.fromkeys(files))}" for axis, files in sorted(found.items()))
        raise GreyboxError(f"the training logs are of different axes ({listed}); a model is one axis's: train each "
                           "axis's logs apart, or give --axes to train a model per axis of logs that hold several")
    return next(iter(found), None)


def check_effort_measured(runs) -> None:
    """Refuse training runs whose effort is zero throughout: nothing to fit, and no relative error to compare.

    Parameters
    ----------
    runs : sequence of AxisLog
        The training runs (their ``source`` names the files in the message).

    Raises
    ------
    GreyboxError
        When every sample of every run has an effort of 0 (or none is finite).
    """
    import numpy as np

    if runs and not any(np.any(np.isfinite(run.effort) & (run.effort != 0.0)) for run in runs):
        files = ", ".join(dict.fromkeys(Path(run.source or "?").name for run in runs))
        raise GreyboxError(f"the effort of the training logs is zero throughout ({files}): nothing to fit; check the "
                           "effort column (--columns) or the drive's recording")


def check_one_effort(runs, what: str = "the training logs",
                     advice: str = "a model is fitted to one: train on logs of one quantity (or map the other "
                                   "column with --columns)") -> str:
    """The one effort quantity of ``runs``; an error naming the files when they mix quantities.

    Parameters
    ----------
    runs : sequence of AxisLog
        The runs (their ``source`` names the file in the message).
    what : str, default "the training logs"
        What the runs are, for the message.
    advice : str, optional
        What to do instead, the end of the message (by default, for training logs).

    Returns
    -------
    str
        The quantity (:func:`effort_quantity`).

    Raises
    ------
    GreyboxError
        When the runs carry efforts of different quantities, e.g. a current and a motor torque.
    """
    found: dict[str, list[str]] = {}
    for run in runs:
        names = found.setdefault(effort_quantity(run), [])
        if _name(run) not in names:
            names.append(_name(run))
    if len(found) > 1:
        listed = "; ".join(f"{quantity} [{EFFORT_UNITS[quantity]}]: {', '.join(names)}"
                           for quantity, names in found.items())
        raise GreyboxError(f"{what} mix effort quantities ({listed}); {advice}")
    return next(iter(found))


def convert_effort(runs, quantity: str, torque_constant_Nm_per_A: float) -> list:
    """Runs of a linear axis with their effort turned into ``quantity``, a current or a motor torque.

    A current becomes a motor torque ``k_t I`` [Nm] and a motor torque a current ``tau / k_t`` [A]; runs
    already of ``quantity`` are returned as they are.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs whose effort is a current or a motor torque.
    quantity : {"current", "motor torque"}
        The quantity wanted.
    torque_constant_Nm_per_A : float
        The motor's torque constant ``k_t`` [Nm/A] (from the axis file).

    Returns
    -------
    list of AxisLog
    """
    if quantity not in ("current", MOTOR_TORQUE_QUANTITY):
        raise ValueError(f"cannot convert an effort into {quantity!r}")
    converted = []
    for run in runs:
        have = effort_quantity(run)
        if have == quantity:
            converted.append(run)
        elif have not in ("current", MOTOR_TORQUE_QUANTITY):
            raise ValueError(f"cannot convert a {have} into a {quantity}")
        elif quantity == MOTOR_TORQUE_QUANTITY:
            converted.append(run.replace(effort=run.effort * torque_constant_Nm_per_A,
                                         attrs={**run.attrs, MOTOR_TORQUE: "current_A times k_t"}))
        else:
            attrs = {key: value for key, value in run.attrs.items() if key != MOTOR_TORQUE}
            converted.append(run.replace(effort=run.effort / torque_constant_Nm_per_A, attrs=attrs))
    return converted
