"""MCAP axis logs: JSON messages, one per sample, one channel per axis.

Layout written by :func:`write_mcap` (documented for logger authors in
``docs/log-formats.md``):

* schema ``greybox.AxisSample``, schema encoding ``jsonschema`` (text in
  :data:`AXIS_SAMPLE_SCHEMA`), message encoding ``json``;
* one channel per axis, topic ``/axis/<axis>`` (``/axis`` without a name),
  channel metadata ``axis``, ``dataset``, ``effort_unit`` and ``attrs`` (a JSON
  object as text);
* one message per sample: ``log_time = publish_time =`` sample time [ns];
  fields ``position_mm``, ``current_A`` (or ``force_N``), optionally
  ``velocity_mm_s``, ``acceleration_mm_s2`` and further numeric extras;
* zstd-compressed chunks.

:func:`read_mcap` reads any MCAP file whose channel carries JSON messages: the
field names follow the same rules as CSV columns (unit suffixes, ``columns=``
mapping). It walks the records itself, so that a file of millions of messages
is decoded in bulk rather than message by message, and so that a damaged file
gives a :class:`~greybox.errors.LogError`: chunks are read ahead on a pool of
worker threads (one per core), each taking whole chunks: decompressed, split
into records and, once the channel to read is known, that channel's messages
parsed by the compiled reader of flat objects of numbers
(:mod:`greybox.data.json_numbers`); messages that are not all such objects go to
pyarrow's JSON reader in batches of chunks.
"""

from __future__ import annotations

import json
import os
import zlib
from collections import deque
from functools import partial
from typing import Callable, Iterator, Mapping, Sequence

import numba
import numpy as np
from numba import njit

from ..errors import LogError, Setting
from ..threads import shared_pool
from .blocks import CannotStream, reblock
from .json_numbers import parse_flat_objects, read_u64
from .log import AxisLog
from .units import log_from_columns

__all__ = ["AXIS_SAMPLE_SCHEMA", "SCHEMA_NAME", "McapLog", "read_mcap", "write_mcap", "topic_for"]

#: Name of the message schema written by greybox.
SCHEMA_NAME = "greybox.AxisSample"

#: JSON schema of one sample message (schema encoding ``jsonschema``).
AXIS_SAMPLE_SCHEMA = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": SCHEMA_NAME,
    "description": "One sample of one machine-tool axis, linear (mm, N) or rotary (deg, Nm). "
                   "The sample time is the message log_time in ns.",
    "type": "object",
    "properties": {
        "position_mm": {"type": "number", "description": "position of a linear axis [mm]"},
        "position_deg": {"type": "number", "description": "angle of a rotary axis [deg]"},
        "current_A": {"type": "number", "description": "motor current [A]"},
        "force_N": {"type": "number", "description": "drive force [N], for linear-axis logs without current"},
        "torque_Nm": {"type": "number", "description": "drive torque [Nm], for rotary-axis logs without current"},
        "velocity_mm_s": {"type": "number", "description": "axis velocity [mm/s]"},
        "velocity_deg_s": {"type": "number", "description": "axis angular velocity [deg/s]"},
        "acceleration_mm_s2": {"type": "number", "description": "axis acceleration [mm/s^2]"},
        "acceleration_deg_s2": {"type": "number", "description": "axis angular acceleration [deg/s^2]"},
    },
    "allOf": [
        {"anyOf": [{"required": ["position_mm"]}, {"required": ["position_deg"]}]},
        {"anyOf": [{"required": ["current_A"]}, {"required": ["force_N"]}, {"required": ["torque_Nm"]}]},
    ],
    "additionalProperties": {"type": "number", "description": "extra channel; the name ends in its unit"},
}

_MAGIC = b"\x89MCAP0\r\n"
_OP_FOOTER, _OP_CHANNEL, _OP_MESSAGE, _OP_CHUNK, _OP_MESSAGE_INDEX, _OP_DATA_END = 0x02, 0x04, 0x05, 0x06, 0x07, 0x0F
_MESSAGE_HEADER = 22  # channel_id u16, sequence u32, log_time u64, publish_time u64
_BATCH_BYTES = 16 << 20  # JSON text parsed per call of the bulk parser
_BLOCK_BYTES = 4 << 20  # its block size (blocks are parsed in parallel)
_WINDOW_BYTES = 8 << 20  # file bytes scanned at a time
_CHUNKS_AHEAD_PER_THREAD = 2  # chunks read ahead of the one being collected, per worker thread


def topic_for(axis: str) -> str:
    """Topic of an axis channel: ``/axis/<axis>``, or ``/axis`` for an unnamed axis.

    Parameters
    ----------
    axis : str
        Axis name; empty for an unnamed axis.
    """
    return f"/axis/{axis}" if axis else "/axis"


