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
import math
import re
from dataclasses import dataclass
from typing import Mapping, Union

import msgspec
import numpy as np

from ..data.log import AxisLog
from ..data.units import EFFORT_QUANTITIES, log_from_columns, resolve_table
from ..errors import GreyboxError, LogError

__all__ = ["MessageError", "SEQUENCE_KEY", "MAX_MESSAGE_SAMPLES", "MAX_MESSAGE_BYTES", "MAX_MESSAGE_DEPTH",
           "MessageBounds", "DEFAULT_BOUNDS", "json_depth", "parse_json",
           "parse_csv_row", "csv_header", "Decoder", "message_log", "MessageLogs", "estimate_message",
           "finite_rows"]

#: Key of a message's sequence tag, echoed in the estimates it completes.
SEQUENCE_KEY = "seq"

#: Most samples one message may hold (a minute at 500 Hz is 30 000); a larger one is refused.
MAX_MESSAGE_SAMPLES = 100_000

#: Most bytes of one message by default (16 MiB: a minute at 500 Hz of five columns takes about 3 MB).
MAX_MESSAGE_BYTES = 16 << 20

#: Deepest nesting of JSON arrays and objects in a message by default (the shapes read need 2).
MAX_MESSAGE_DEPTH = 8


@dataclass(frozen=True)
class MessageBounds:
    """The largest message a stream takes; a larger one is refused before it is decoded.

    Attributes
    ----------
    max_bytes : int
        Most bytes of one message.
    max_depth : int
        Deepest nesting of JSON arrays and objects.
    max_samples : int
        Most samples of one message.
    """

    max_bytes: int = MAX_MESSAGE_BYTES
    max_depth: int = MAX_MESSAGE_DEPTH
    max_samples: int = MAX_MESSAGE_SAMPLES

    def __post_init__(self):
        for name in ("max_bytes", "max_depth", "max_samples"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"{name} must be a positive integer, got {value!r}")


#: The bounds of a stream's messages by default.
DEFAULT_BOUNDS = MessageBounds()

#: The string literals of JSON text (escapes included), left out when the nesting is counted.
_STRING = re.compile(rb'"(?:[^"\\]|\\.)*"', re.DOTALL)
_OPENING, _CLOSING = np.frombuffer(b"[{", dtype=np.uint8), np.frombuffer(b"]}", dtype=np.uint8)


def json_depth(text: str | bytes) -> int:
    """The deepest nesting of arrays and objects in JSON text, counted without parsing it (no recursion).

    Brackets inside string literals are not counted; in text that is not JSON the count is an upper bound.

    Parameters
    ----------
    text : str or bytes
        The text.
    """
    data = text.encode("utf-8", "surrogatepass") if isinstance(text, str) else bytes(text)
    codes = np.frombuffer(_STRING.sub(b"", data), dtype=np.uint8)
    if not codes.size:
        return 0
    steps = np.isin(codes, _OPENING).astype(np.int64) - np.isin(codes, _CLOSING)
    return max(0, int(np.cumsum(steps).max()))


class MessageError(GreyboxError):
    """A message that cannot be used: malformed, of the wrong shape, or holding values out of range."""


def _column(name: str, values) -> np.ndarray:
    """One column of a message as a float array; refuses text, nested lists and booleans.

    A JSON ``null`` is a missing value: NaN, which ``--max-gap`` bridges as a gap and which is refused
    without it, as a NaN is.
    """
    if values is None or type(values) in (int, float):
        return np.array([np.nan if values is None else values], dtype=np.float64)
    if type(values) is list and all(value is None or type(value) in (int, float) for value in values):
        return np.array(values, dtype=np.float64)  # numpy reads None as NaN
    array = np.asarray(values, dtype=object)
    if array.ndim > 1:
        raise MessageError(f"column '{name}' holds nested lists, not numbers")
    array = array.reshape(-1)
    out = np.empty(array.size)
    for k, value in enumerate(array):
        if isinstance(value, bool) or not isinstance(value, (int, float, type(None))):
            raise MessageError(f"column '{name}' holds {value!r}, not a number")
        out[k] = np.nan if value is None else value
    return out


