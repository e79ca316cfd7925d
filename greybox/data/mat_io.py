"""MATLAB ``.mat`` axis logs: version 5 (and 4) through SciPy, version 7.3 (HDF5) through h5py.

A ``.mat`` file holds named variables; the vectors among them are the
columns of the log, named like CSV columns: by convention (``time_s``,
``position_mm``, ``current_A``, any supported unit suffix) or mapped with
``columns`` (``--columns time_s=t,position_m=x,current_A=iq``), the mapping of
:func:`greybox.data.units.resolve_columns`. Row and column vectors are both
taken; matrices, structs, cells and text are not columns (a mapping that names
one is an error). MATLAB stores arrays column-major, which HDF5 shows
transposed; both read as vectors of the same length.

:func:`greybox.data.matlab.read_mat` reads a file, as the EMPS benchmark
where it holds the benchmark's variables.
"""

from __future__ import annotations

from pathlib import Path
from typing import Mapping

import numpy as np

from ..errors import LogError
from .log import AxisLog
from .units import log_from_columns

__all__ = ["load_mat_variables", "log_from_vectors"]

#: First bytes of an HDF5 file (a MATLAB 7.3 file starts with a 512-byte text header, then HDF5).
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def _is_hdf5(path) -> bool:
    with open(path, "rb") as stream:
        head = stream.read(1024)
    return _HDF5_SIGNATURE in head


def _load_hdf5(path) -> dict[str, np.ndarray]:
    import h5py

    variables = {}
    try:
        with h5py.File(path, "r") as store:
            for name, item in store.items():
                if isinstance(item, h5py.Dataset) and item.dtype.kind in "biuf" and not name.startswith("#"):
                    variables[name] = np.asarray(item[()]).T  # column-major in MATLAB, row-major in HDF5
    except OSError as exc:
        raise LogError(path, f"not a readable MATLAB 7.3 (HDF5) file ({exc})") from None
    return variables


def load_mat_variables(path) -> dict[str, np.ndarray]:
    """The numeric variables of a ``.mat`` file, any version, as arrays in MATLAB's shape.

    Parameters
    ----------
    path : str or path-like
        MATLAB file.

    Returns
    -------
    dict of str to ndarray
        Variable name -> array (structs, cells and text are left out of a 7.3 file; a version-5 file gives
        what :func:`scipy.io.loadmat` gives).

    Raises
    ------
    LogError
        For a file that is not a readable MATLAB file.
    """
    from scipy.io import loadmat
    from scipy.io.matlab import MatReadError

    if _is_hdf5(path):
        return _load_hdf5(path)
    try:
        variables = loadmat(path)
    except IndexError:  # scipy runs off the end of a header cut short
        raise LogError(path, "not a readable MATLAB .mat file (it ends inside its header)") from None
    except (MatReadError, ValueError, TypeError, NotImplementedError, OSError, EOFError) as exc:
        raise LogError(path, f"not a readable MATLAB .mat file ({exc})") from None
    return {name: value for name, value in variables.items() if not name.startswith("__")}


def _columns(variables: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The numeric vectors among the variables, flattened (row or column vectors of at least 2 elements)."""
    out = {}
    for name, value in variables.items():
        array = np.asarray(value)
        if array.dtype.kind in "biuf" and array.ndim <= 2 and array.size >= 2 and 1 in array.shape:
            out[name] = array.ravel().astype(np.float64)
    return out


def log_from_vectors(variables: Mapping[str, np.ndarray], path, *, columns: Mapping[str, str] | None = None,
                     sample_time: float | None = None, axis: str | None = None) -> AxisLog:
    """An axis log from a ``.mat`` file's variables, its vectors taken as named columns.

    Parameters
    ----------
    variables : mapping of str to ndarray
        The file's variables (:func:`load_mat_variables`).
    path : str or path-like
        The file, for the log's source and error messages.
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
        For vectors of different lengths among the mapped channels, a mapped variable that is not a
        vector, or missing channels (the message lists the vectors the file holds).
    """
    vectors = _columns(variables)
    if not vectors:
        found = ", ".join(sorted(variables)) or "none"
        raise LogError(path, f"no numeric vector among the variables ({found})")
    wanted = set((columns or {}).values())
    for name in wanted:
        if name in variables and name not in vectors:
            raise LogError(path, f"variable '{name}' has shape {np.shape(variables[name])}; a channel must be a vector")
    lengths = {name: vector.size for name, vector in vectors.items()}
    mapped = [name for name in vectors if name in wanted] or list(vectors)
    common = max(set(lengths[name] for name in mapped), key=[lengths[name] for name in mapped].count)
    table = {name: vector for name, vector in vectors.items() if vector.size == common}
    odd = [name for name in wanted if name in vectors and name not in table]
    if odd:
        raise LogError(path, f"variable '{odd[0]}' has {lengths[odd[0]]} samples, the other channels {common}")
    return log_from_columns(table, source=str(path), columns=columns, sample_time=sample_time,
                            dataset=Path(path).stem, select=axis)