# ---------------------------------------------------------------------- write
def _check_encodable(log: AxisLog, path) -> None:
    for name, values in log.named_channels(time=True):
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise LogError(path, f"channel '{name}' holds {values[bad[0]]} at sample {bad[0]}; "
                                 "JSON messages carry finite numbers only")
    if len(log) and log.time.min() < 0:
        raise LogError(path, f"time reaches {log.time.min()} s; MCAP time stamps must be non-negative")


def _encode_messages(log: AxisLog) -> Iterator[bytes]:
    """One JSON object per sample; floats as their shortest exact text (``repr``)."""
    fields = log.named_channels()
    template = "{" + ",".join(json.dumps(name).replace("%", "%%") + ":%r" for name, _ in fields) + "}"
    columns = [values.tolist() for _, values in fields]
    return ((template % row).encode() for row in zip(*columns))


def write_mcap(logs: AxisLog | Sequence[AxisLog], path) -> None:
    """Write one or several axis logs to an MCAP file, one channel per log.

    Parameters
    ----------
    logs : AxisLog or sequence of AxisLog
        Logs of different axes (their topics ``/axis/<axis>`` must differ).
        Times must be non-negative (MCAP time stamps are unsigned ns).
    path : str or path-like
        File to write. Written in place; :func:`greybox.data.io.write_log`
        wraps this function to write atomically.

    Raises
    ------
    LogError
        For negative times, duplicate topics or non-finite values (JSON has no NaN).
    """
    from mcap.writer import CompressionType, IndexType, Writer

    runs = [logs] if isinstance(logs, AxisLog) else list(logs)
    topics = [topic_for(log.axis) for log in runs]
    if len(set(topics)) != len(topics):
        raise LogError(path, f"several logs share a topic ({', '.join(topics)}); give each log its own axis name")
    for log in runs:
        _check_encodable(log, path)
    with open(path, "wb") as stream:
        # Chunk indexes only: per-message indexes would add 16 uncompressed bytes per
        # sample (about half of a compressed 500 Hz log) and readers do not need them.
        writer = Writer(stream, compression=CompressionType.ZSTD, index_types=IndexType.CHUNK)
        writer.start(profile="", library="greybox")
        schema_id = writer.register_schema(
            name=SCHEMA_NAME, encoding="jsonschema", data=json.dumps(AXIS_SAMPLE_SCHEMA, indent=2).encode()
        )
        for log, topic in zip(runs, topics):
            metadata = {
                "axis": log.axis,
                "dataset": log.dataset,
                "effort_unit": log.effort_unit,
                "attrs": json.dumps(log.attrs),
            }
            channel_id = writer.register_channel(topic, "json", schema_id, metadata)
            stamps = np.rint(log.time * 1e9).astype(np.uint64).tolist()
            for stamp, message in zip(stamps, _encode_messages(log)):
                writer.add_message(channel_id, stamp, message, stamp)
        writer.finish()


# ----------------------------------------------------------------------- scan
@njit(cache=True, nogil=True)
def scan_records(buf, start, stop):
    """Split a byte range into MCAP records (opcode u8, length u64, content).

    Parameters
    ----------
    buf : ndarray of uint8
        File or decompressed chunk bytes.
    start, stop : int
        Byte range holding a sequence of whole records.

    Returns
    -------
    opcodes : ndarray of uint8
    offsets : ndarray of int64
        Offset of each record's content in ``buf``.
    lengths : ndarray of int64
        Length of each record's content.
    end : int
        Where scanning stopped: ``stop`` when the range holds whole records
        only; otherwise the start of the record that runs past ``stop``.
    """
    count = 0
    pos = start
    while pos + 9 <= stop:
        length = read_u64(buf, pos + 1)
        if length > np.uint64(stop - pos - 9):
            break
        pos += 9 + np.int64(length)
        count += 1
    opcodes = np.empty(count, np.uint8)
    offsets = np.empty(count, np.int64)
    lengths = np.empty(count, np.int64)
    pos = start
    for k in range(count):
        length = np.int64(read_u64(buf, pos + 1))
        opcodes[k] = buf[pos]
        offsets[k] = pos + 9
        lengths[k] = length
        pos += 9 + length
    return opcodes, offsets, lengths, pos


@njit(cache=True, nogil=True)
def join_slices(buf, offsets, lengths, separator):
    """Concatenate ``buf[offsets[k]:offsets[k] + lengths[k]]``, one ``separator`` byte between slices.

    Returns
    -------
    ndarray of uint8
    """
    n = offsets.shape[0]
    total = max(n - 1, 0)
    for k in range(n):
        total += lengths[k]
    out = np.empty(total, np.uint8)
    pos = 0
    for k in range(n):
        if k:
            out[pos] = separator
            pos += 1
        out[pos:pos + lengths[k]] = buf[offsets[k]:offsets[k] + lengths[k]]
        pos += lengths[k]
    return out


