"""MCAP reading and writing: round trip, compatibility with the mcap library, bad files."""

from __future__ import annotations

import json

import numpy as np
import pytest
from log_errors import assert_read_fails
from mcap.reader import make_reader

from greybox.data.io import read_log, write_log
from greybox.data.mcap_io import SCHEMA_NAME, join_slices, scan_records, select_messages
from greybox.errors import LogError


def test_round_trip_keeps_values_extras_and_metadata(tmp_path, make_log):
    rng = np.random.default_rng(3)
    log = make_log(
        velocity=rng.normal(size=2000),
        acceleration=rng.normal(size=2000),
        extras={"truth_friction_A": rng.normal(size=2000), "cutting_force_N": rng.normal(size=2000)},
        attrs={"seed": 3, "trajectory": {"kind": "sine", "amplitude_mm": 50.0}},
    )
    path = tmp_path / "axis.mcap"
    write_log(log, path)
    back = read_log(path)
    np.testing.assert_allclose(back.time, log.time, rtol=0, atol=1e-9)  # 1 ns time stamps
    for name in ("position", "effort", "velocity", "acceleration"):
        assert np.array_equal(getattr(back, name), getattr(log, name)), name
    assert back.extras.keys() == log.extras.keys()
    for name, values in log.extras.items():
        assert np.array_equal(back.extras[name], values)
    assert (back.axis, back.dataset, back.effort_unit, back.attrs) == ("X", "T", "A", log.attrs)
    assert back.source == str(path)


def test_force_log_keeps_its_unit(tmp_path, make_log):
    log = make_log(effort_unit="N")
    write_log(log, tmp_path / "force.mcap")
    back = read_log(tmp_path / "force.mcap")
    assert back.effort_unit == "N"
    assert np.array_equal(back.effort, log.effort)


