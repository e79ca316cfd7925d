"""Axis logs: the in-memory type, readers and writers, validation and preparation."""

from .log import AxisLog, as_log_list

__all__ = ["AxisLog", "as_log_list"]
