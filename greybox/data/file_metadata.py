"""The greybox metadata that CSV and Parquet logs carry beside their columns.

One JSON object, ``{"axis", "dataset", "effort_unit", "attrs"}``: CSV keeps it
in a ``# greybox {...}`` comment line, Parquet under the key ``greybox`` of the
schema metadata. Every key is optional when reading.
"""

from __future__ import annotations

from typing import Mapping

from .log import AxisLog

__all__ = ["log_metadata", "metadata_fields"]


def log_metadata(log: AxisLog) -> dict[str, object]:
    """The metadata object written with a log (JSON-able)."""
    return {"axis": log.axis, "dataset": log.dataset, "effort_unit": log.effort_unit, "attrs": log.attrs}


def metadata_fields(metadata: Mapping[str, object]) -> dict[str, object]:
    """Keyword arguments of :func:`greybox.data.units.log_from_columns` from a read metadata object.

    Parameters
    ----------
    metadata : mapping
        The decoded JSON object; missing keys give an unknown effort unit,
        empty axis and dataset names and no attrs.
    """
    return {
        "effort_unit": metadata.get("effort_unit"),
        "axis": str(metadata.get("axis", "")),
        "dataset": str(metadata.get("dataset", "")),
        "attrs": metadata.get("attrs", {}),
    }
