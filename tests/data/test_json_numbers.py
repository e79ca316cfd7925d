"""The compiled reader of flat JSON objects of numbers against Python's json module, bit for bit."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from greybox.data import json_numbers, mcap_io
from greybox.data.json_numbers import MAX_SLOW_NUMBERS, parse_flat_objects
from greybox.data.log import AxisLog

PROPERTY = settings(max_examples=300, deadline=None, derandomize=True, database=None)


def pack(messages: list[bytes]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Messages laid one after another in one buffer, with a byte of padding between them."""
    buf = np.frombuffer(b"#".join(messages), np.uint8)
    lengths = np.array([len(message) for message in messages], np.int64)
    offsets = np.concatenate([[0], np.cumsum(lengths + 1)[:-1]]).astype(np.int64)
    return buf, offsets, lengths


def reference(messages: list[bytes]) -> dict[str, np.ndarray] | None:
    """Plain Python: every message a JSON object of numbers or nulls, the first message's keys in order."""
    rows = []
    for message in messages:
        try:
            pairs = json.loads(message, object_pairs_hook=list, parse_constant=lambda name: "constant")
        except (ValueError, RecursionError):
            return None
        if not isinstance(pairs, list) or not pairs or len({key for key, _ in pairs}) != len(pairs):
            return None
        rows.append(pairs)
    keys = [key for key, _ in rows[0]]
    columns = {key: [] for key in keys}
    for pairs in rows:
        if [key for key, _ in pairs] != keys:
            return None
        for key, value in pairs:
            if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))):
                return None
            columns[key].append(np.nan if value is None else float(value))
    return {key: np.array(values, np.float64) for key, values in columns.items()}


def assert_same_columns(got, expected):
    assert got is not None and list(got) == list(expected)
    for key in expected:
        equal = (got[key] == expected[key]) | (np.isnan(got[key]) & np.isnan(expected[key]))
        assert equal.all(), (key, got[key][~equal][:3], expected[key][~equal][:3])


def parse(messages, **options):
    return parse_flat_objects(*pack(messages), **options)


finite_doubles = st.floats(allow_nan=False, allow_infinity=False, allow_subnormal=True)
number_text = st.one_of(
    finite_doubles.map(repr),
    st.tuples(finite_doubles, st.sampled_from(["%.17g", "%.3e", "%.6f", "%.25e", "%.1f"])).map(
        lambda pair: pair[1] % pair[0]),
    st.integers(-10 ** 25, 10 ** 25).map(str),
    st.tuples(st.integers(0, 10 ** 22), st.integers(-350, 320)).map(lambda pair: f"{pair[0]}e{pair[1]}"),
    st.tuples(st.text("0123456789", min_size=1, max_size=30), st.text("0123456789", min_size=1, max_size=30))
    .map(lambda pair: f"{pair[0].lstrip('0') or '0'}.{pair[1]}"),
    st.just("null"),
)


@PROPERTY
@given(values=st.lists(st.lists(number_text, min_size=3, max_size=3), min_size=1, max_size=40),
       space=st.sampled_from(["", " ", "\n\t ", "\r\n"]))
def test_numbers_read_as_python_reads_them(values, space):
    keys = ["position_mm", "current_A", "x"]
    messages = [(space + "{" + ",".join(f'{space}"{key}"{space}:{space}{text}{space}' for key, text in zip(keys, row))
                 + "}" + space).encode() for row in values]
    got = parse(messages)
    expected = reference(messages)
    assert expected is not None
    if got is None:  # only when the batch has more numbers to convert slowly than the parser keeps
        slow = [text for row in values for text in row if len(text.replace("-", "").lstrip("0.")) > 19]
        assert len(slow) > MAX_SLOW_NUMBERS
    else:
        assert_same_columns(got, expected)


@PROPERTY
@given(message=st.binary(max_size=60) | st.text(alphabet='{}[]":,.-+eE0123456789 nul\\tab', max_size=60)
       .map(str.encode))
def test_whatever_the_bytes_the_parser_agrees_with_python_or_declines(message):
    template = b'{"a":1.5,"b":-2}'
    for messages in ([message], [template, message], [message, template]):
        got = parse(messages)
        if got is not None:
            assert_same_columns(got, reference(messages))


@pytest.mark.parametrize("text", ["01", "1.", ".5", "+1", "1e", "1e+", "-", "--1", "NaN", "Infinity", "-Infinity",
                                  "1.5.2", "0x10", "1_000", "true", "false", '"1.5"', "[1]", "{}", "nul", "1 2"])
def test_anything_but_a_json_number_or_null_is_declined(text):
    assert parse([b'{"a":1.0,"b":2.0}', f'{{"a":1.0,"b":{text}}}'.encode()]) is None


