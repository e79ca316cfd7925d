"""The messages of a live stream: samples in, estimates out.

An input message holds one sample or a batch of samples of one axis, with the column names the log
readers know (``time_s``, ``position_mm``, ``velocity_mm_s``, ``current_A``, ...; units as in a CSV
header, :mod:`greybox.data.units`):

* JSON, one sample: ``{"time_s": 0.002, "position_mm": -250.0, "velocity_mm_s": 12.5, "current_A": 0.41}``;
* JSON, a batch as columns: ``{"time_s": [0.002, 0.004], "position_mm": [...], ...}``;
* JSON, a batch as rows: ``[{"time_s": 0.002, ...}, {"time_s": 0.004, ...}]``;
* a CSV line, after a header line naming the columns (stdin only).

A message may carry ``"seq"`` (any JSON number or string); the estimates it completes carry it back, so a
publisher can match them. An output message (:func:`estimate_message`) holds the columns ``greybox
predict`` writes (:meth:`greybox.predict.process.ProcessResult.columns`) for the samples it completes.
"""

from __future__ import annotations

import json
from typing import Mapping

import msgspec
import numpy as np

from ..data.log import AxisLog
from ..data.units import log_from_columns
from ..errors import GreyboxError, LogError

__all__ = ["MessageError", "SEQUENCE_KEY", "MAX_MESSAGE_SAMPLES", "MAX_MESSAGE_BYTES", "parse_json",
           "parse_csv_row", "csv_header", "Decoder", "message_log", "estimate_message"]

#: Key of a message's sequence tag, echoed in the estimates it completes.
SEQUENCE_KEY = "seq"

#: Most samples one message may hold (a minute at 500 Hz is 30 000); a larger one is refused.
MAX_MESSAGE_SAMPLES = 100_000

#: Most bytes of one message.
MAX_MESSAGE_BYTES = 64 << 20


class MessageError(GreyboxError):
    """A message that cannot be used: malformed, of the wrong shape, or holding values out of range."""


def _column(name: str, values) -> np.ndarray:
    """One column of a message as a float array; refuses text, nested lists and booleans."""
    if type(values) in (int, float):
        return np.array([values], dtype=np.float64)
    if type(values) is list and all(type(value) in (int, float) for value in values):
        return np.array(values, dtype=np.float64)
    array = np.asarray(values, dtype=object)
    if array.ndim > 1:
        raise MessageError(f"column '{name}' holds nested lists, not numbers")
    array = array.reshape(-1)
    out = np.empty(array.size)
    for k, value in enumerate(array):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise MessageError(f"column '{name}' holds {value!r}, not a number")
        out[k] = value
    return out


def parse_json(text: str | bytes) -> tuple[dict[str, np.ndarray], object]:
    """The columns and the sequence tag of one JSON message.

    Parameters
    ----------
    text : str or bytes
        The message (UTF-8).

    Returns
    -------
    columns : dict of str to ndarray
        Equal-length columns in the message's units.
    seq : object
        The message's ``"seq"``, or None.

    Raises
    ------
    MessageError
        For text that is not JSON, not an object or a list of objects, columns of different lengths or
        values that are not numbers.
    """
    if len(text) > MAX_MESSAGE_BYTES:
        raise MessageError(f"the message holds {len(text)} bytes, more than {MAX_MESSAGE_BYTES}")
    try:  # msgspec reads strict JSON a few times faster; json.loads takes what it refuses (NaN) or explains why
        value = _DECODER.decode(text)
    except msgspec.DecodeError:
        value = None
    try:
        value = json.loads(text) if value is None else value
    except (ValueError, UnicodeDecodeError) as exc:
        raise MessageError(f"not JSON ({exc})") from None
    seq = None
    if isinstance(value, list):
        if not value or not all(isinstance(row, dict) for row in value):
            raise MessageError("a JSON list must hold one object per sample")
        seq = value[0].get(SEQUENCE_KEY)
        names = [name for name in value[0] if name != SEQUENCE_KEY]
        for k, row in enumerate(value):
            keys = set(row) - {SEQUENCE_KEY}
            if keys != set(names):
                raise MessageError(f"sample {k} of the batch has other columns than sample 0")
        columns = {name: _column(name, [row[name] for row in value]) for name in names}
    elif isinstance(value, dict):
        seq = value.get(SEQUENCE_KEY)
        columns = {name: _column(name, column) for name, column in value.items() if name != SEQUENCE_KEY}
    else:
        raise MessageError("a message must be a JSON object (one sample, or columns of a batch) or a list of objects")
    lengths = {len(column) for column in columns.values()}
    if not columns or lengths == {0}:
        raise MessageError("the message holds no samples")
    if len(lengths) > 1:
        raise MessageError(f"the columns have different lengths ({', '.join(map(str, sorted(lengths)))})")
    if max(lengths) > MAX_MESSAGE_SAMPLES:
        raise MessageError(f"the message holds {max(lengths)} samples, more than {MAX_MESSAGE_SAMPLES}")
    return columns, seq


