"""Read and write axis logs in any supported format, chosen by file extension.

=========== ===================== ===========================================
format      extensions            reader options
=========== ===================== ===========================================
``csv``     ``.csv``              ``columns``, ``sample_time``
``parquet`` ``.parquet``, ``.pq`` ``columns``, ``sample_time``
``mcap``    ``.mcap``             ``columns``, ``topic``
``mat``     ``.mat``              ``columns``, ``sample_time`` (MATLAB 4, 5 or 7.3; read only;
                                  EMPS benchmark files read as such)
``tdms``    ``.tdms``             ``columns``, ``topic`` (the group), ``sample_time`` (read only)
=========== ===================== ===========================================

:func:`read_log` validates what it reads (uniform time base, finite values),
so every log it returns is ready for :func:`greybox.data.prepare.prepare`.
:func:`write_log` writes atomically and never overwrites the file a log was
read from.
"""

from __future__ import annotations

import importlib
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

from ..atomic import atomic_output
from ..errors import GreyboxError, LogError
from .file_metadata import sidecar_path
from .log import AxisLog
from .units import CANONICAL_NAMES, known_column
from .validate import check_finite, check_increasing, check_time

__all__ = ["read_log", "write_log", "parse_column_mapping", "format_of", "FORMATS", "LOG_FORMATS", "LOG_SUFFIXES",
           "LogFormat"]

@dataclass(frozen=True)
class LogFormat:
    """How greybox reads (and writes) one log format: a line of :data:`LOG_FORMATS`.

    Parameters
    ----------
    suffixes : tuple of str
        The file extensions of the format, lower case with the dot.
    module : str
        The module of :mod:`greybox.data` that reads it (imported on first use).
    reader : str
        Its reading function: ``reader(path, **options)`` returns an :class:`~greybox.data.log.AxisLog`.
    writer : str or None
        Its writing function, ``writer(log, path)``; None for a format greybox only reads.
    options : tuple of str
        The reader options it takes of ``columns``, ``topic``, ``sample_time`` and ``axis``.
    """

    suffixes: tuple[str, ...]
    module: str
    reader: str
    writer: str | None
    options: tuple[str, ...]


#: The log formats: a new format is its reading module and one line here.
LOG_FORMATS = {
    "csv": LogFormat((".csv",), "csv_io", "read_csv", "write_csv", ("columns", "sample_time", "axis")),
    "parquet": LogFormat((".parquet", ".pq"), "parquet_io", "read_parquet", "write_parquet",
                         ("columns", "sample_time", "axis")),
    "mcap": LogFormat((".mcap",), "mcap_io", "read_mcap", "write_mcap", ("columns", "topic", "axis")),
    "mat": LogFormat((".mat",), "matlab", "read_mat", None, ("columns", "sample_time", "axis")),
    "tdms": LogFormat((".tdms",), "tdms_io", "read_tdms", None, ("columns", "topic", "sample_time", "axis")),
}

#: File extensions of each format.
FORMATS = {name: entry.suffixes for name, entry in LOG_FORMATS.items()}

#: Every extension of a log file, in the order of :data:`FORMATS` (what a directory of logs is searched for).
LOG_SUFFIXES = tuple(suffix for suffixes in FORMATS.values() for suffix in suffixes)

def format_of(path, fmt: str | None = None) -> str:
    """Return the format name of a file: ``fmt`` if given, else from the extension.

    Parameters
    ----------
    path : str or path-like
        Log file; its extension (case-insensitive) gives the format.
    fmt : str, optional
        Format name (a key of :data:`FORMATS`), overriding the extension.

    Raises
    ------
    LogError
        For an unknown format name or extension.
    """
    if fmt is not None:
        if fmt not in FORMATS:
            raise LogError(path, f"unknown log format '{fmt}'; known: {', '.join(FORMATS)}")
        return fmt
    suffix = Path(path).suffix.lower()
    for name, suffixes in FORMATS.items():
        if suffix in suffixes:
            return name
    known = ", ".join(s for suffixes in FORMATS.values() for s in suffixes)
    raise LogError(path, f"unknown log file extension '{suffix}'; known: {known}")


def _handler(fmt: str, writer: bool = False):
    """The reading (or writing) function of format ``fmt``, its module imported on first use."""
    entry = LOG_FORMATS[fmt]
    module = importlib.import_module(f"{__package__}.{entry.module}")
    return getattr(module, entry.writer if writer else entry.reader)