@njit(cache=True, nogil=True)
def select_messages(buf, opcodes, offsets, lengths, channel_id):
    """The message records of one channel among scanned records, with their ``log_time``, in one pass.

    Parameters
    ----------
    buf : ndarray of uint8
        Bytes holding the records.
    opcodes : ndarray of uint8
        Each record's opcode.
    offsets, lengths : ndarray of int64
        Each record's content: offset in ``buf`` and length [bytes].
    channel_id : int
        Channel whose messages to select.

    Returns
    -------
    offsets, lengths : ndarray of int64
        Offset and length of each selected message record's content.
    stamps : ndarray of uint64
        Their ``log_time`` [ns].
    short : bool
        True when a message record (of any channel) is shorter than its header; then nothing is selected.
    """
    count = 0
    for k in range(opcodes.shape[0]):
        if opcodes[k] == _OP_MESSAGE:
            if lengths[k] < _MESSAGE_HEADER:
                return np.empty(0, np.int64), np.empty(0, np.int64), np.empty(0, np.uint64), True
            if np.int64(buf[offsets[k]]) | (np.int64(buf[offsets[k] + 1]) << 8) == channel_id:
                count += 1
    offs = np.empty(count, np.int64)
    lens = np.empty(count, np.int64)
    stamps = np.empty(count, np.uint64)
    j = 0
    for k in range(opcodes.shape[0]):
        if opcodes[k] == _OP_MESSAGE and np.int64(buf[offsets[k]]) | (np.int64(buf[offsets[k] + 1]) << 8) == channel_id:
            offs[j], lens[j] = offsets[k], lengths[k]
            stamps[j] = read_u64(buf, offsets[k] + 6)
            j += 1
    return offs, lens, stamps, False


# ----------------------------------------------------------------------- read
class _Records:
    """Little-endian reader of one record's fields (raises on running short)."""

    def __init__(self, data: bytes, path):
        self.data, self.pos, self.path = data, 0, path

    def take(self, size: int) -> bytes:
        if self.pos + size > len(self.data):
            raise LogError(self.path, "corrupt MCAP file: a record is shorter than its fields")
        chunk = self.data[self.pos:self.pos + size]
        self.pos += size
        return chunk

    def uint(self, size: int) -> int:
        return int.from_bytes(self.take(size), "little")

    def string(self) -> str:
        try:
            return self.take(self.uint(4)).decode("utf-8")
        except UnicodeDecodeError as exc:
            raise LogError(self.path, f"corrupt MCAP file: invalid text in a record ({exc.reason})") from None

    def string_map(self) -> dict[str, str]:
        inner = _Records(self.take(self.uint(4)), self.path)
        pairs = {}
        while inner.pos < len(inner.data):
            key = inner.string()
            pairs[key] = inner.string()
        return pairs


class _Channel:
    def __init__(self, content: bytes, path):
        fields = _Records(content, path)
        self.id = fields.uint(2)
        self.schema_id = fields.uint(2)
        self.topic = fields.string()
        self.message_encoding = fields.string()
        self.metadata = fields.string_map()


def _decompress(content: bytes, path) -> bytes:
    fields = _Records(content, path)
    fields.take(16)  # message start and end time
    size = fields.uint(8)
    crc = fields.uint(4)
    compression = fields.string()
    records = fields.take(fields.uint(8))
    try:
        if compression == "":
            data = records
        elif compression == "zstd":
            import zstandard

            data = zstandard.ZstdDecompressor().decompress(records, max_output_size=size)
        elif compression == "lz4":
            import lz4.frame

            data = lz4.frame.decompress(records)
        else:
            raise LogError(path, f"MCAP chunk compression '{compression}' is not supported (use zstd, lz4 or none)")
    except LogError:
        raise
    except Exception as exc:  # the decompressors raise their own error types
        raise LogError(path, f"corrupt MCAP file: a {compression} chunk does not decompress ({exc})") from None
    if len(data) != size or (crc and zlib.crc32(data) != crc):
        raise LogError(path, "corrupt MCAP file: a chunk fails its size or CRC check")
    return data