def test_file_is_standard_mcap_with_json_messages(tmp_path, make_log):
    log = make_log(n=50)
    write_log(log, tmp_path / "axis.mcap")
    with open(tmp_path / "axis.mcap", "rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        (schema,) = summary.schemas.values()
        (channel,) = summary.channels.values()
        assert (schema.name, schema.encoding) == (SCHEMA_NAME, "jsonschema")
        json.loads(schema.data)
        assert (channel.topic, channel.message_encoding) == ("/axis/X", "json")
        assert channel.metadata["effort_unit"] == "A"
        assert {c.compression for c in summary.chunk_indexes} == {"zstd"}
        messages = list(reader.iter_messages())
    assert len(messages) == 50
    _, _, first = messages[1]
    assert first.log_time == first.publish_time == 2_000_000
    assert json.loads(first.data)["position_mm"] == log.position[1]


def test_several_axes_need_a_topic(tmp_path, make_log):
    path = tmp_path / "two.mcap"
    write_log([make_log(axis="X"), make_log(axis="Y", seed=1)], path)
    with pytest.raises(LogError) as error:
        read_log(path)
    assert str(path) in str(error.value) and "/axis/X" in str(error.value) and "/axis/Y" in str(error.value)
    y = read_log(path, topic="/axis/Y")
    assert y.axis == "Y"
    assert np.array_equal(y.effort, make_log(axis="Y", seed=1).effort)
    with pytest.raises(LogError, match="no channel with topic '/axis/Z'"):
        read_log(path, topic="/axis/Z")


def _reference_scan(data: bytes, start: int, stop: int):
    opcodes, offsets, lengths = [], [], []
    pos = start
    while pos + 9 <= stop:
        length = int.from_bytes(data[pos + 1:pos + 9], "little")
        if length > stop - pos - 9:
            break
        opcodes.append(data[pos])
        offsets.append(pos + 9)
        lengths.append(length)
        pos += 9 + length
    return opcodes, offsets, lengths, pos


def test_compiled_scan_and_join_agree_with_plain_python():
    rng = np.random.default_rng(7)
    records = b"".join(
        bytes([int(rng.integers(1, 16))]) + len(body).to_bytes(8, "little") + body
        for body in (rng.bytes(int(rng.integers(0, 40))) for _ in range(200))
    )
    data = b"\x00" * 5 + records + b"\x05\xff"  # a partial record at the end
    buf = np.frombuffer(data, np.uint8)
    opcodes, offsets, lengths, end = scan_records(buf, 5, len(data))
    ref = _reference_scan(data, 5, len(data))
    assert (opcodes.tolist(), offsets.tolist(), lengths.tolist(), end) == ref
    assert end == 5 + len(records)
    joined = join_slices(buf, offsets, lengths, 10).tobytes()
    assert joined == b"\n".join(data[o:o + n] for o, n in zip(ref[1], ref[2]))


def test_compiled_message_selection_agrees_with_plain_python():
    """One channel's message records and their log_time, compiled and with the compiler off (``py_func``, what
    NUMBA_DISABLE_JIT=1 runs), against the fields read with int.from_bytes."""
    rng = np.random.default_rng(8)
    bodies = []
    for _ in range(300):
        opcode = int(rng.choice([5, 5, 5, 4, 7]))
        body = int(rng.integers(1, 4)).to_bytes(2, "little") + rng.bytes(int(rng.integers(20, 60)))
        bodies.append(bytes([opcode]) + len(body).to_bytes(8, "little") + body)
    data = b"".join(bodies)
    buf = np.frombuffer(data, np.uint8)
    opcodes, offsets, lengths, _ = scan_records(buf, 0, buf.size)
    for kernel in (select_messages, getattr(select_messages, "py_func", select_messages)):
        for channel in (1, 2, 3, 9):
            mine = [(o, n) for op, o, n in zip(opcodes.tolist(), offsets.tolist(), lengths.tolist())
                    if op == 5 and int.from_bytes(data[o:o + 2], "little") == channel]
            offs, lens, stamps, short = kernel(buf, opcodes, offsets, lengths, channel)
            assert not short
            assert list(zip(offs.tolist(), lens.tolist())) == mine
            assert stamps.tolist() == [int.from_bytes(data[o + 6:o + 14], "little") for o, _ in mine]
        short_buf = np.frombuffer(data + b"\x05" + (3).to_bytes(8, "little") + b"\x01\x00\x00", np.uint8)
        ops, offs, lens, _ = scan_records(short_buf, 0, short_buf.size)
        offs, lens, stamps, short = kernel(short_buf, ops, offs, lens, 1)  # a message shorter than its header
        assert short and not offs.size


def _write_with_mcap_library(path, messages, *, encoding="json", **writer_options):
    """Write (log_time_ns, bytes) messages on /axis/X with the mcap package's Writer."""
    from mcap.writer import Writer

    with open(path, "wb") as stream:
        writer = Writer(stream, **writer_options)
        writer.start()
        schema_id = writer.register_schema("greybox.AxisSample", "jsonschema", b'{"type": "object"}')
        channel_id = writer.register_channel("/axis/X", encoding, schema_id, {"axis": "X"})
        for stamp, data in messages:
            writer.add_message(channel_id, log_time=stamp, data=data, publish_time=stamp)
        writer.finish()


def _sample_messages(n=300, *, indent=None):
    return [
        (k * 1_000_000, json.dumps({"position_um": 1000.0 * k, "current_mA": 500.0, "temperature_C": 20.0 + k},
                                   indent=indent).encode())
        for k in range(n)
    ]


@pytest.mark.parametrize(
    "options",
    [
        {},
        {"use_chunking": False},
        {"compression": "lz4"},
        {"compression": "none", "chunk_size": 512},
    ],
    ids=["zstd-chunks", "no-chunks", "lz4", "uncompressed-small-chunks"],
)
def test_files_of_other_writers_read_with_unit_conversion(tmp_path, options):
    from mcap.writer import CompressionType

    if "compression" in options:
        kinds = {"lz4": CompressionType.LZ4, "none": CompressionType.NONE}
        options = {**options, "compression": kinds[options["compression"]]}
    path = tmp_path / "other.mcap"
    _write_with_mcap_library(path, _sample_messages(), **options)
    log = read_log(path)
    k = np.arange(300)
    np.testing.assert_allclose(log.time, k * 1e-3, rtol=0, atol=1e-12)
    np.testing.assert_allclose(log.position, k * 1.0)  # 1000 um per sample = 1 mm
    np.testing.assert_allclose(log.current, 0.5)  # 500 mA
    assert np.array_equal(log.extras["temperature_C"], 20.0 + k)
    assert log.axis == "X"


def test_pretty_printed_messages_and_field_mapping(tmp_path):
    path = tmp_path / "pretty.mcap"
    messages = [
        (k * 2_000_000, json.dumps({"pos": 0.1 * k, "iq": -1.0}, indent=2).encode()) for k in range(100)
    ]
    _write_with_mcap_library(path, messages)
    log = read_log(path, columns={"position_m": "pos", "current_A": "iq"})
    np.testing.assert_allclose(log.position, 100.0 * np.arange(100))  # 0.1 m = 100 mm
    assert np.all(log.current == -1.0)


def test_messages_out_of_time_order_are_sorted(tmp_path):
    path = tmp_path / "unordered.mcap"
    messages = _sample_messages(50)
    _write_with_mcap_library(path, messages[25:] + messages[:25])
    log = read_log(path)
    assert np.all(np.diff(log.time) > 0)
    np.testing.assert_allclose(log.position, np.arange(50.0))


def test_random_bytes_are_not_mcap(tmp_path):
    path = tmp_path / "noise.mcap"
    path.write_bytes(np.random.default_rng(0).bytes(5000))
    assert_read_fails(path, "not an MCAP file")


def test_truncated_file(tmp_path, make_log):
    path = tmp_path / "axis.mcap"
    write_log(make_log(), path)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    assert_read_fails(path, "truncated")


def test_truncated_file_that_ends_with_the_magic_bytes(tmp_path, make_log):
    path = tmp_path / "axis.mcap"
    write_log(make_log(), path)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2] + data[:8])
    assert_read_fails(path, "corrupt or truncated", "runs past the end")