def read_log(
    path,
    *,
    columns: Mapping[str, str] | None = None,
    topic: str | None = None,
    sample_time: float | None = None,
    time_tolerance: float | None = 0.25,
    fmt: str | None = None,
    axis: str | None = None,
) -> AxisLog:
    """Read and validate one axis log.

    Parameters
    ----------
    path : str or path-like
        Log file; the format follows from the extension (see module docstring).
    columns : mapping of str to str, optional
        ``{canonical_name: name_in_file}`` for columns (CSV, Parquet) or message
        fields (MCAP) not named by the greybox convention, e.g.
        ``{"position_mm": "X1_ActualPosition", "current_A": "X1_CurrentFeedback"}``.
        A key may carry any supported unit (``"position_um"``, ``"velocity_mm_min"``).
    topic : str, optional
        MCAP channel to read; required when the file has several.
    sample_time : float, optional
        Sample time [s] for CSV/Parquet files without a time column; time is
        then ``row_index * sample_time`` from 0 s.
    time_tolerance : float or None, default 0.25
        Allowed deviation of a time step from the nominal step (fraction); None accepts any strictly
        increasing time (a log to be resampled, :func:`greybox.data.prepare.prepare`).
    fmt : {"csv", "parquet", "mcap", "mat", "tdms"}, optional
        Format, overriding the extension.
    axis : str, optional
        One axis of a file holding several: columns (fields, vectors, channels) named
        ``<axis>_<quantity>_<unit>`` (``X_position_mm``, ``X_current_A``; columns without a prefix,
        such as ``time_s``, are shared), or the MCAP channel ``/axis/<axis>``, or the TDMS group
        ``<axis>``.

    Returns
    -------
    AxisLog
        Channels in canonical units (s, mm, mm/s, mm/s^2, A or N); ``source`` is ``path``.

    Raises
    ------
    LogError
        For a missing, empty or unreadable file, an unknown extension, an
        option that does not apply to the format, or content that fails
        validation (see :func:`greybox.data.validate.check_time`).
    """
    path = os.fspath(path)
    if not os.path.exists(path):
        raise LogError(path, "no such file")
    if os.path.isdir(path):
        raise LogError(path, "is a directory, not a log file")
    fmt = format_of(path, fmt)
    if os.path.getsize(path) == 0:
        raise LogError(path, "empty file (0 bytes)")
    given = {"columns": columns, "topic": topic, "sample_time": sample_time, "axis": axis}
    accepted = LOG_FORMATS[fmt].options
    for option, value in given.items():
        if value is not None and option not in accepted:
            raise LogError(path, f"option '{option}' does not apply to {fmt} files")
    options = {option: given[option] for option in accepted}
    try:
        log = _handler(fmt)(path, **options)
    except OSError as exc:
        raise LogError(path, f"cannot read the file ({exc.strerror or exc})") from None
    if time_tolerance is None:
        check_increasing(log.time, source=path)
    else:
        check_time(log.time, source=path, tolerance=time_tolerance)
    check_finite(log)
    return log


def write_log(log: AxisLog | Sequence[AxisLog], path, *, fmt: str | None = None) -> None:
    """Write an axis log atomically.

    The data go to a temporary file in the target directory, which then
    replaces ``path`` in one step, so a reader never sees a half-written file.
    A CSV file gets its metadata in a sidecar ``<path>.json``
    (:mod:`greybox.data.csv_io`), written the same way.

    Parameters
    ----------
    log : AxisLog or sequence of AxisLog
        The log; or several logs of different axes: one channel each in MCAP, one table with
        columns ``X_position_mm, ...`` in CSV and Parquet (same time stamps needed).
    path : str or path-like
        Output file; the format follows from the extension.
    fmt : {"csv", "parquet", "mcap"}, optional
        Format, overriding the extension.

    Raises
    ------
    LogError
        For an unknown or read-only format, several logs that one table cannot hold,
        or a ``path`` that is the file a log was read from.
    """
    path = os.fspath(path)
    fmt = format_of(path, fmt)
    if LOG_FORMATS[fmt].writer is None:
        writable = ", ".join(entry.suffixes[0] for entry in LOG_FORMATS.values() if entry.writer is not None)
        raise LogError(path, f"{fmt} files can be read but not written; write {writable}")
    logs = [log] if isinstance(log, AxisLog) else list(log)
    if not logs:
        raise LogError(path, "no log to write")
    for item in logs:
        if item.source and os.path.exists(path) and os.path.exists(item.source) and os.path.samefile(path, item.source):
            raise LogError(path, "refusing to overwrite the file the log was read from; choose another output path")
    writer = _handler(fmt, writer=True)
    if fmt == "csv":  # two files, each replaced in one step: the plain CSV and its metadata sidecar
        target = os.path.abspath(path)
        with atomic_output(target) as temporary, atomic_output(sidecar_path(target)) as side:
            writer(logs, str(temporary), metadata_path=str(side))
        return
    with atomic_output(os.path.abspath(path)) as temporary:
        writer(logs, str(temporary))


def parse_column_mapping(text: str) -> dict[str, str]:
    """Parse a command-line column mapping.

    Parameters
    ----------
    text : str
        Comma-separated ``canonical_name=name_in_file`` pairs, e.g.
        ``"position_mm=X1_ActualPosition,current_A=X1_CurrentFeedback"``.
        Spaces around names are ignored. Names in the file may contain ``=``
        (the first ``=`` splits) but not commas.

    Returns
    -------
    dict of str to str

    Raises
    ------
    GreyboxError
        For a pair without ``=``, an empty name, a repeated key or a key that
        is not a quantity with a known unit.
    """
    mapping: dict[str, str] = {}
    known = ", ".join(CANONICAL_NAMES.values())
    for pair in text.split(","):
        if not pair.strip():
            continue
        if "=" not in pair:
            raise GreyboxError(f"column mapping: '{pair.strip()}' is not of the form canonical_name=column_in_file")
        key, value = (part.strip() for part in pair.split("=", 1))
        if not key or not value:
            raise GreyboxError(f"column mapping: empty name in '{pair.strip()}'")
        if not known_column(key):
            raise GreyboxError(f"column mapping: '{key}' is not a quantity with a known unit; use e.g. {known}")
        if key in mapping:
            raise GreyboxError(f"column mapping: '{key}' is given twice")
        mapping[key] = value
    if not mapping:
        raise GreyboxError("column mapping: no pairs given")
    return mapping