class _MessageCollector:
    """Gathers the messages of one channel: each chunk's by the compiled reader, else in batches by pyarrow's."""

    def __init__(self, path):
        self.path = path
        self.stamps: list[np.ndarray] = []
        self.rows = 0  # messages collected since the last :meth:`columns` or :meth:`take_stamps`
        self.pending: list[np.ndarray] = []
        self.pending_bytes = 0
        self.pending_rows = 0
        self.batches: list[tuple[int, dict]] = []

    def add(self, buf: np.ndarray, offsets: np.ndarray, lengths: np.ndarray, stamps: np.ndarray,
            columns: dict | None | bool = False) -> None:
        """Collect the message records at ``offsets`` in ``buf`` with their ``stamps`` [ns]; ``columns``: their
        fields by :func:`~greybox.data.json_numbers.parse_flat_objects` if already parsed (False: parse them here).
        """
        if not offsets.size:
            return
        if columns is False:
            columns = _parse_messages(buf, offsets, lengths)
        self.stamps.append(stamps)
        self.rows += offsets.size
        if columns is not None:
            self.flush()
            self.batches.append((offsets.size, columns))
            return
        text = join_slices(buf, offsets + _MESSAGE_HEADER, lengths - _MESSAGE_HEADER, 10)
        self.pending.append(text)
        self.pending_bytes += text.size
        self.pending_rows += offsets.size
        if self.pending_bytes >= _BATCH_BYTES:
            self.flush()

    def flush(self) -> None:
        if not self.pending:
            return
        import pyarrow as pa
        import pyarrow.json as pa_json

        newline = np.array([10], np.uint8)
        pieces = []
        for piece in self.pending:
            pieces.extend((piece, newline))
        text = np.concatenate(pieces[:-1])
        rows = self.pending_rows
        self.pending, self.pending_bytes, self.pending_rows = [], 0, 0
        lines = int(np.count_nonzero(text == 10)) + 1
        try:
            table = pa_json.read_json(
                pa.BufferReader(pa.py_buffer(text)),
                read_options=pa_json.ReadOptions(block_size=_BLOCK_BYTES),
                parse_options=pa_json.ParseOptions(newlines_in_values=lines != rows),
            )
        except Exception as exc:  # pyarrow.ArrowInvalid and friends
            raise LogError(self.path, f"messages are not valid JSON objects ({str(exc).splitlines()[0]})") from None
        if table.num_rows != rows:
            raise LogError(self.path, f"{rows} messages gave {table.num_rows} JSON objects; "
                                      "each message must hold one object")
        self.batches.append((rows, {name: _as_array(table.column(name)) for name in table.column_names}))

    def take_stamps(self) -> np.ndarray:
        """The time stamps [ns] collected since the last call (or :meth:`columns`), as they came."""
        stamps = np.concatenate(self.stamps) if self.stamps else np.empty(0, np.uint64)
        self.stamps, self.rows = [], 0
        return stamps

    def columns(self) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """Time stamps [ns] and field columns, in log_time order (missing values NaN)."""
        self.flush()
        stamps = self.take_stamps()
        batches, self.batches = self.batches, []
        names = list(dict.fromkeys(name for _, batch in batches for name in batch))
        threads = min(max(1, numba.get_num_threads()), len(names))
        join = partial(_join_column, batches)  # a column per thread at a time (copies release the GIL)
        table = dict(zip(names, shared_pool(threads, "mcap-columns").map(join, names) if threads > 1
                         else map(join, names)))
        if np.any(stamps[1:] < stamps[:-1]):
            order = np.argsort(stamps, kind="stable")
            stamps = stamps[order]
            table = {name: values[order] for name, values in table.items()}
        return stamps, table


def _join_column(batches: list[tuple[int, dict]], name: str) -> np.ndarray:
    """One field's column from the batches (rows, {name: values}), taken out of them: float64 written into
    one array made for it (NaN where a batch lacks the field), else objects (None where missing)."""
    parts = [batch.pop(name, None) for _, batch in batches]
    if all(part is None or part.dtype == np.float64 for part in parts):
        column = np.empty(sum(rows for rows, _ in batches))
        start = 0
        for (rows, _), part in zip(batches, parts):
            column[start:start + rows] = np.nan if part is None else part
            start += rows
        return column
    return np.concatenate([np.full(rows, None, object) if part is None else part.astype(object)
                           for (rows, _), part in zip(batches, parts)])


def _parse_messages(buf: np.ndarray, offsets: np.ndarray, lengths: np.ndarray,
                    threads: int | None = None) -> dict | None:
    """The fields of the message records at ``offsets`` by the compiled reader.

    None when the messages are not all flat JSON objects of numbers with the same keys
    (:func:`~greybox.data.json_numbers.parse_flat_objects`, on ``threads`` threads).
    """
    return parse_flat_objects(buf, offsets + _MESSAGE_HEADER, lengths - _MESSAGE_HEADER, threads=threads)


def _as_array(column) -> np.ndarray:
    """A pyarrow column as float64 (nulls as NaN), or as objects when it is not numeric."""
    import pyarrow as pa
    import pyarrow.compute as pc

    kind = column.type
    if pa.types.is_integer(kind) or pa.types.is_floating(kind) or pa.types.is_boolean(kind) or pa.types.is_null(kind):
        return pc.cast(column, pa.float64()).to_numpy()
    return column.to_numpy().astype(object)


def _match(channels: Mapping[int, _Channel], topic: str | None) -> _Channel | None:
    """The channel to read as far as known so far, or None (not seen yet, or ambiguous)."""
    if topic is None:
        return next(iter(channels.values())) if len(channels) == 1 else None
    return next((channel for channel in channels.values() if channel.topic == topic), None)


def _choose(channels: Mapping[int, _Channel], topic: str | None, path) -> _Channel:
    topics = ", ".join(sorted(channel.topic for channel in channels.values()))
    if not channels:
        raise LogError(path, "the MCAP file has no channels")
    if topic is None:
        if len(channels) > 1:
            raise LogError(path, "the MCAP file has several channels; choose one with ", Setting("topic"),
                           f" ({topics})")
        return next(iter(channels.values()))
    for channel in channels.values():
        if channel.topic == topic:
            return channel
    raise LogError(path, f"no channel with topic '{topic}'; topics in the file: {topics}")