def test_corrupt_chunk(tmp_path, make_log):
    path = tmp_path / "axis.mcap"
    write_log(make_log(), path)
    data = bytearray(path.read_bytes())
    middle = len(data) // 3
    data[middle:middle + 64] = np.random.default_rng(1).bytes(64)
    path.write_bytes(bytes(data))
    assert_read_fails(path, "corrupt")


def test_messages_that_are_not_json(tmp_path):
    path = tmp_path / "binary.mcap"
    _write_with_mcap_library(path, [(k * 1_000_000, b"\x01\x02 not json") for k in range(10)])
    assert_read_fails(path, "not valid JSON")


def test_channel_with_another_encoding(tmp_path):
    path = tmp_path / "proto.mcap"
    _write_with_mcap_library(path, [(k * 1_000_000, b"\x08\x01") for k in range(10)], encoding="protobuf")
    assert_read_fails(path, "message encoding 'protobuf'")


def test_missing_field(tmp_path):
    path = tmp_path / "nocurrent.mcap"
    _write_with_mcap_library(path, [(k * 1_000_000, json.dumps({"position_mm": 1.0}).encode()) for k in range(10)])
    assert_read_fails(path, "missing required column 'current_A'")


def test_field_missing_in_some_messages_is_reported_as_non_finite(tmp_path):
    path = tmp_path / "holes.mcap"
    messages = [(k * 1_000_000, json.dumps({"position_mm": 1.0, "current_A": 2.0}).encode()) for k in range(20)]
    messages[7] = (7_000_000, json.dumps({"position_mm": 1.0}).encode())
    _write_with_mcap_library(path, messages)
    assert_read_fails(path, "channel 'current_A'", "t = 0.007")


def test_repeated_time_stamp(tmp_path):
    path = tmp_path / "repeat.mcap"
    messages = _sample_messages(20)
    messages[10] = (messages[9][0], messages[10][1])
    _write_with_mcap_library(path, messages)
    assert_read_fails(path, "time repeats at sample 10")


def test_writer_refuses_what_mcap_cannot_hold(tmp_path, make_log):
    log = make_log(n=20)
    with pytest.raises(LogError, match="time reaches -1.0 s; MCAP time stamps must be non-negative"):
        write_log(log.replace(time=log.time - 1.0), tmp_path / "negative.mcap")
    with pytest.raises(LogError, match="finite numbers"):
        write_log(log.replace(extras={"bad_A": np.full(20, np.nan)}), tmp_path / "nan.mcap")
    with pytest.raises(LogError, match="share a topic"):
        write_log([log, log], tmp_path / "twice.mcap")
    assert list(tmp_path.iterdir()) == []  # nothing half-written is left behind


def _doc_text():
    from pathlib import Path

    return (Path(__file__).resolve().parents[2] / "docs" / "log-formats.md").read_text(encoding="utf-8")


