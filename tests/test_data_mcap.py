"""MCAP reading and writing: round trip, compatibility with the mcap library, bad files."""

from __future__ import annotations

import json

import numpy as np
import pytest
from mcap.reader import make_reader

from greybox.data.io import read_log, write_log
from greybox.data.mcap_io import SCHEMA_NAME, join_slices, scan_records
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
