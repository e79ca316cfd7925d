"""CSV axis logs: one row per sample, one column per channel, unit suffix in each header.

Written by :func:`write_csv` as two files. ``x.csv`` is plain CSV, its first
line the header, so that ``pandas.read_csv``, a spreadsheet or MATLAB's
``readtable`` read it with default settings::

    time_s,position_mm,velocity_mm_s,current_A,truth_friction_A
    0.0,12.5,0.0,0.31,0.02
    ...

and the sidecar ``x.csv.json`` holds the metadata
(:mod:`greybox.data.file_metadata`)::

    {"axis": "X", "dataset": "A", "effort_unit": "A", "attrs": {...}}

Read by :func:`read_csv` (UTF-8, with or without byte-order mark): the
metadata come from the sidecar when there is one; leading lines starting with
``#`` are comments, and a ``# greybox {...}`` comment (how earlier versions
stored the metadata) restores them for a file without sidecar. The delimiter is
detected from the header line (comma, semicolon or tab); with a semicolon
delimiter a decimal comma is accepted. Column names follow
:mod:`greybox.data.units`.
"""

from __future__ import annotations

import csv
from typing import Mapping, Sequence

import pandas as pd

from ..errors import LogError
from .file_metadata import logs_metadata, metadata_fields, parse_metadata, read_sidecar, sidecar_path, sidecar_text
from .log import AxisLog
from .units import log_from_columns, several_axes_table

__all__ = ["read_csv", "write_csv"]

_METADATA_TAG = "# greybox "


def _preamble(path) -> tuple[int, dict, str]:
    """Count leading comment lines, parse greybox metadata, return the header line."""
    comments, metadata = 0, {}
    try:
        with open(path, encoding="utf-8-sig", newline="") as stream:
            for line in stream:
                if not line.startswith("#"):
                    return comments, metadata, line
                if line.startswith(_METADATA_TAG):
                    metadata = parse_metadata(line[len(_METADATA_TAG):], path,
                                              f"line {comments + 1}: greybox metadata")
                comments += 1
    except UnicodeDecodeError as exc:
        raise LogError(path, f"not UTF-8 text (byte {exc.start}); save the CSV as UTF-8") from None
    return comments, metadata, ""


def read_csv(path, *, columns: Mapping[str, str] | None = None, sample_time: float | None = None,
             axis: str | None = None) -> AxisLog:
    """Read a CSV axis log.

    Parameters
    ----------
    path : str or path-like
        CSV file with a header row. Its metadata (axis, dataset, effort unit,
        attrs) are read from the sidecar ``<path>.json`` if it exists, else
        from a ``# greybox {...}`` comment line.
    columns : mapping of str to str, optional
        ``{canonical_name: header}`` for headers not named by the convention.
    sample_time : float, optional
        Sample time [s] for files without a time column.
    axis : str, optional
        Axis to read from a file holding several, its columns named ``<axis>_<quantity>_<unit>``
        (``X_position_mm``; :func:`greybox.data.units.select_axis`).

    Returns
    -------
    AxisLog
        Not yet validated; :func:`greybox.data.io.read_log` validates.

    Raises
    ------
    LogError
        For a file without header or data rows, malformed rows, or columns
        that do not give the required channels (see :func:`~greybox.data.units.log_from_columns`),
        and for a sidecar that is not a JSON object.
    """
    comments, metadata, header = _preamble(path)
    sidecar = read_sidecar(path)
    if sidecar is not None:
        metadata = sidecar
    if not header.strip():
        raise LogError(path, "no header row (the file holds only comments or blank lines)")
    delimiter = max((",", ";", "\t"), key=header.count)
    decimal = "."
    if delimiter == ";":
        with open(path, encoding="utf-8-sig") as stream:
            lines = [line for _, line in zip(range(comments + 2), stream)][comments + 1:]
        if lines and "," in lines[0]:
            decimal = ","
    try:
        frame = pd.read_csv(
            path, skiprows=comments, sep=delimiter, decimal=decimal, engine="c", low_memory=False, encoding="utf-8-sig"
        )
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError, csv.Error) as exc:
        raise LogError(path, f"malformed CSV ({str(exc).strip().splitlines()[0]})") from None
    if frame.empty:
        raise LogError(path, "no data rows (the file holds only a header)")
    table = {str(name).strip(): frame[name].to_numpy() for name in frame.columns}
    return log_from_columns(table, source=path, columns=columns, sample_time=sample_time, select=axis,
                            **metadata_fields(metadata, axis))


def write_csv(log: AxisLog | Sequence[AxisLog], path, *, metadata_path=None) -> None:
    """Write an axis log as plain CSV with canonical headers, and its metadata as a JSON sidecar.

    Floats are written with the shortest text that reads back to the same
    value, so a round trip is exact.

    Parameters
    ----------
    log : AxisLog or sequence of AxisLog
        One log, or several axes on the same time stamps: one table with the columns
        ``time_s, X_position_mm, ...`` (:func:`~greybox.data.units.several_axes_table`).
    path : str or path-like
        CSV file; its first line is the header. Written in place;
        :func:`greybox.data.io.write_log` makes it atomic.
    metadata_path : str or path-like, optional
        Where to write the metadata JSON; default the sidecar of ``path``
        (:func:`~greybox.data.file_metadata.sidecar_path`, ``<path>.json``).
        :func:`greybox.data.io.write_log` passes a temporary file that then
        replaces the sidecar.
    """
    logs = [log] if isinstance(log, AxisLog) else list(log)
    with open(path, "w", encoding="utf-8", newline="") as stream:
        pd.DataFrame(several_axes_table(logs, source=path)).to_csv(stream, index=False, lineterminator="\n")
    side = sidecar_path(path) if metadata_path is None else metadata_path
    with open(side, "w", encoding="utf-8", newline="\n") as stream:
        stream.write(sidecar_text(logs_metadata(logs)))
