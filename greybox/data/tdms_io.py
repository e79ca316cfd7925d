"""TDMS axis logs (National Instruments, e.g. a CompactRIO recording a SINUMERIK axis data stream), via npTDMS.

A TDMS file holds groups of channels. One group is one log: the group named
by ``topic`` (``--topic``), or the file's only group. Its channels are the
columns, named like CSV columns (``position_mm``, ``current_A``, any supported
unit suffix) or mapped with ``columns`` (``--columns
position_mm=X1_Pos,current_A=X1_Iq``). Time comes from a time channel
(``time_s`` or mapped), else from the channels' waveform properties
(``wf_start_offset`` and ``wf_increment``, as LabVIEW writes waveforms), else
from ``sample_time``. Only numeric channels of the group's common length are
columns.
"""

from __future__ import annotations

import contextlib
import logging
import warnings
from pathlib import Path
from typing import Mapping

import numpy as np

from ..errors import LogError
from .log import AxisLog
from .units import log_from_columns, parse_column_name

__all__ = ["read_tdms"]


def _group(tdms, path, topic: str | None):
    groups = tdms.groups()
    names = [group.name for group in groups]
    if topic is not None:
        for group in groups:
            if group.name == topic:
                return group
        raise LogError(path, f"no TDMS group '{topic}'; the file holds {', '.join(names) or 'none'}")
    if len(groups) != 1:
        listed = ", ".join(names) or "none"
        raise LogError(path, f"the file holds {len(groups)} TDMS groups ({listed}); choose one with --topic GROUP")
    return groups[0]


@contextlib.contextmanager
def _notes_of_nptdms(path):
    """npTDMS's log messages (a truncated last segment, ...) as warnings naming the file, not log lines; none when
    the read fails (its error says it all)."""

    class Collect(logging.Handler):
        def emit(self, record):
            messages.append(record.getMessage())

    messages: list[str] = []
    collector = Collect(logging.WARNING)
    loggers = [logging.getLogger(name) for name in list(logging.Logger.manager.loggerDict)
               if name == "nptdms" or name.startswith("nptdms.")]
    saved = [(logger, list(logger.handlers), logger.propagate) for logger in loggers]
    for logger in loggers:
        logger.handlers = [collector]
        logger.propagate = False
    try:
        yield
    finally:
        for logger, handlers, propagate in saved:
            logger.handlers, logger.propagate = handlers, propagate
    for message in dict.fromkeys(messages):  # only when the file was read: a failed read is its error alone
        shown = message if len(message) <= 200 else message[:200] + "..."
        warnings.warn(f"{path}: {shown} (npTDMS)", stacklevel=3)


def _has_time_column(names, columns: Mapping[str, str] | None) -> bool:
    """True if a channel name, or a key of the mapping, names the time."""
    return any((parse_column_name(name) or (None,))[0] == "time" for name in [*names, *(columns or {})])


def read_tdms(path, *, columns: Mapping[str, str] | None = None, topic: str | None = None,
              sample_time: float | None = None, axis: str | None = None) -> AxisLog:
    """Read one group of a TDMS file as an axis log.

    Parameters
    ----------
    path : str or path-like
        TDMS file.
    columns : mapping of str to str, optional
        ``{canonical_name: channel}`` for channels not named by the convention.
    topic : str, optional
        Group to read; required when the file holds several.
    sample_time : float, optional
        Sample time [s] for a group with neither a time channel nor waveform properties.
    axis : str, optional
        Axis to read from a file holding several: the group of that name if there is one (and no
        ``topic``), else the group's channels named ``<axis>_<quantity>_<unit>``
        (:func:`greybox.data.units.select_axis`).

    Returns
    -------
    AxisLog
        Not yet validated; :func:`greybox.data.io.read_log` validates.

    Raises
    ------
    LogError
        For a file that is not TDMS, a missing or ambiguous group, or missing channels.
    """
    from nptdms import TdmsFile

    with _notes_of_nptdms(path):
        try:
            tdms = TdmsFile.read(path)
        except Exception as exc:  # npTDMS raises ValueError, KeyError, struct.error ... on corrupt files
            raise LogError(path, f"not a readable TDMS file ({type(exc).__name__}: {exc})") from None
    select = axis
    if axis is not None and topic is None and any(group.name == axis for group in tdms.groups()):
        topic, select = axis, None
    group = _group(tdms, path, topic)
    numeric = [(channel, data) for channel, data in ((channel, np.asarray(channel[:])) for channel in group.channels())
               if data.dtype.kind in "biuf"]
    if not numeric:
        raise LogError(path, f"TDMS group '{group.name}' holds no numeric channel")
    lengths = [data.size for _, data in numeric]
    common = max(set(lengths), key=lengths.count)
    kept = [(channel, data) for channel, data in numeric if data.size == common]
    table = {channel.name: data.astype(np.float64) for channel, data in kept}
    time = None
    if not _has_time_column(table, columns) and sample_time is None and "wf_increment" in kept[0][0].properties:
        time = np.asarray(kept[0][0].time_track(), dtype=np.float64)
    return log_from_columns(table, source=str(path), columns=columns, time=time, sample_time=sample_time,
                            dataset=Path(path).stem, axis=group.name if topic is not None else "", select=select)
