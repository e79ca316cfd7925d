"""Reading a MATLAB ``.mat`` axis log: the EMPS benchmark's files as the benchmark, any other by its vectors."""

from __future__ import annotations

from typing import Mapping

from .emps import EMPS_VARIABLES, emps_log
from .log import AxisLog
from .mat_io import load_mat_variables, log_from_vectors

__all__ = ["read_mat"]


def read_mat(path, *, columns: Mapping[str, str] | None = None, sample_time: float | None = None,
             axis: str | None = None) -> AxisLog:
    """Read an axis log from a MATLAB ``.mat`` file (version 4, 5 or 7.3).

    A file holding any of the EMPS benchmark's own variables (``qm``, ``vir``,
    ``gtau``) and given no mapping is read as the benchmark
    (:func:`greybox.data.emps.emps_log`); any other file by its vectors, named
    or mapped like CSV columns (:func:`greybox.data.mat_io.log_from_vectors`).

    Parameters
    ----------
    path : str or path-like
        MATLAB file.
    columns : mapping of str to str, optional
        ``{canonical_name: variable}`` for variables not named by the convention.
    sample_time : float, optional
        Sample time [s] for files without a time vector.
    axis : str, optional
        Axis to read from a file holding several, its vectors named ``<axis>_<quantity>_<unit>``
        (``X_position_mm``; :func:`greybox.data.units.select_axis`).

    Returns
    -------
    AxisLog
        Not yet validated; :func:`greybox.data.io.read_log` validates.

    Raises
    ------
    LogError
        For an unreadable file or missing or malformed channels; the message names the file.
    """
    variables = load_mat_variables(path)
    if columns is None and axis is None and any(name in variables for name in EMPS_VARIABLES[1:]):
        return emps_log(variables, path)
    return log_from_vectors(variables, path, columns=columns, sample_time=sample_time, axis=axis)
