"""Axis logs: the in-memory type, readers and writers, validation and preparation."""

from .io import parse_column_mapping, read_log, write_log
from .log import AxisLog, as_log_list
from .prepare import default_cutoff, derive, prepare, resample, trim
from .validate import check_finite, check_time

__all__ = [
    "AxisLog",
    "as_log_list",
    "read_log",
    "write_log",
    "parse_column_mapping",
    "check_time",
    "check_finite",
    "prepare",
    "derive",
    "resample",
    "trim",
    "default_cutoff",
]