def _walk(path, channel_id: Callable[[], int | None] = lambda: None) -> Iterator[tuple]:
    """Yield (buffer, opcodes, offsets, lengths, parsed) of the data section, a stretch of records or a chunk at a time.

    Chunks are read :data:`_CHUNKS_AHEAD_PER_THREAD` per worker thread ahead of the one given, on a pool of
    one thread per core (:func:`_read_chunk`), while the caller works on the records already given; each
    is read for the channel ``channel_id()`` names when it is handed to the pool (``parsed``, None for the
    records outside chunks).
    """
    threads = max(1, numba.get_num_threads())
    pool = shared_pool(threads, "mcap-chunks")
    pending: deque = deque()  # records outside chunks (tuples) and chunks being read (futures), in file order
    reading = 0  # futures in ``pending``
    stretches = _stretches(path)
    try:
        while True:
            while reading < _CHUNKS_AHEAD_PER_THREAD * threads:
                item = next(stretches, None)
                if item is None:
                    break
                if isinstance(item, bytes):
                    pending.append(pool.submit(_read_chunk, item, channel_id(), path))
                    reading += 1
                else:
                    pending.append(item)
            if not pending:
                return
            item = pending.popleft()
            if isinstance(item, tuple):
                yield item
            else:
                reading -= 1
                yield item.result()
    finally:
        for item in pending:
            if not isinstance(item, tuple):
                item.cancel()


def _stretches(path) -> Iterator[tuple | bytes]:
    """The data section in file order: records outside chunks as (buffer, opcodes, offsets, lengths, None),
    each chunk record as its content (bytes)."""
    for buf, data, opcodes, offsets, lengths, _ in _windows(path):
        begin = 0
        for index in np.flatnonzero(opcodes == _OP_CHUNK).tolist() + [opcodes.size]:
            if index > begin:
                yield buf, opcodes[begin:index], offsets[begin:index], lengths[begin:index], None
            if index < opcodes.size:
                yield data[offsets[index]:offsets[index] + lengths[index]]
            begin = index + 1


def _read_chunk(content: bytes, channel_id: int | None, path) -> tuple:
    """A chunk record's content decompressed and scanned: (buffer, opcodes, offsets, lengths, parsed).

    ``parsed`` is None, or with a ``channel_id`` ``(channel_id, offsets, lengths, stamps, columns)``: the
    offsets, lengths and ``log_time`` of that channel's message records (:func:`select_messages`) and their
    :func:`_parse_messages` on this thread (None when there are none, or when they fail a check, which the
    caller then meets if it reads that channel).
    """
    buf, opcodes, offsets, lengths = _chunk_records(_decompress(content, path), path)
    parsed = None
    if channel_id is not None and np.any(opcodes == _OP_MESSAGE):
        offs, lens, stamps, short = select_messages(buf, opcodes, offsets, lengths, channel_id)
        if short:
            return buf, opcodes, offsets, lengths, None
        parsed = (channel_id, offs, lens, stamps, _parse_messages(buf, offs, lens, threads=1) if offs.size else None)
    return buf, opcodes, offsets, lengths, parsed


def _windows(path) -> Iterator[tuple[np.ndarray, bytes, np.ndarray, np.ndarray, np.ndarray, bool]]:
    """Yield (buffer, its bytes, opcodes, offsets, lengths, last) of the data section's records, chunks not opened.

    ``last`` is True for the window that reaches the data-end record.

    The file is scanned :data:`_WINDOW_BYTES` at a time (a record longer than that is read whole), up to
    the data-end record, so that the memory held does not grow with the file.
    """
    size = os.path.getsize(path)
    with open(path, "rb") as stream:
        if size < 2 * len(_MAGIC) or stream.read(len(_MAGIC)) != _MAGIC:
            raise LogError(path, "not an MCAP file (the file does not start with the MCAP magic bytes)")
        stream.seek(size - len(_MAGIC))
        if stream.read(len(_MAGIC)) != _MAGIC:
            raise LogError(path, "truncated MCAP file: it does not end with the MCAP magic bytes "
                                 "(was the logger stopped before closing it?)")
        stop = size - len(_MAGIC)
        stream.seek(len(_MAGIC))
        start = len(_MAGIC)  # file offset of the first byte not yet scanned
        carry = b""
        while True:
            unread = stop - start - len(carry)
            wanted = _WINDOW_BYTES
            if len(carry) >= 9:  # the record that did not fit: read it whole
                missing = 9 + int.from_bytes(carry[1:9], "little") - len(carry)
                if missing > unread:
                    unread = 0
                wanted = max(wanted, missing)
            if not unread:
                if carry:
                    raise LogError(path, f"corrupt or truncated MCAP file: the record at byte {start} runs past "
                                         "the end of the file")
                raise LogError(path, "corrupt MCAP file: no data-end record")
            data = carry + stream.read(min(wanted, unread))
            buf = np.frombuffer(data, np.uint8)
            opcodes, offsets, lengths, end = scan_records(buf, 0, buf.size)
            ends = np.flatnonzero(opcodes == _OP_DATA_END)
            last = int(ends[0]) if ends.size else opcodes.size
            yield buf, data, opcodes[:last], offsets[:last], lengths[:last], bool(ends.size)
            if ends.size:
                return
            carry, start = data[end:], start + end


