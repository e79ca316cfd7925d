"""Reader of the EMPS benchmark files (Janot, Gautier & Brunot 2019, nonlinearbenchmark.org).

The MATLAB files ``DATA_EMPS.mat`` and ``DATA_EMPS_PULSES.mat`` hold the
time ``t`` [s], the measured motor position ``qm`` [m] (load side), the
reference position ``qg`` [m], the controller output ``vir`` [V] and the drive
gain ``gtau`` [N/V]; the force on the load side is ``gtau * vir`` [N]. No
motor current is recorded, so the log's effort is this force (unit ``"N"``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import LogError
from .log import AxisLog

__all__ = ["read_emps", "emps_log", "EMPS_VARIABLES"]

#: Variables every EMPS file must hold.
EMPS_VARIABLES = ("t", "qm", "vir", "gtau")


def read_emps(path) -> AxisLog:
    """Read an EMPS benchmark ``.mat`` file.

    Parameters
    ----------
    path : str or path-like
        ``DATA_EMPS.mat``, ``DATA_EMPS_PULSES.mat`` or a file with the same variables.

    Returns
    -------
    AxisLog
        time ``t`` [s]; position ``1000 * qm`` [mm]; effort ``gtau * vir`` [N]
        (``effort_unit="N"``); extras ``reference_position_mm`` (``1000 * qg``)
        and ``pulses_N`` when present; attrs ``gtau`` [N/V], ``kp`` [1/s] and
        ``kv`` [V/(m/s)] when present. Dataset is the file stem. Not yet
        validated; :func:`greybox.data.io.read_log` validates.

    Raises
    ------
    LogError
        For a file that is not a MATLAB file or lacks a required variable.
    """
    from .mat_io import load_mat_variables

    return emps_log(load_mat_variables(path), path)


def emps_log(variables, path) -> AxisLog:
    """The EMPS log of a ``.mat`` file's variables (see :func:`read_emps`).

    Parameters
    ----------
    variables : mapping of str to ndarray
        The file's variables (:func:`greybox.data.mat_io.load_mat_variables`).
    path : str or path-like
        The file, for the log's source and error messages.

    Returns
    -------
    AxisLog

    Raises
    ------
    LogError
        For a missing variable, or one of the wrong shape.
    """
    missing = [name for name in EMPS_VARIABLES if name not in variables]
    if missing:
        found = sorted(name for name in variables if not name.startswith("__"))
        raise LogError(path, f"missing EMPS variable(s) {', '.join(missing)}; "
                             f"the file holds {', '.join(found) or 'none'}")

    def series(name):
        values = np.asarray(variables[name], dtype=np.float64)
        if values.ndim != 2 or 1 not in values.shape:
            raise LogError(path, f"variable '{name}' has shape {values.shape}; expected a vector")
        return values.ravel()

    def scalar(name):
        values = np.asarray(variables[name], dtype=np.float64)
        if values.size != 1:
            raise LogError(path, f"variable '{name}' has shape {values.shape}; expected a scalar")
        return float(values.ravel()[0])

    gtau = scalar("gtau")
    extras = {}
    if "qg" in variables:
        extras["reference_position_mm"] = 1e3 * series("qg")
    if "pulses_N" in variables:
        extras["pulses_N"] = series("pulses_N")
    attrs = {"gtau": gtau}
    for name in ("kp", "kv"):
        if name in variables:
            attrs[name] = scalar(name)
    return AxisLog(
        time=series("t"),
        position=1e3 * series("qm"),
        effort=gtau * series("vir"),
        effort_unit="N",
        dataset=Path(path).stem,
        source=str(path),
        extras=extras,
        attrs=attrs,
    )