def parse_json(text: str | bytes, bounds: MessageBounds = DEFAULT_BOUNDS) -> tuple[dict[str, np.ndarray], object]:
    """The columns and the sequence tag of one JSON message.

    Parameters
    ----------
    text : str or bytes
        The message (UTF-8).
    bounds : MessageBounds, optional
        The largest message taken (size, nesting, samples).

    Returns
    -------
    columns : dict of str to ndarray
        Equal-length columns in the message's units.
    seq : object
        The message's ``"seq"``, or None.

    Raises
    ------
    MessageError
        For text that is not JSON, not an object or a list of objects, columns of different lengths,
        values that are not numbers, or a message beyond ``bounds``.
    """
    _check_size(len(text), bounds)
    decoded = _typed_columns(text)
    if decoded is not None:
        columns, seq = decoded
        return _checked(columns, bounds), seq
    depth = json_depth(text)  # the general readers below recurse once per level: bounded first
    if depth > bounds.max_depth:
        raise MessageError(f"JSON nested {depth} levels deep, more than {bounds.max_depth}")
    try:  # msgspec reads strict JSON a few times faster; json.loads takes what it refuses (NaN) or explains why
        value = _DECODER.decode(text)
    except msgspec.DecodeError:
        value = None
    try:
        value = json.loads(text) if value is None else value
    except (ValueError, UnicodeDecodeError, RecursionError) as exc:
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
    return _checked(columns, bounds), seq


def _check_size(size: int, bounds: MessageBounds) -> None:
    if size > bounds.max_bytes:
        raise MessageError(f"the message holds {size} bytes, more than {bounds.max_bytes}")


def _typed_columns(text: str | bytes) -> tuple[dict[str, np.ndarray], object] | None:
    """The columns and sequence tag of a JSON object of number columns (or of one sample's numbers), or None.

    The usual message, read in one pass: msgspec checks every value is a number as it reads it
    (:data:`_COLUMNS`), and each column becomes a float array at once. Any other message (rows, text or
    booleans in a column, NaN, nested lists, not JSON) gives None and goes to the general reader, which
    names the problem.
    """
    try:
        value = _COLUMNS.decode(text)
    except msgspec.DecodeError:
        return None
    seq = value.pop(SEQUENCE_KEY, None)
    columns = {}
    for name, column in value.items():
        kind = type(column)
        if kind is list:
            columns[name] = np.array(column, dtype=np.float64)
        elif kind is float or kind is int:
            columns[name] = np.array([column], dtype=np.float64)
        else:  # text or null where numbers belong
            return None
    return columns, seq


def _checked(columns: dict[str, np.ndarray], bounds: MessageBounds) -> dict[str, np.ndarray]:
    """The columns of a message, refused when empty, of different lengths or too long."""
    lengths = {len(column) for column in columns.values()}
    if not columns or lengths == {0}:
        raise MessageError("the message holds no samples")
    if len(lengths) > 1:
        raise MessageError(f"the columns have different lengths ({', '.join(map(str, sorted(lengths)))})")
    if max(lengths) > bounds.max_samples:
        raise MessageError(f"the message holds {max(lengths)} samples, more than {bounds.max_samples}")
    return columns


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

    Parameters
    ----------
    bounds : MessageBounds, optional
        The largest message taken (size, nesting, samples).

    Attributes
    ----------
    header : list of str or None
        The CSV header once read.
    """

    def __init__(self, bounds: MessageBounds = DEFAULT_BOUNDS):
        self.bounds = bounds
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
        _check_size(len(payload), self.bounds)
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
            return parse_json(text, self.bounds)
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
    _check_finite(log)
    return log.replace(extras={}) if log.extras else log


def _all_finite(arrays: list[np.ndarray]) -> bool:
    """True when every value of ``arrays`` is finite: their sum is, in one reduction (the usual message); False
    also for finite values whose sum overflows, which the caller's value-by-value check then finds finite."""
    return math.isfinite(float(np.add.reduce(np.concatenate(arrays))))


def _check_finite(log: AxisLog) -> None:
    """Refuse a message whose channels hold NaN or infinity, naming the first such value."""
    channels = log.named_channels(time=True)
    if _all_finite([values for _, values in channels]):
        return
    for channel, values in channels:
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise MessageError(f"channel '{channel}' holds {values[bad[0]]} at sample {bad[0]} of the message")


