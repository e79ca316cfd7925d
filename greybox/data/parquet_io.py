"""Parquet axis logs: canonical columns plus extras; metadata in the schema.

:func:`write_parquet` writes the columns of :meth:`AxisLog.to_frame` (``time_s``,
``position_mm``, ``velocity_mm_s``, ``acceleration_mm_s2``, ``current_A`` or
``force_N``, extras) as float64, zstd-compressed, and stores
``{"axis", "dataset", "effort_unit", "attrs"}`` as JSON under the key
``greybox`` of the schema metadata. :func:`read_parquet` reads any Parquet
file whose column names follow :mod:`greybox.data.units` (or a ``columns=``
mapping); the metadata is optional.
"""

from __future__ import annotations

import json
from typing import Mapping, Sequence

import numpy as np

from ..errors import LogError
from .file_metadata import logs_metadata, metadata_fields, parse_metadata
from .log import AxisLog
from .units import log_from_columns, several_axes_table

__all__ = ["read_parquet", "write_parquet"]

_METADATA_KEY = b"greybox"


def read_parquet(path, *, columns: Mapping[str, str] | None = None, sample_time: float | None = None,
                 axis: str | None = None) -> AxisLog:
    """Read a Parquet axis log.

    Parameters
    ----------
    path : str or path-like
    columns : mapping of str to str, optional
        ``{canonical_name: column}`` for columns not named by the convention.
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
        For a file that is not Parquet, holds no rows, or lacks required columns.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(path)
    except (pa.ArrowException, OSError) as exc:
        raise unreadable(path, exc) from None
    if table.num_rows == 0:
        raise LogError(path, "no data rows")
    return log_from_columns(column_arrays(table.column_names, table.columns), source=path, columns=columns,
                            sample_time=sample_time, select=axis, **schema_fields(table.schema, path, axis))


def unreadable(path, error: Exception) -> LogError:
    """The error of a file pyarrow cannot open as Parquet."""
    return LogError(path, f"not a readable Parquet file ({str(error).strip().splitlines()[0]})")


def schema_fields(schema, path, axis: str | None = None) -> dict:
    """The log's axis, dataset, effort unit and attrs from the greybox metadata of an Arrow schema."""
    raw = (schema.metadata or {}).get(_METADATA_KEY)
    return metadata_fields(parse_metadata(raw, path, "the greybox schema metadata") if raw else {}, axis)


def column_arrays(names, columns) -> dict[str, np.ndarray]:
    """Arrow columns (of a table or a record batch) as arrays: numeric ones as numbers, others as objects."""
    import pyarrow as pa

    arrays = {}
    for name, column in zip(names, columns):
        kind = column.type
        numeric = pa.types.is_integer(kind) or pa.types.is_floating(kind) or pa.types.is_boolean(kind)
        arrays[name] = (column.to_numpy(zero_copy_only=False) if numeric
                        else column.to_numpy(zero_copy_only=False).astype(object))
    return arrays


def write_parquet(log: AxisLog | Sequence[AxisLog], path) -> None:
    """Write an axis log as Parquet (float64 columns, zstd, metadata in the schema).

    Parameters
    ----------
    log : AxisLog or sequence of AxisLog
        One log, or several axes on the same time stamps: one table with the columns
        ``time_s, X_position_mm, ...`` (:func:`~greybox.data.units.several_axes_table`).
    path : str or path-like
        Written in place; :func:`greybox.data.io.write_log` makes it atomic.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    logs = [log] if isinstance(log, AxisLog) else list(log)
    table = pa.table(
        {name: np.asarray(values, dtype=np.float64) for name, values in several_axes_table(logs, source=path).items()},
        metadata={_METADATA_KEY: json.dumps(logs_metadata(logs)).encode()},
    )
    pq.write_table(table, path, compression="zstd")