def test_documented_schema_is_the_written_schema():
    import re

    from greybox.data.mcap_io import AXIS_SAMPLE_SCHEMA

    (block,) = re.findall(r"```json\n(.*?)```", _doc_text(), re.S)
    assert json.loads(block) == AXIS_SAMPLE_SCHEMA


def test_documented_example_logger_writes_a_loadable_file(tmp_path, monkeypatch):
    import re

    (code,) = [block for block in re.findall(r"```python\n(.*?)```", _doc_text(), re.S) if "Writer(" in block]
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "docs/log-formats.md", "exec"), {})
    log = read_log(tmp_path / "axis_X.mcap")
    assert (len(log), log.axis, log.dataset, log.effort_unit) == (5000, "X", "shop-floor", "A")
    assert log.sample_time == pytest.approx(0.002)
    np.testing.assert_allclose(log.position, 100 + 50 * np.sin(0.4 * np.pi * log.time), atol=1e-9)


def _two_channel_file(path, n=700, late=300, chunk_size=2000):
    """/axis/X from the start, /axis/Y registered after ``late`` samples; small chunks (read ahead on the pool).

    Y's messages from sample 600 on carry a text field, so that those chunks go to the general JSON reader.
    Returns the messages of each topic as (log_time_ns, dict) in the order written.
    """
    from mcap.writer import Writer

    rng = np.random.default_rng(11)
    written = {"/axis/X": [], "/axis/Y": []}
    with open(path, "wb") as stream:
        writer = Writer(stream, chunk_size=chunk_size)
        writer.start()
        schema_id = writer.register_schema("greybox.AxisSample", "jsonschema", b'{"type": "object"}')
        ids = {"/axis/X": writer.register_channel("/axis/X", "json", schema_id, {"axis": "X"})}
        for k in range(n):
            if k == late:
                ids["/axis/Y"] = writer.register_channel("/axis/Y", "json", schema_id, {"axis": "Y"})
            for topic, channel_id in ids.items():
                fields = {"position_mm": float(rng.normal()) * 10 ** int(rng.integers(-30, 30)),
                          "current_A": float(rng.normal()), "extra_temperature_C": float(rng.normal())}
                if topic == "/axis/Y" and k >= 600:
                    fields["note"] = "text"
                stamp = k * 2_000_000
                written[topic].append((stamp, fields))
                writer.add_message(channel_id, log_time=stamp, data=json.dumps(fields).encode(), publish_time=stamp)
        writer.finish()
    return written


def test_chunks_read_ahead_on_the_pool_give_python_json_values_bit_for_bit(tmp_path):
    path = tmp_path / "two.mcap"
    written = _two_channel_file(path)
    with open(path, "rb") as stream:
        assert len(make_reader(stream).get_summary().chunk_indexes) > 20  # more chunks than are read ahead
    for topic in ("/axis/X", "/axis/Y"):
        log = read_log(path, topic=topic)
        messages = written[topic]
        assert np.array_equal(log.time, np.array([stamp for stamp, _ in messages]) * 1e-9)
        for name, values in (("position", log.position), ("effort", log.effort),
                             ("extra_temperature_C", log.extras["extra_temperature_C"])):
            field = {"position": "position_mm", "effort": "current_A"}.get(name, name)
            expected = np.array([fields[field] for _, fields in messages])
            assert values.tobytes() == expected.tobytes(), (topic, name)


def test_a_channel_registered_late_makes_the_file_ambiguous_without_a_topic(tmp_path):
    path = tmp_path / "two.mcap"
    _two_channel_file(path)
    with pytest.raises(LogError, match="several channels") as error:
        read_log(path)
    assert str(path) in str(error.value)


def test_reading_ahead_gives_the_same_log_on_any_number_of_threads(tmp_path, make_log):
    import numba

    rng = np.random.default_rng(2)
    log = make_log(n=20000, velocity=rng.normal(size=20000), extras={"truth_friction_A": rng.normal(size=20000)})
    path = tmp_path / "axis.mcap"
    write_log(log, path)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = read_log(path)
    finally:
        numba.set_num_threads(before)
    every = read_log(path)
    assert one.time.tobytes() == every.time.tobytes()
    for name in ("position", "effort", "velocity"):
        assert getattr(one, name).tobytes() == getattr(every, name).tobytes() == getattr(log, name).tobytes(), name
    assert one.extras["truth_friction_A"].tobytes() == every.extras["truth_friction_A"].tobytes() \
        == log.extras["truth_friction_A"].tobytes()
