"""The effort of a cutting log in the quantity its model was trained on: a current, or a servo trace's torque."""

from __future__ import annotations

from typing import Callable

from ..data.effort import EFFORT_UNITS, check_one_effort, convert_effort
from ..errors import GreyboxError
from ..provenance import model_quantity

__all__ = ["align_effort"]


def align_effort(records: dict, model, runs, axis_config, log_name: str, model_name: str,
                 notify: Callable[[str], None] | None = None) -> list:
    """The runs of a log in the effort quantity the model was trained on, with a one-line note when converted.

    A current log predicted by a model trained on a motor torque (or the other way round) is converted
    through the torque constant of the axis file (:func:`~greybox.data.effort.convert_effort`); without an
    axis file, or for quantities no constant links, it is refused in one line.

    Parameters
    ----------
    records : dict
        The model file's records.
    model : CurrentModel
        The fitted model.
    runs : list of AxisLog
        The prepared runs of the log.
    axis_config : AxisConfig or None
        The axis file (--axis-config), whose torque constant [Nm/A] converts.
    log_name, model_name : str
        Names for the messages.
    notify : callable, optional
        Receives the note of a conversion (one line); default: no note.

    Returns
    -------
    list of AxisLog

    Raises
    ------
    GreyboxError
        For a log of another effort quantity that cannot be converted.
    """
    want = model_quantity(records, model)
    have = check_one_effort(runs, f"the runs of {log_name}")
    if have == want:
        return list(runs)
    convertible = {have, want} == {"current", "motor torque"}
    if not convertible or axis_config is None:
        how = ("give the axis file (--axis-config) whose torque constant converts one into the other"
               if convertible else "predict it with a model trained on that quantity")
        raise GreyboxError(f"{log_name}: its effort is a {have} [{EFFORT_UNITS[have]}], {model_name} was trained on "
                           f"a {want} [{EFFORT_UNITS[want]}]; {how}")
    k_t = axis_config.torque_constant_Nm_per_A
    if notify is not None:
        notify(f"note: {log_name}: its {have} [{EFFORT_UNITS[have]}] is converted into the {want} "
               f"[{EFFORT_UNITS[want]}] {model_name} was trained on, through the torque constant {k_t:g} Nm/A of "
               "the axis file")
    return convert_effort(runs, want, k_t)