def finite_rows(columns: Mapping[str, np.ndarray]) -> tuple[dict[str, np.ndarray], int]:
    """The samples of a message without those holding NaN or infinity in a number column.

    Parameters
    ----------
    columns : mapping of str to ndarray
        The message's columns, of equal length.

    Returns
    -------
    columns : dict of str to ndarray
        The columns of the finite samples (the same arrays when every sample is finite).
    dropped : int
        Samples left out.
    """
    numbers = [values for values in columns.values() if values.dtype.kind == "f"]
    if not numbers or _all_finite(numbers):
        return dict(columns), 0
    good = np.logical_and.reduce([np.isfinite(values) for values in numbers])
    if good.all():  # a sum of finite values overflowing
        return dict(columns), 0
    return {name: values[good] for name, values in columns.items()}, int(np.count_nonzero(~good))


class MessageLogs:
    """The samples of a stream's messages as axis logs (:func:`message_log`), the column names resolved once.

    A stream's messages carry the same columns one after another. For the first message with a set of
    column names, :func:`message_log` reads it and says what is wrong with it; the names' meaning (which
    column is which channel, in which unit, the kind of axis) is kept, and the following messages with
    the same names are read through it: each channel the column times its unit's factor, checked finite.
    A plan that does not give the first message's log exactly is not used (nor is one of a rotary axis,
    whose angle is unwrapped message by message): then every message goes through :func:`message_log`.

    Parameters
    ----------
    mapping : mapping of str to str, optional
        ``{canonical_name: column}`` for columns not named by the convention.
    """

    def __init__(self, *, mapping: Mapping[str, str] | None = None):
        self.mapping = dict(mapping) if mapping else None
        self._key: tuple | None = None
        self._plan: _ColumnPlan | None = None

    def log(self, columns: Mapping[str, np.ndarray], *, name: str, axis: str | None = None) -> AxisLog:
        """The samples of one message, as :func:`message_log` gives them.

        Parameters
        ----------
        columns : mapping of str to ndarray
            The message's columns (:func:`parse_json`, :func:`parse_csv_row`).
        name : str
            How the message is named in errors.
        axis : str, optional
            Axis to take from a message holding several.

        Raises
        ------
        MessageError
            As :func:`message_log`.
        """
        key = (*columns, axis)
        if key == self._key:
            if self._plan is not None:
                return self._plan.log(columns, name)
            return message_log(columns, name=name, mapping=self.mapping, axis=axis)
        log = message_log(columns, name=name, mapping=self.mapping, axis=axis)
        self._key, self._plan = key, _ColumnPlan.of(columns, log, mapping=self.mapping, axis=axis, name=name)
        return log


class _ColumnPlan:
    """Which column of a message is which channel, and the factor to its canonical unit."""

    def __init__(self, channels: dict, log: AxisLog):
        self.channels = channels  # {field: (column, factor)}
        self.effort_unit, self.motion, self.axis, self.attrs = log.effort_unit, log.motion, log.axis, log.attrs

    @classmethod
    def of(cls, columns, log: AxisLog, *, mapping, axis, name) -> "_ColumnPlan | None":
        """The plan of the column names of ``columns``, whose log is ``log``; None where it would not give it."""
        if log.motion != "linear":
            return None
        try:
            table, _, found, _ = resolve_table({column: column for column in columns}, source=name,
                                               columns=mapping or None, select=axis)
        except LogError:
            return None
        effort = next(quantity for quantity in EFFORT_QUANTITIES if quantity in found)
        fields = {"time": "time", "position": "position", effort: "effort", "velocity": "velocity",
                  "acceleration": "acceleration"}
        channels = {field: (table[found[quantity][0]], found[quantity][1])
                    for quantity, field in fields.items() if quantity in found}
        plan = cls(channels, log)
        try:
            again = plan.log(columns, name)
        except MessageError:
            return None
        same = all((a is None and b is None) or (a is not None and b is not None and np.array_equal(a, b))
                   for a, b in ((getattr(log, field), getattr(again, field)) for field in fields.values()))
        same = same and (again.effort_unit, again.motion, again.axis, again.attrs) == \
            (log.effort_unit, log.motion, log.axis, log.attrs)
        return plan if same else None

    def log(self, columns, name: str) -> AxisLog:
        """The samples of a message with the plan's column names."""
        values = {}
        for field, (column, factor) in self.channels.items():
            values[field] = columns[column] * factor if factor != 1.0 else columns[column]
        log = AxisLog(**values, effort_unit=self.effort_unit, motion=self.motion, axis=self.axis, source=name,
                      attrs=self.attrs)
        _check_finite(log)
        return log


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

#: The decoder of the usual message: an object of number columns (or of one sample's numbers) and a tag.
_COLUMNS = msgspec.json.Decoder(dict[str, Union[list[float], float, int, str, None]])
