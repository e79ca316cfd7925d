"""The greybox metadata that CSV and Parquet logs carry beside their columns.

One JSON object, ``{"axis", "dataset", "effort_unit", "attrs"}``: a CSV file
``x.csv`` keeps it in the sidecar file ``x.csv.json`` beside it (so the CSV
itself starts with its header and any spreadsheet or ``pandas.read_csv`` reads
it with default settings), Parquet under the key ``greybox`` of the schema
metadata. Every key is optional when reading. CSV files written by earlier
greybox versions hold it in a first ``# greybox {...}`` comment line instead,
which is still read.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Mapping

from ..errors import LogError
from .log import AxisLog

__all__ = ["SIDECAR_SUFFIX", "log_metadata", "logs_metadata", "metadata_fields", "parse_metadata", "read_sidecar",
           "sidecar_path", "sidecar_text"]

#: Appended to a CSV file's name to give its metadata file: ``x.csv`` -> ``x.csv.json``.
SIDECAR_SUFFIX = ".json"


def log_metadata(log: AxisLog) -> dict[str, object]:
    """The metadata object written with a log (JSON-able).

    Parameters
    ----------
    log : AxisLog
        The log whose axis, dataset, effort unit and attrs are taken.
    """
    return {"axis": log.axis, "dataset": log.dataset, "effort_unit": log.effort_unit, "attrs": log.attrs}


def logs_metadata(logs) -> dict[str, object]:
    """The metadata object written with one log, or with several axes in one table: ``{"axes": {axis: ...}}``.

    Parameters
    ----------
    logs : iterable of AxisLog
        The logs written to one file: one, or several axes on the same time stamps.
    """
    logs = list(logs)
    if len(logs) == 1:
        return log_metadata(logs[0])
    return {"axes": {log.axis: log_metadata(log) for log in logs}}


def parse_metadata(text: str | bytes, source, what: str = "greybox metadata") -> dict:
    """The metadata object of JSON ``text``.

    Parameters
    ----------
    text : str or bytes
        The JSON text (bytes are decoded as UTF-8).
    source : str or path-like or None
        The file it was read from, for error messages.
    what : str, default "greybox metadata"
        What the text is, for error messages ("metadata file").

    Raises
    ------
    LogError
        Naming ``source`` and ``what``, for text that is not UTF-8, not JSON (or nested or numbered
        beyond what JSON readers take), or JSON that is not an object.
    """
    try:
        metadata = json.loads(text)
    except UnicodeDecodeError as exc:
        raise LogError(source, f"{what} is not UTF-8 text (byte {exc.start})") from None
    except json.JSONDecodeError as exc:
        raise LogError(source, f"{what} is not valid JSON (line {exc.lineno}: {exc.msg})") from None
    except (ValueError, RecursionError) as exc:  # a number of too many digits, nesting too deep
        raise LogError(source, f"{what} is not JSON greybox reads ({type(exc).__name__}: {exc})") from None
    if not isinstance(metadata, dict):
        raise LogError(source, f"{what} holds a JSON {type(metadata).__name__}, not an object")
    return metadata


def metadata_fields(metadata: Mapping[str, object], axis: str | None = None) -> dict[str, object]:
    """Keyword arguments of :func:`greybox.data.units.log_from_columns` from a read metadata object.

    Parameters
    ----------
    metadata : mapping
        The decoded JSON object; missing keys give an unknown effort unit,
        empty axis and dataset names and no attrs.
    axis : str, optional
        The axis read from a table of several: its entry of ``metadata["axes"]``.
    """
    if isinstance(metadata.get("axes"), dict):
        entry = metadata["axes"].get(axis) if axis is not None else None
        metadata = entry if isinstance(entry, dict) else {}
    unit, attrs = metadata.get("effort_unit"), metadata.get("attrs", {})
    return {
        "effort_unit": unit if isinstance(unit, str) else None,
        "axis": str(metadata.get("axis", "")),
        "dataset": str(metadata.get("dataset", "")),
        "attrs": attrs if isinstance(attrs, dict) else {"attrs": attrs},
    }


def sidecar_path(path: str | os.PathLike) -> Path:
    """The metadata file beside a CSV file: its full name plus ``.json`` (``x.csv`` -> ``x.csv.json``).

    The whole name is kept, rather than the extension replaced, so that the
    sidecar never collides with a JSON file of the same stem (``metrics.csv``
    and ``metrics.json`` of a report, ``x.csv`` and ``x.json`` of a user).

    Parameters
    ----------
    path : str or path-like
        The CSV file.
    """
    path = Path(path)
    return path.with_name(path.name + SIDECAR_SUFFIX)


def sidecar_text(metadata: Mapping[str, object]) -> str:
    """The text of a sidecar file: the metadata object as indented JSON.

    Parameters
    ----------
    metadata : mapping
        The metadata object (:func:`log_metadata` or :func:`logs_metadata`); must be JSON-able.
    """
    return json.dumps(dict(metadata), indent=1) + "\n"


def read_sidecar(path: str | os.PathLike) -> dict | None:
    """The metadata object of the sidecar of ``path``, or None if there is no sidecar.

    Parameters
    ----------
    path : path-like
        The CSV file (not the sidecar).

    Returns
    -------
    dict or None

    Raises
    ------
    LogError
        If the sidecar exists but is not UTF-8 JSON holding an object.
    """
    side = sidecar_path(path)
    if not side.is_file():
        return None
    data = side.read_bytes()
    return parse_metadata(data[3:] if data.startswith(b"\xef\xbb\xbf") else data, side, "metadata file")
