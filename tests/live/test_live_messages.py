"""The message format: one sample, a batch as columns or as rows, CSV lines; refusals name the problem."""

from __future__ import annotations

import json

import numpy as np
import pytest

from greybox.live.messages import (
    Decoder,
    MessageBounds,
    MessageError,
    MessageLogs,
    estimate_message,
    finite_rows,
    json_depth,
    message_log,
    parse_json,
)

ROWS = [{"time_s": 0.0, "position_mm": 1.0, "velocity_mm_s": 0.5, "current_A": 0.1},
        {"time_s": 0.002, "position_mm": 1.001, "velocity_mm_s": 0.5, "current_A": 0.2}]


def test_three_json_shapes_give_the_same_samples():
    as_rows, seq = parse_json(json.dumps([{**ROWS[0], "seq": 7}, ROWS[1]]))
    as_columns, _ = parse_json(json.dumps({name: [row[name] for row in ROWS] for name in ROWS[0]}))
    single, _ = parse_json(json.dumps(ROWS[0]))
    assert seq == 7
    for name in ROWS[0]:
        np.testing.assert_array_equal(as_rows[name], as_columns[name])
        assert single[name][0] == ROWS[0][name]


def test_units_are_converted_as_the_readers_do():
    columns, _ = parse_json(json.dumps({"time_ms": [0, 2], "position_m": [0.001, 0.002], "current_A": [0, 1]}))
    log = message_log(columns, name="m")
    np.testing.assert_allclose(log.time, [0.0, 0.002])
    np.testing.assert_allclose(log.position, [1.0, 2.0])


def test_csv_lines_after_a_header():
    decoder = Decoder()
    assert decoder.decode("# greybox {}") is None
    assert decoder.decode("time_s,position_mm,current_A") is None
    columns, seq = decoder.decode(b"0.004,2.5,-0.25\n")
    assert seq is None and columns["position_mm"][0] == 2.5
    with pytest.raises(MessageError, match="3 fields, the header names 3|2 fields"):
        decoder.decode("0.006,2.5")


def test_a_non_json_line_in_a_json_stream_is_refused_not_taken_for_a_header():
    decoder = Decoder()
    decoder.decode(json.dumps(ROWS[0]))
    with pytest.raises(MessageError, match="not JSON"):
        decoder.decode("time_s,position_mm,current_A")


@pytest.mark.parametrize("text, words", [
    ("{", "not JSON"),
    ("3", "must be a JSON object"),
    ('{"time_s": [0, 1], "position_mm": [1], "current_A": [0, 0]}', "different lengths"),
    ('{"time_s": true, "position_mm": 1, "current_A": 0}', "holds True, not a number"),
    ('{"time_s": [[0]], "position_mm": 1, "current_A": 0}', "nested lists"),
    ("{}", "no samples"),
    (json.dumps({"time_s": [0.0] * 100_001, "position_mm": [0.0] * 100_001, "current_A": [0.0] * 100_001}),
     "100001 samples, more than 100000"),
])
def test_malformed_json_is_refused(text, words):
    with pytest.raises(MessageError, match=words):
        parse_json(text)


def test_non_finite_values_are_refused_naming_the_channel():
    columns, _ = parse_json('{"time_s": [0, 0.002], "position_mm": [1, NaN], "current_A": [0, 0]}')
    with pytest.raises(MessageError, match="channel 'position_mm' holds nan at sample 1"):
        message_log(columns, name="m")


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning", "ignore:invalid value:RuntimeWarning")
def test_finite_values_whose_sum_overflows_are_taken_and_one_infinity_among_them_is_named():
    big = {"time_s": np.array([0.0, 0.002]), "position_mm": np.array([1e308, 1e308]),
           "current_A": np.array([-1e308, -1e308])}  # every value finite, their sum not
    reader = MessageLogs()
    for k in range(2):  # the first message read afresh, the second through the stream's plan
        np.testing.assert_array_equal(reader.log(big, name=f"message {k}").position, big["position_mm"])
    assert finite_rows(big)[1] == 0
    bad = {**big, "current_A": np.array([-1e308, -np.inf])}
    with pytest.raises(MessageError, match="channel 'current_A' holds -inf at sample 1"):
        reader.log(bad, name="message 2")
    assert finite_rows(bad)[1] == 1


def test_estimate_messages_are_json_with_the_sequence_tag():
    text = estimate_message({"time_s": np.array([0.0, 0.002]), "current_process_A": np.array([0.5, np.inf])}, seq=3)
    assert json.loads(text) == {"time_s": [0.0, 0.002], "current_process_A": [0.5, None], "seq": 3}


def test_estimate_messages_carry_every_float_exactly():
    rng = np.random.default_rng(5)
    values = np.concatenate([rng.normal(size=200) * 10.0 ** rng.integers(-300, 300, 200), [-0.0, 5e-324, 1.5e308]])
    text = estimate_message({"current_process_A": values}, seq="a", axis="X")
    back = json.loads(text)
    assert back["seq"] == "a" and back["axis"] == "X"
    np.testing.assert_array_equal(np.array(back["current_process_A"]), values)


def test_a_message_with_nan_reads_as_its_strict_part_does():
    rng = np.random.default_rng(6)
    message = {"time_s": (np.arange(10) * 0.002).tolist(), "position_mm": rng.normal(size=10).tolist(), "seq": 7}
    strict, seq = parse_json(json.dumps(message))
    nan_column = '"current_A": [' + ", ".join(["NaN"] * 10) + '], "seq"'
    with_nan, _ = parse_json(json.dumps(message).replace('"seq"', nan_column))
    assert seq == 7
    for name in ("time_s", "position_mm"):
        np.testing.assert_array_equal(strict[name], message[name])
        np.testing.assert_array_equal(with_nan[name], message[name])
    assert np.isnan(with_nan["current_A"]).all()


