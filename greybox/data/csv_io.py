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


#: Lines looked at to find the header below a preamble.
_HEAD_LINES = 200


def _fields(line: str, delimiter: str) -> list[str]:
    return [field.strip().strip('"') for field in line.rstrip("\r\n").split(delimiter)]


def _number(text: str, decimal: str) -> bool:
    try:
        float(text.replace(decimal, ".") if decimal != "." else text)
    except ValueError:
        return False
    return True


def _layout(path) -> tuple[int, int | None, dict, str, str, str]:
    """Where the header is and how the file is written.

    Returns the header's line index (below ``#`` comments and a controller's preamble of other lines), the
    index of a units row under it (or None), greybox metadata from a ``# greybox {...}`` comment, the header
    line, the delimiter and the decimal mark.
    """
    metadata, lines = {}, []
    try:
        with open(path, encoding="utf-8-sig", newline="") as stream:
            for index, line in zip(range(_HEAD_LINES), stream):
                if line.startswith(_METADATA_TAG):
                    metadata = parse_metadata(line[len(_METADATA_TAG):], path,
                                              f"line {index + 1}: greybox metadata")
                lines.append(line)
    except UnicodeDecodeError as exc:
        raise LogError(path, f"not UTF-8 text (byte {exc.start}); save the CSV as UTF-8") from None
    content = [(index, line) for index, line in enumerate(lines) if line.strip() and not line.startswith("#")]
    if not content:
        return len(lines), None, metadata, "", ",", "."
    # the data rows set the delimiter and the number of fields; the header is the first line of that many
    tail = [line for _, line in content[-5:]]
    # tab or semicolon when every data row holds one (a decimal comma then makes commas of its own)
    delimiter = next((mark for mark in ("\t", ";") if min(line.count(mark) for line in tail) > 0), ",")
    width = min(line.count(delimiter) for line in tail)
    header_at = next((k for k, (_, line) in enumerate(content) if line.count(delimiter) == width and width > 0), 0)
    header_index, header = content[header_at]
    rows = [line for _, line in content[header_at + 1:header_at + 3]]
    decimal = "," if delimiter == ";" and any("," in line for line in rows[-1:]) else "."
    units_index = None
    if len(rows) == 2:
        first, second = _fields(rows[0], delimiter), _fields(rows[1], delimiter)
        if not any(_number(text, decimal) for text in first) and any(_number(text, decimal) for text in second):
            units_index = content[header_at + 1][0]
    return header_index, units_index, metadata, header, delimiter, decimal


def _headers(header: str, units: str | None, delimiter: str) -> list[str]:
    """The column names: the header's, each with the unit of a units row below it as ``name [unit]``."""
    names = _fields(header, delimiter)
    if units is not None:
        written = _fields(units, delimiter)
        names = [f"{name} [{unit.strip('[]()')}]" if unit.strip("[]()") else name
                 for name, unit in zip(names, written + [""] * (len(names) - len(written)))]
    seen: dict[str, int] = {}
    for k, name in enumerate(names):  # a repeated header becomes name.1, name.2 (as pandas names them)
        if name in seen:
            seen[name] += 1
            names[k] = f"{name}.{seen[name]}"
        else:
            seen[name] = 0
    return names


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
    header_index, units_index, metadata, header, delimiter, decimal = _layout(path)
    sidecar = read_sidecar(path)
    if sidecar is not None:
        metadata = sidecar
    if not header.strip():
        raise LogError(path, "no header row (the file holds only comments or blank lines)")
    units = None
    if units_index is not None:
        with open(path, encoding="utf-8-sig", newline="") as stream:
            units = next(line for index, line in enumerate(stream) if index == units_index)
    skipped = set(range(header_index + 1)) | ({units_index} if units_index is not None else set())
    try:
        frame = pd.read_csv(
            path, skiprows=sorted(skipped), header=None, sep=delimiter, decimal=decimal, engine="c",
            low_memory=False, encoding="utf-8-sig",
        )
    except pd.errors.EmptyDataError:
        raise LogError(path, "no data rows (the file holds only a header)") from None
    except (pd.errors.ParserError, UnicodeDecodeError, csv.Error) as exc:
        line = str(exc).strip().splitlines()[0]
        raise LogError(path, f"malformed CSV ({line}); the header is line {header_index + 1} "
                             f"({header.strip()[:60]!r}), delimiter {delimiter!r}") from None
    names = _headers(header, units, delimiter)
    if frame.shape[1] != len(names):
        raise LogError(path, f"the rows hold {frame.shape[1]} fields, the header (line {header_index + 1}) "
                             f"{len(names)}")
    frame.columns = range(len(names))
    if frame.empty:
        raise LogError(path, "no data rows (the file holds only a header)")
    table = {name: frame[k].to_numpy() for k, name in enumerate(names)}
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