@pytest.mark.parametrize("message", [
    b'{"a":1.0}',  # a key missing
    b'{"b":2.0,"a":1.0}',  # another order
    b'{"a":1.0,"b":2.0,"c":3.0}',  # a key more
    b'{"a":1.0,"c":2.0}',  # another key
    b'{"a":1.0,"b":2.0,}',  # a trailing comma
    b'{"a":1.0,"b":2.0',  # cut short
    b'{"a":1.0,"b":2.0}}',  # more after the object
    b'{"a":1.0,"b":{"c":2.0}}',  # nested
    b'{"a":1.0 "b":2.0}',  # no comma
])
def test_a_message_unlike_the_first_is_declined(message):
    assert parse([b'{"a":1.0,"b":2.0}', message]) is None
    assert parse([b'{"a":1.0,"b":2.0}'] * 3) is not None


@pytest.mark.parametrize("first", [b'{"a":1.0,"a":2.0}', b'{"a\\u0062":1.0}', b'{"\xff":1.0}', b"{}", b"[1.0]"])
def test_keys_the_parser_does_not_take_are_declined(first):
    assert parse([first]) is None


def test_null_reads_as_nan_and_negative_zero_keeps_its_sign():
    got = parse([b'{"a":null,"b":-0.0}', b'{"a":2.5,"b":-0}'])
    assert np.isnan(got["a"][0]) and got["a"][1] == 2.5
    assert np.all(np.signbit(got["b"]))


def test_numbers_beyond_the_fast_conversion_are_exact():
    texts = ["0.1000000000000000055511151231257827021181583404541015625",  # 56 significant digits
             "4.9406564584124654e-324", "2.2250738585072011e-308",  # subnormal and just below the normal range
             "1.7976931348623157e308", "1e-400", "123456789012345678901234567890", "9007199254740993",
             "2.0000000000000001110223024625156540423631668090820312500000001"]  # just above a halfway point
    got = parse([f'{{"v":{text}}}'.encode() for text in texts])
    np.testing.assert_array_equal(got["v"].view(np.int64), np.array([float(text) for text in texts]).view(np.int64))


def test_more_slow_numbers_than_kept_are_declined():
    slow = b'{"v":0.10000000000000000000001}'
    assert parse([slow] * MAX_SLOW_NUMBERS, threads=1) is not None
    assert parse([slow] * (MAX_SLOW_NUMBERS + 1), threads=1) is None


@pytest.mark.parametrize("threads", [2, 3])
def test_threads_give_the_same_columns_as_one(threads):
    rng = np.random.default_rng(4)
    values = rng.standard_normal((5000, 4)) * 10.0 ** rng.integers(-20, 20, (5000, 4))
    messages = [json.dumps(dict(zip("abcd", row))).encode() for row in values.tolist()]
    messages[4321] = b'{"a":0.1000000000000000000000000001,"b":1e-320,"c":null,"d":7}'
    one = parse(messages, threads=1)
    assert_same_columns(parse(messages, threads=threads), one)
    assert_same_columns(one, reference(messages))
    assert parse(messages[:-1] + [b'{"a":1,"b":2,"c":3}'], threads=threads) is None


