"""The message format: one sample, a batch as columns or as rows, CSV lines; refusals name the problem."""

from __future__ import annotations

import json

import numpy as np
import pytest

from greybox.live.messages import Decoder, MessageError, estimate_message, message_log, parse_json

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
