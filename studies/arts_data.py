"""Reader of the ARTS-Lab friction-device files (dry friction with backlash, harmonic tests at 1024 Hz).

The files ``test0.npy`` ... ``test12.npy`` (D. Coble, "Physics-Informed
Machine Learning for Dry Friction and Backlash Modeling in Structural Control
Systems", ARTS-Lab, 2024; CC BY-SA 4.0) are float64 NumPy arrays of shape
``(N, 4)`` with the columns ``t, F, x, v``: time [s], measured friction force
[N], displacement [m] and velocity [m/s], sampled at 1024 Hz. The force is
measured directly, so the log's effort is this force (unit ``"N"``).

The recorded velocity agrees with the derivative of the recorded displacement:
both low-pass filtered alike (4th-order Butterworth at 20 Hz, forward and
backward), they differ by 0.02-0.6 % RMS of the velocity on every file, with
unit gain and no lag. It is kept as recorded (:func:`greybox.data.prepare.derive`
then only derives the acceleration).

These files are not read by :func:`greybox.data.io.read_log`: a ``.npy`` file
carries neither column names nor units, and its extension is shared by every
NumPy array, so reading any 4-column array as ``t, F, x, v`` in SI units would
silently misread arrays of other origins. :func:`read_arts` is called by name
(:mod:`studies.arts`).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from greybox.data.log import AxisLog
from greybox.data.validate import check_finite, check_time
from greybox.errors import LogError

__all__ = ["ARTS_COLUMNS", "read_arts"]

#: Columns of an ARTS file, in order, with their units in the file.
ARTS_COLUMNS = ("t [s]", "F [N]", "x [m]", "v [m/s]")


def read_arts(path: str | os.PathLike) -> AxisLog:
    """Read and validate one ARTS-Lab friction-device file.

    Parameters
    ----------
    path : str or path-like
        A ``.npy`` file holding a real array of shape ``(N, 4)``, columns
        :data:`ARTS_COLUMNS`.

    Returns
    -------
    AxisLog
        time ``t`` [s]; position ``1000 x`` [mm]; velocity ``1000 v`` [mm/s];
        effort ``F`` [N] (``effort_unit="N"``); no acceleration (derive it with
        :func:`greybox.data.prepare.derive`). Dataset is the file stem, source
        the path.

    Raises
    ------
    LogError
        Naming the file: a missing file or directory, a name not ending in
        ``.npy``, a file NumPy cannot load as a plain array, an array not of
        shape ``(N, 4)`` or not of real numbers, a time base that is not
        uniform and increasing, or a non-finite value.
    """
    name = os.fspath(path)
    if Path(name).suffix.lower() != ".npy":
        raise LogError(name, f"not a .npy file; ARTS files are NumPy arrays with columns {', '.join(ARTS_COLUMNS)}")
    if not os.path.exists(name):
        raise LogError(name, "no such file")
    if os.path.isdir(name):
        raise LogError(name, "is a directory, not an ARTS file")
    try:
        array = np.load(name, allow_pickle=False)
    except (ValueError, OSError, EOFError) as exc:
        raise LogError(name, f"not a readable NumPy .npy array ({exc})") from None
    if not isinstance(array, np.ndarray):  # an .npz archive under a .npy name
        array.close()
        raise LogError(name, "is an .npz archive, not a single .npy array")
    if array.dtype.kind not in "fiu":
        raise LogError(name, f"holds {array.dtype} values; expected real numbers (float64)")
    if array.ndim != 2 or array.shape[1] != len(ARTS_COLUMNS):
        raise LogError(name, f"array of shape {array.shape}; expected (N, {len(ARTS_COLUMNS)}) with columns "
                             f"{', '.join(ARTS_COLUMNS)}")
    time, force, displacement, velocity = np.asarray(array, dtype=np.float64).T
    log = AxisLog(time=time, position=1e3 * displacement, velocity=1e3 * velocity, effort=force, effort_unit="N",
                  dataset=Path(name).stem, source=name)
    check_time(log.time, source=name)
    check_finite(log)
    return log