def _same_log(got, expected):
    assert (got.effort_unit, got.motion, got.axis, got.source, got.attrs, got.extras) == \
        (expected.effort_unit, expected.motion, expected.axis, expected.source, expected.attrs, expected.extras)
    channels, wanted_channels = got.named_channels(time=True), expected.named_channels(time=True)
    assert [name for name, _ in channels] == [name for name, _ in wanted_channels]
    for (name, values), (_, wanted) in zip(channels, wanted_channels):
        np.testing.assert_array_equal(values, wanted, err_msg=name)


LAYOUTS = {  # columns of a stream's messages, mapping, axis; whether the names are resolved once
    "canonical": (["time_s", "position_mm", "velocity_mm_s", "current_A"], None, None, True),
    "other units": (["time_ms", "position_m", "current_mA"], None, None, True),
    "one axis of two": (["time_s", "X_position_mm", "X_current_A", "Y_position_mm", "Y_current_A"], None, "Y", True),
    "mapped": (["time_s", "pos", "I", "spare"], {"position_um": "pos", "current_A": "I"}, None, True),
    "motor torque": (["time_s", "position_mm", "torque_Nm"], None, None, True),
    "rotary": (["time_s", "position_deg", "torque_Nm"], None, None, False),
}


@pytest.mark.parametrize("layout", LAYOUTS)
def test_the_stream_reader_gives_what_message_log_gives(layout):
    names, mapping, axis, planned = LAYOUTS[layout]
    reader = MessageLogs(mapping=mapping)
    rng = np.random.default_rng(8)
    for k in range(3):
        columns = {name: rng.normal(size=5) for name in names}
        columns[names[0]] = (k * 5 + np.arange(5)) * (2.0 if names[0] == "time_ms" else 0.002)
        got = reader.log(columns, name=f"message {k}", axis=axis)
        _same_log(got, message_log(columns, name=f"message {k}", mapping=mapping, axis=axis))
    assert (reader._plan is not None) == planned  # names resolved once where the plan gives the same log


def test_the_stream_reader_refuses_a_later_message_as_message_log_does():
    reader = MessageLogs()
    good = {"time_s": np.array([0.0, 0.002]), "position_mm": np.array([1.0, 2.0]), "current_A": np.array([0.0, 1.0])}
    reader.log(good, name="message 1")
    bad = {**good, "current_A": np.array([0.5, np.inf])}
    with pytest.raises(MessageError) as expected:
        message_log(bad, name="message 2")
    with pytest.raises(MessageError) as got:
        reader.log(bad, name="message 2")
    assert str(got.value) == str(expected.value) and "current_A" in str(got.value)
    other = {"time_s": good["time_s"], "position_mm": good["position_mm"]}  # new names: read and refused afresh
    with pytest.raises(MessageError, match="current_A"):
        reader.log(other, name="message 3")


def test_number_columns_read_as_the_general_reader_reads_them():
    rng = np.random.default_rng(9)
    message = {"time_s": (np.arange(6) * 0.002).tolist(), "position_mm": [1, 2, 3, 4, 5, 6],
               "current_A": rng.normal(size=6).tolist(), "seq": "a7"}
    columns, seq = parse_json(json.dumps(message))
    assert seq == "a7" and list(columns) == ["time_s", "position_mm", "current_A"]
    for name in columns:
        assert columns[name].dtype == np.float64
        np.testing.assert_array_equal(columns[name], np.array(message[name], dtype=float))
    single, seq = parse_json('{"time_s": 1, "position_mm": 2.5, "current_A": -3, "seq": 4}')
    assert seq == 4 and {name: values.tolist() for name, values in single.items()} == \
        {"time_s": [1.0], "position_mm": [2.5], "current_A": [-3.0]}
    with pytest.raises(MessageError, match="column 'current_A' holds 'x', not a number"):
        parse_json('{"time_s": 1, "position_mm": 2.5, "current_A": "x"}')


@pytest.mark.parametrize("text", ["[" * 1000 + "]" * 1000, '{"a": ' * 1000 + "1" + "}" * 1000,
                                  '{"time_s": [0], "x": ' + "[" * 5000 + "]" * 5000 + "}"])
def test_deep_nesting_is_refused_without_recursion(text):
    with pytest.raises(MessageError, match=r"JSON nested \d+ levels deep, more than 8"):
        parse_json(text)
    with pytest.raises(MessageError, match="more than 3"):
        Decoder(MessageBounds(max_depth=3)).decode(text.encode())


def test_json_depth_counts_brackets_outside_strings():
    assert json_depth(b'{"a": [1, 2], "b": "[[[\\"[{"}') == 2
    assert json_depth("[[], [[]]]") == 3 and json_depth("1") == 0
    assert json_depth(json.dumps(ROWS)) == 2  # the shapes of a message need two levels


def test_a_message_over_the_size_bound_is_refused_before_it_is_read():
    text = json.dumps({"time_s": [0.0, 0.002], "position_mm": [1.0, 2.0], "current_A": [0.0, 0.0]})
    assert parse_json(text, MessageBounds(max_bytes=len(text)))[0]["time_s"].size == 2
    with pytest.raises(MessageError, match=f"holds {len(text)} bytes, more than {len(text) - 1}"):
        Decoder(MessageBounds(max_bytes=len(text) - 1)).decode(text.encode())
    with pytest.raises(MessageError, match="holds 2 samples, more than 1"):
        parse_json(text, MessageBounds(max_samples=1))
    with pytest.raises(ValueError, match="max_depth"):
        MessageBounds(max_depth=0)