def csv_header(line: str) -> list[str]:
    """The column names of a CSV header line.

    Parameters
    ----------
    line : str
        The header line (comma-separated names).

    Raises
    ------
    MessageError
        For an empty or repeated column name.
    """
    names = [name.strip() for name in line.strip().split(",")]
    if not all(names) or len(set(names)) != len(names):
        raise MessageError(f"CSV header {line.strip()!r}: column names must be non-empty and distinct")
    return names


def parse_csv_row(line: str, header: list[str]) -> dict[str, np.ndarray]:
    """The one-sample columns of a CSV data line.

    Parameters
    ----------
    line : str
        Comma-separated numbers, one per column of the header.
    header : list of str
        The column names (:func:`csv_header`).

    Raises
    ------
    MessageError
        For a wrong number of fields or a field that is not a number.
    """
    fields = line.strip().split(",")
    if len(fields) != len(header):
        raise MessageError(f"CSV line has {len(fields)} fields, the header names {len(header)}")
    columns = {}
    for name, field in zip(header, fields):
        try:
            columns[name] = np.array([float(field)])
        except ValueError:
            raise MessageError(f"column '{name}' holds {field.strip()!r}, not a number") from None
    return columns


class Decoder:
    """The columns of each message of a stream: JSON messages, or CSV lines after a header line.

    A payload starting with ``{`` or ``[`` is JSON; any other is a CSV line, after a header that must be
    the stream's first line. Lines starting with ``#`` are comments (a CSV log's metadata preamble).

    Attributes
    ----------
    header : list of str or None
        The CSV header once read.
    """

    def __init__(self):
        self.header: list[str] | None = None
        self._started = False

    def decode(self, payload: str | bytes) -> tuple[dict[str, np.ndarray], object] | None:
        """The columns and the sequence tag of one message; None for a CSV header or a comment.

        Parameters
        ----------
        payload : str or bytes
            The message (UTF-8).

        Raises
        ------
        MessageError
            For a message that cannot be read (see :func:`parse_json`, :func:`parse_csv_row`).
        """
        if isinstance(payload, bytes):
            try:
                payload = payload.decode("utf-8")
            except UnicodeDecodeError:
                raise MessageError("not UTF-8 text") from None
        text = payload.strip()
        if not text or text.startswith("#"):
            return None
        first, self._started = not self._started, True
        if text[0] in "{[":
            return parse_json(text)
        if self.header is None:
            if not first:
                raise MessageError("not JSON (a CSV header must be the stream's first line)")
            self.header = csv_header(text)
            return None
        return parse_csv_row(text, self.header), None


def message_log(columns: Mapping[str, np.ndarray], *, name: str, mapping: Mapping[str, str] | None = None,
                axis: str | None = None) -> AxisLog:
    """The samples of a message as an axis log in canonical units (s, mm, mm/s, A), checked finite.

    Parameters
    ----------
    columns : mapping of str to ndarray
        The message's columns (:func:`parse_json`, :func:`parse_csv_row`).
    name : str
        How the message is named in errors (e.g. ``"message 12 on axis/X"``).
    mapping : mapping of str to str, optional
        ``{canonical_name: column}`` for columns not named by the convention (the axis file's channels).
    axis : str, optional
        Axis to take from a message holding several (columns ``<axis>_<quantity>_<unit>``).

    Returns
    -------
    AxisLog
        Without extra columns.

    Raises
    ------
    MessageError
        For missing columns, unknown units, a time column missing, or a value that is NaN or infinite.
    """
    try:
        log = log_from_columns(columns, source=name, columns=mapping or None, select=axis)
    except LogError as exc:
        raise MessageError(exc.problem) from None
    for channel, values in log.named_channels(time=True):
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise MessageError(f"channel '{channel}' holds {values[bad[0]]} at sample {bad[0]} of the message")
    return log.replace(extras={}) if log.extras else log


def estimate_message(columns: Mapping[str, np.ndarray], seq=None, axis: str | None = None) -> str:
    """The JSON text of one output message: the estimate's columns as lists, and the sequence tag.

    Parameters
    ----------
    columns : mapping of str to ndarray
        The output columns of the samples (``time_s``, ``current_process_A``, ``force_process_N``, ...).
    seq : object, optional
        The ``"seq"`` of the input message that completed these samples.
    axis : str, optional
        The axis of a machine the estimates are of (key ``"axis"``).
    """
    out: dict = {name: np.asarray(values, dtype=np.float64).tolist() for name, values in columns.items()}
    if seq is not None:
        out[SEQUENCE_KEY] = seq
    if axis is not None:
        out["axis"] = axis
    # msgspec writes a float's shortest round-trip digits ten times faster than json, NaN and inf as null
    return _ENCODER.encode(out).decode()


#: One encoder for every output message, one decoder for every input message.
_ENCODER, _DECODER = msgspec.json.Encoder(), msgspec.json.Decoder()