def test_the_table_of_powers_of_five_is_the_exact_power_normalised():
    table = json_numbers._POWERS_OF_FIVE
    for q in (0, 1, 27, 55, 308):
        value = 5 ** q
        shift = 128 - value.bit_length()
        expected = value << shift if shift >= 0 else value >> -shift
        assert (int(table[q + 342, 0]) << 64) | int(table[q + 342, 1]) == expected
    for q in (-1, -27, -28, -342):  # the reciprocal, rounded up: never below 2**k / 5**-q
        word = (int(table[q + 342, 0]) << 64) | int(table[q + 342, 1])
        assert word >> 127 == 1
        power = 5 ** -q
        exponent = next(k for k in range(2000) if (1 << k) // power >= 1 << 127)
        assert word >= (1 << exponent) // power


def test_an_mcap_log_reads_the_same_by_either_parser(tmp_path, monkeypatch):
    rng = np.random.default_rng(2)
    n = 3000
    log = AxisLog(time=np.arange(n) * 0.002, position=np.cumsum(rng.normal(size=n)), effort=rng.normal(size=n),
                  velocity=rng.normal(size=n) * 1e-17, extras={"temperature_C": rng.normal(size=n) * 1e300})
    path = tmp_path / "x.mcap"
    mcap_io.write_mcap(log, path)
    fast = mcap_io.read_mcap(path)
    monkeypatch.setattr(mcap_io, "parse_flat_objects", lambda *args, **kwargs: None)
    general = mcap_io.read_mcap(path)
    for name, values in fast.named_channels(time=True):
        np.testing.assert_array_equal(values, dict(general.named_channels(time=True))[name])
    np.testing.assert_array_equal(fast.position, log.position)
    np.testing.assert_array_equal(fast.extras["temperature_C"], log.extras["temperature_C"])


def test_the_128_bit_product_is_the_exact_product_compiled_and_plain():
    """The compiled multiplication (one 128-bit product) and the plain-Python one (32-bit words, what
    NUMBA_DISABLE_JIT=1 runs) both give the exact product's high and low words."""
    rng = np.random.default_rng(7)
    edges = [0, 1, 2 ** 32 - 1, 2 ** 32, 2 ** 63, 2 ** 64 - 1]
    pairs = [(a, b) for a in edges for b in edges] + [tuple(map(int, pair)) for pair in
                                                      rng.integers(0, 2 ** 64 - 1, (500, 2), np.uint64, True)]
    compiled = njit(lambda a, b: json_numbers._multiply(a, b))
    for a, b in pairs:
        exact = a * b
        expected = (exact >> 64, exact & (2 ** 64 - 1))
        for multiply in (compiled, json_numbers._multiply):
            high, low = multiply(np.uint64(a), np.uint64(b))
            assert (int(high), int(low)) == expected, (a, b, multiply)


@PROPERTY
@given(text=st.binary(min_size=0, max_size=10) | st.text("0123456789/:", min_size=8, max_size=9).map(str.encode))
def test_eight_digits_at_once_read_as_int_reads_them(text):
    buf = np.frombuffer(text, np.uint8)
    expected = int(text[:8]) if len(text) >= 8 and text[:8].isdigit() else -1
    plain = getattr(json_numbers._eight_digits, "py_func", json_numbers._eight_digits)  # what NUMBA_DISABLE_JIT runs
    for kernel in (json_numbers._eight_digits, plain):
        assert kernel(buf, 0, buf.size) == expected
    padded = np.frombuffer(text.ljust(8, b"\0"), np.uint8)
    for kernel in (json_numbers.read_u64, getattr(json_numbers.read_u64, "py_func", json_numbers.read_u64)):
        assert kernel(padded, 0) == int.from_bytes(padded[:8].tobytes(), "little")


def test_compiled_and_plain_python_parsers_give_the_same_bits(tmp_path):
    """The kernels with the compiler off (NUMBA_DISABLE_JIT=1, a fresh process) read the same bits as compiled."""
    rng = np.random.default_rng(9)
    values = rng.standard_normal((300, 4)) * 10.0 ** rng.integers(-30, 30, (300, 4))
    texts = [[repr(value) for value in row] for row in values.tolist()]
    texts[0] = ["0.000123456789012345678", "-0.0", "12345678901234567", "1e-400"]  # leading zeros, -0, long
    texts[1] = ["123456789.87654321", "0.00000000", "99999999999999999999", "7"]
    messages = ["{" + ",".join(f'"k{key}":{text}' for key, text in enumerate(row)) + "}" for row in texts]
    source = tmp_path / "messages.json"
    source.write_text(json.dumps(messages))
    script = (
        "import json, sys, numpy as np\n"
        "from greybox.data.json_numbers import parse_flat_objects\n"
        "messages = [m.encode() for m in json.load(open(sys.argv[1]))]\n"
        "buf = np.frombuffer(b''.join(messages), np.uint8)\n"
        "lengths = np.array([len(m) for m in messages], np.int64)\n"
        "offsets = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)\n"
        "columns = parse_flat_objects(buf, offsets, lengths, threads=1)\n"
        "print(json.dumps({key: column.view(np.int64).tolist() for key, column in columns.items()}))\n"
    )
    environment = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    plain = subprocess.run([sys.executable, "-c", script, str(source)], env=environment, check=True,
                           capture_output=True, text=True)
    compiled = parse([message.encode() for message in messages], threads=1)
    assert json.loads(plain.stdout) == {key: column.view(np.int64).tolist() for key, column in compiled.items()}
    for key, column in compiled.items():
        expected = [float(row[int(key[1:])]) for row in texts]
        assert column.view(np.int64).tolist() == np.array(expected).view(np.int64).tolist()


def test_a_borrowed_view_is_the_array_itself_compiled_and_plain():
    """The view passed to the number reader without reference counting reads and writes the array's memory."""
    @njit
    def through_view(array, row, value):
        view = json_numbers._borrow(array)
        view[row, 1] = value
        return view.shape, view.strides, view.sum()

    array = np.arange(12.0).reshape(4, 3)[::2]  # not contiguous: strides carried over
    shape, strides, total = through_view(array, 1, -100.0)
    assert shape == array.shape and strides == array.strides
    assert array[1, 1] == -100.0 and total == array.sum()
    assert json_numbers._borrow(array) is array


def test_results_at_the_ends_of_the_normal_range_are_scaled_exactly():
    """Numbers converted through the 128-bit product whose double has the smallest or the largest exponent."""
    texts = ["2.2250738585072014e-308", "2.2250738585072019e-308", "4.4501477170144023e-308",
             "1.7976931348623157e308", "8.98846567431158e307", "1.2345678901234567e-307"]
    got = parse([f'{{"v":{text}}}'.encode() for text in texts])
    np.testing.assert_array_equal(got["v"].view(np.int64), np.array([float(text) for text in texts]).view(np.int64))