def _chunk_records(raw: bytes, path) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(buffer, opcodes, offsets, lengths) of the records of a decompressed chunk, which must hold whole records."""
    inner = np.frombuffer(raw, np.uint8)
    opcodes, offsets, lengths, end = scan_records(inner, 0, inner.size)
    if end != inner.size:
        raise LogError(path, "corrupt MCAP file: a chunk holds a partial record")
    return inner, opcodes, offsets, lengths


def _collect(path, topic: str | None) -> tuple[dict[int, _Channel], _MessageCollector]:
    """Walk the file once: every channel record, and the messages of the channel to read."""
    channels: dict[int, _Channel] = {}
    collector = _MessageCollector(path)
    for _ in _messages(path, topic, channels, collector):
        pass
    return channels, collector


def _messages(path, topic: str | None, channels: dict[int, _Channel], collector: _MessageCollector) -> Iterator[int]:
    """Walk the file, adding channel records to ``channels`` and the chosen channel's messages to ``collector``;
    yield the messages collected after each stretch.

    A chunk read ahead for the channel chosen when it was handed to the pool keeps its parsed messages if
    that is still the channel chosen once the records before it are known; otherwise they are parsed here.
    """
    def chosen_id() -> int | None:
        chosen = _match(channels, topic)
        return None if chosen is None else chosen.id

    for buf, opcodes, offsets, lengths, parsed in _walk(path, chosen_id):
        _add_channels(channels, buf, opcodes, offsets, lengths, path)
        chosen = _match(channels, topic)
        if chosen is None or not np.any(opcodes == _OP_MESSAGE):
            continue
        if parsed is not None and parsed[0] == chosen.id:
            _, offs, lens, stamps, columns = parsed
        else:
            (offs, lens, stamps), columns = _channel_messages(buf, opcodes, offsets, lengths, chosen.id, path), False
        collector.add(buf, offs, lens, stamps, columns)
        yield collector.rows


def _channel_messages(buf, opcodes, offsets, lengths, channel_id: int,
                      path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Offsets, lengths and ``log_time`` [ns] of the message records of one channel among scanned records."""
    offs, lens, stamps, short = select_messages(buf, opcodes, offsets, lengths, channel_id)
    if short:
        raise LogError(path, "corrupt MCAP file: a message record is shorter than its header")
    return offs, lens, stamps


def _channel_stamps(path, channel_id: int) -> Iterator[np.ndarray]:
    """The ``log_time`` [ns] of one channel's messages in the order they are stored, a chunk at a time.

    A chunk followed by its message-index records gives them from the index, without being decompressed;
    a chunk without them (or whose index is cut by the scan window, or malformed) is decompressed.
    """
    for buf, data, opcodes, offsets, lengths, last in _windows(path):
        begin = 0
        for chunk in np.flatnonzero(opcodes == _OP_CHUNK).tolist() + [opcodes.size]:
            _, _, stamps = _channel_messages(buf, opcodes[begin:chunk], offsets[begin:chunk], lengths[begin:chunk],
                                             channel_id, path)  # messages outside chunks
            if stamps.size:
                yield stamps
            if chunk == opcodes.size:
                break
            end = chunk + 1
            while end < opcodes.size and opcodes[end] == _OP_MESSAGE_INDEX:
                end += 1
            stamps = None
            if chunk + 1 < end and (end < opcodes.size or last):  # its index records, none cut off by the window
                stamps = _indexed_stamps(buf, offsets[chunk + 1:end], lengths[chunk + 1:end], channel_id)
            if stamps is None:
                inner, ops, offs, lens = _chunk_records(
                    _decompress(data[offsets[chunk]:offsets[chunk] + lengths[chunk]], path), path)
                stamps = _channel_messages(inner, ops, offs, lens, channel_id, path)[2]
            if stamps.size:
                yield stamps
            begin = end


def _indexed_stamps(buf, offsets, lengths, channel_id: int) -> np.ndarray | None:
    """A chunk's ``log_time`` values of one channel from its message-index records, in storage order.

    Returns None when a record is malformed (then the chunk is read instead).
    """
    pairs = []
    for offset, length in zip(offsets.tolist(), lengths.tolist()):
        if length < 6:
            return None
        size = int.from_bytes(bytes(buf[offset + 2:offset + 6]), "little")
        if size % 16 or 6 + size != length:
            return None
        if int(buf[offset]) | int(buf[offset + 1]) << 8 == channel_id:
            pairs.append(np.frombuffer(bytes(buf[offset + 6:offset + length]), "<u8").reshape(-1, 2))
    if not pairs:
        return np.empty(0, np.uint64)
    pairs = np.concatenate(pairs)
    return pairs[np.argsort(pairs[:, 1], kind="stable"), 0].astype(np.uint64)


def _resolve_channel(channels: Mapping[int, _Channel], topic: str | None, axis: str | None,
                     path) -> tuple[_Channel, str | None]:
    """The channel to read, and the axis whose prefixed fields to select in it (None: the whole channel).

    An axis without a topic is the channel ``/axis/<axis>``, or the fields ``<axis>_...`` of the file's one
    channel.
    """
    select = None
    if axis is not None and topic is None:
        topic = topic_for(axis)
        if not any(channel.topic == topic for channel in channels.values()):
            if len(channels) > 1:
                listed = ", ".join(sorted(channel.topic for channel in channels.values()))
                raise LogError(path, f"no channel of axis '{axis}' ({topic}); the channels in the file: {listed}")
            topic, select = None, axis
    channel = _choose(channels, topic, path)
    if channel.message_encoding != "json":
        raise LogError(
            path,
            f"channel '{channel.topic}' has message encoding '{channel.message_encoding}'; greybox reads JSON messages",
        )
    return channel, select


def read_mcap(
    path,
    *,
    topic: str | None = None,
    columns: Mapping[str, str] | None = None,
    axis: str | None = None,
) -> AxisLog:
    """Read one axis channel of an MCAP file with JSON messages.

    Parameters
    ----------
    path : str or path-like
        MCAP file.
    topic : str, optional
        Channel to read; required when the file has several channels (the
        error lists them).
    columns : mapping of str to str, optional
        ``{canonical_name: message_field}`` for fields not named by the
        greybox convention, e.g. ``{"position_mm": "pos", "current_A": "iq"}``.
    axis : str, optional
        Axis to read from a file holding several: the channel ``/axis/<axis>`` if there is one
        (and no ``topic``), else the fields named ``<axis>_<quantity>_<unit>`` of the one channel
        (:func:`greybox.data.units.select_axis`).

    Returns
    -------
    AxisLog
        Time [s] = ``log_time`` / 1e9, messages in ``log_time`` order; base
        channels converted to canonical units, other numeric fields as extras;
        axis, dataset, effort unit and attrs from the channel metadata (axis
        defaults to the last part of the topic).

    Raises
    ------
    LogError
        For a file that is not MCAP, truncated or corrupt, an ambiguous or
        unknown topic, non-JSON messages, or missing fields.
    """
    channels, collector = _collect(path, topic_for(axis) if axis is not None and topic is None else topic)
    channel, select = _resolve_channel(channels, topic, axis, path)
    if select is not None:  # the axis's fields in the one channel: collect that channel's messages
        channels, collector = _collect(path, None)
    stamps, table = collector.columns()
    if not stamps.size:
        raise LogError(path, f"channel '{channel.topic}' has no messages")
    return log_from_columns(table, source=path, columns=columns, time=stamps * 1e-9, select=select,
                            **_channel_fields(channel, path))


def _channel_fields(channel: _Channel, path) -> dict:
    """The log's effort unit, axis, dataset and attrs from a channel's metadata."""
    metadata = channel.metadata
    try:
        attrs = json.loads(metadata.get("attrs", "{}"))
    except (ValueError, RecursionError):
        raise LogError(path, f"channel '{channel.topic}': metadata 'attrs' is not JSON text") from None
    return {"effort_unit": metadata.get("effort_unit"),
            "axis": metadata.get("axis", channel.topic.rstrip("/").rsplit("/", 1)[-1]),
            "dataset": metadata.get("dataset", ""), "attrs": attrs if isinstance(attrs, dict) else {"attrs": attrs}}


def _add_channels(channels: dict[int, _Channel], buf: np.ndarray, opcodes, offsets, lengths, path) -> None:
    for k in np.flatnonzero(opcodes == _OP_CHANNEL):
        channel = _Channel(buf[offsets[k]:offsets[k] + lengths[k]].tobytes(), path)
        channels.setdefault(channel.id, channel)


def _walked_channels(path) -> dict[int, _Channel]:
    """The channel records of the data section (a walk over the whole file)."""
    channels: dict[int, _Channel] = {}
    for buf, opcodes, offsets, lengths, _ in _walk(path):
        _add_channels(channels, buf, opcodes, offsets, lengths, path)
    return channels


def _summary_channels(path) -> dict[int, _Channel]:
    """The channel records of the summary section that the footer points to; empty if there are none."""
    size = os.path.getsize(path)
    footer = 1 + 8 + 20  # opcode, length, summary start u64, summary offset start u64, summary CRC u32
    if size < 2 * len(_MAGIC) + footer:
        return {}
    with open(path, "rb") as stream:
        stream.seek(size - len(_MAGIC) - footer)
        record = stream.read(footer)
        if record[0] != _OP_FOOTER or int.from_bytes(record[1:9], "little") != 20:
            return {}
        start = int.from_bytes(record[9:17], "little")
        stop = int.from_bytes(record[17:25], "little") or size - len(_MAGIC) - footer
        if not len(_MAGIC) <= start < stop <= size - len(_MAGIC) - footer or stop - start > _WINDOW_BYTES:
            return {}
        stream.seek(start)
        data = stream.read(stop - start)
    buf = np.frombuffer(data, np.uint8)
    opcodes, offsets, lengths, _ = scan_records(buf, 0, buf.size)
    channels: dict[int, _Channel] = {}
    _add_channels(channels, buf, opcodes, offsets, lengths, path)
    return channels


class McapLog:
    """An MCAP axis log read block by block, converted as :func:`read_mcap` converts it.

    The channel is chosen as :func:`read_mcap` chooses it, from a first walk over the file's records.
    Its messages must be stored in time order (:meth:`times` raises
    :class:`~greybox.data.blocks.CannotStream` otherwise; :func:`read_mcap` sorts them).

    Parameters
    ----------
    path : str or path-like
        MCAP file with JSON messages.
    columns : mapping of str to str, optional
        ``{canonical_name: message_field}`` for fields not named by the convention.
    topic : str, optional
        Channel to read.
    axis : str, optional
        Axis to read (see :func:`read_mcap`).
    block_samples : int
        Samples per block.

    Attributes
    ----------
    n_samples : int or None
        Messages of the channel (known after the first pass of :meth:`times`).
    motion : str
        "linear" or "rotary", from the fields of the first messages.
    axis : str
        The log's axis name (the ``axis`` read, else the channel's).

    Raises
    ------
    LogError
        As :func:`read_mcap`.
    """

    def __init__(self, path, *, columns: Mapping[str, str] | None = None, topic: str | None = None,
                 axis: str | None = None, block_samples: int):
        self.path = os.fspath(path)
        self.columns = dict(columns) if columns else None
        self.block_samples = int(block_samples)
        channels = _summary_channels(self.path) or _walked_channels(self.path)
        self._channel, self._select = _resolve_channel(channels, topic, axis, self.path)
        self._topic = self._channel.topic if self._select is None else None
        self._fields = _channel_fields(self._channel, self.path)
        self.axis = self._select if self._select is not None else self._fields["axis"]
        self.n_samples = None
        self._span = None
        self._digest = None  # (count, sum of log_time) of the messages, from the first pass of times()
        first = next(self.blocks(2), None)
        if first is None:
            raise LogError(self.path, f"channel '{self._channel.topic}' has no messages")
        self.motion = first.motion

    def times(self) -> Iterator[np.ndarray]:
        """The message times [s] of the channel, as they come in the file (messages not parsed)."""
        count, first, last, total = 0, None, None, np.uint64(0)
        for stamps in _channel_stamps(self.path, self._channel.id):
            if np.any(stamps[1:] < stamps[:-1]) or (last is not None and stamps[0] < last):
                raise CannotStream(f"{self.path}: messages not stored in time order")
            first = stamps[0] if first is None else first
            last = stamps[-1]
            count += stamps.size
            total += np.sum(stamps, dtype=np.uint64)
            yield stamps * 1e-9
        self.n_samples, self._span = count, (None if first is None else (first * 1e-9, last * 1e-9))
        self._digest = (count, total)

    def time_span(self) -> tuple[float, float]:
        """Times of the first and the last sample [s] (after a pass of :meth:`times`)."""
        if self._span is None:
            for _ in self.times():
                pass
        return self._span

    def blocks(self, block_samples: int | None = None) -> Iterator[AxisLog]:
        """The log, block by block (the last may be shorter), converted but not validated.

        Parameters
        ----------
        block_samples : int, optional
            Samples per block; default :attr:`block_samples`.
        """
        size = self.block_samples if block_samples is None else int(block_samples)
        yield from reblock(self._pieces(size), size)

    def _pieces(self, size: int) -> Iterator[AxisLog]:
        collector = _MessageCollector(self.path)

        def batches():
            for rows in _messages(self.path, self._topic, {}, collector):
                if rows >= size:
                    yield collector.columns()
            if collector.rows:
                yield collector.columns()

        count, total = 0, np.uint64(0)
        for stamps, table in batches():
            count, total = count + stamps.size, total + np.sum(stamps, dtype=np.uint64)
            yield self._convert(stamps, table)
        if self._digest is not None and (count, total) != self._digest:  # raised before the output is kept
            raise LogError(self.path, f"corrupt MCAP file: the message index gives {self._digest[0]} messages of "
                                      f"channel '{self._channel.topic}' (or other times) where {count} are stored")

    def _convert(self, stamps: np.ndarray, table: dict) -> AxisLog:
        return log_from_columns(table, source=self.path, columns=self.columns, time=stamps * 1e-9,
                                select=self._select, **self._fields)
