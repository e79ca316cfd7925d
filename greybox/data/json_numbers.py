"""Compiled reading of JSON messages that are flat objects of numbers, correctly rounded.

An MCAP axis log carries one JSON object per sample, e.g.
``{"position_mm":-250.0,"velocity_mm_s":0.0,"current_A":0.027}``, the same keys in
the same order in every message. :func:`parse_flat_objects` reads a batch of such
messages straight from the decompressed chunk (no copy of the text) into one
float64 column per key. It accepts strict JSON only: an object whose values are
numbers or ``null`` (read as NaN), with the keys of the batch's first message in
the same order in every message. For anything else (strings, nesting, other
keys, escapes in keys, invalid JSON) it returns ``None`` and the caller parses
the batch with a general JSON reader, which gives the same columns or the error.

Numbers are converted to the nearest double (ties to even), as Python's
``float`` converts them:

* a decimal mantissa ``w`` of at most 19 significant digits with a power of ten
  ``q`` is exact in doubles when ``w <= 2**53`` and ``|q| <= 22`` (Clinger's
  fast path: one correctly rounded multiplication or division);
* otherwise ``w * 10**q`` is rounded from its product with a 128-bit truncated
  power of five (the Eisel-Lemire algorithm; D. Lemire, "Number parsing at a
  gigabyte per second", Software: Practice and Experience 51, 2021), which
  either gives the correctly rounded result or reports that it cannot decide;
* the few numbers left (more than 19 significant digits, undecided products,
  results outside the normal range of doubles) are converted by ``float`` on
  their text, at most :data:`MAX_SLOW_NUMBERS` per batch.

Digits are read eight at a time from one 64-bit word while they fit the 19 kept,
keys are compared eight bytes at a time, and the 128-bit products are one
machine multiplication; each of these gives exactly what the byte-by-byte and
32-bit-word code gives, which is what runs with the compiler off
(``NUMBA_DISABLE_JIT=1``). The rounded mantissa is scaled by a table of powers of
two (exact for normal results) rather than by a library call. The tables are
constants of the compiled code, and the text reaches the number reader as a view
that is not reference counted (:func:`_borrow`): passing arrays to a compiled
function that is not inlined otherwise counts references up and down at every
number, atomic operations on memory shared by the parsing threads, which took
a third to a half of the parsing time.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic, overload

from ..threads import shared_pool

__all__ = ["parse_flat_objects", "read_u64", "MAX_KEYS", "MAX_SLOW_NUMBERS", "MIN_MESSAGES_PER_THREAD"]

#: Keys a message may have (beyond: the batch goes to the general reader).
MAX_KEYS = 1024

#: Numbers per batch that may be handed to Python's ``float`` (beyond: the batch goes to the general reader).
MAX_SLOW_NUMBERS = 4096

#: Fewest messages worth a thread of their own.
MIN_MESSAGES_PER_THREAD = 1024

_SMALLEST_POWER, _LARGEST_POWER = -342, 308  # decimal exponents of the table of powers of five


def _powers_of_five() -> np.ndarray:
    """``5**q`` for q in [-342, 308], normalised to 128 bits (top bit set), as (high, low) uint64 words.

    Non-negative powers are truncated; negative ones are the reciprocal rounded up (then truncated where
    it needs more than 128 bits), so that the product with a mantissa never undershoots.
    """
    table = np.empty((_LARGEST_POWER - _SMALLEST_POWER + 1, 2), np.uint64)
    for index, q in enumerate(range(_SMALLEST_POWER, _LARGEST_POWER + 1)):
        if q >= 0:
            value = 5 ** q
            bits = value.bit_length()
            value = value << (128 - bits) if bits < 128 else value >> (bits - 128)
        else:
            power = 5 ** -q
            width = power.bit_length()
            value = (1 << (width + 127 if q >= -27 else 2 * width + 128)) // power + 1
            value >>= max(value.bit_length() - 128, 0)
        table[index] = (value >> 64, value & ((1 << 64) - 1))
    return table


_POWERS_OF_FIVE = _powers_of_five()
_EXACT_POWERS_OF_TEN = np.array([10.0 ** k for k in range(23)])
# 2**(e - 1075) for each biased exponent e of a double: a 53-bit mantissa times it is the double (exact)
_MANTISSA_SCALES = np.array([math.ldexp(1.0, e - 1075) for e in range(0x7FF)])

_MASK32 = np.uint64(0xFFFFFFFF)
_ALL_ONES = np.uint64(0xFFFFFFFFFFFFFFFF)
_TWO_TO_53 = np.uint64(1 << 53)
_TEN_TO_8 = np.uint64(10 ** 8)
_HIGH_NIBBLES = np.uint64(0xF0F0F0F0F0F0F0F0)
_SIXES = np.uint64(0x0606060606060606)
_ASCII_ZEROS = np.uint64(0x3030303030303030)
_EVEN_BYTES = np.uint64(0x00FF00FF00FF00FF)
_LANE = np.uint64(0xFFFF)

# status of a parsed number
_EXACT, _SLOW, _INVALID = 0, 1, 2


def _multiply(a, b):
    """The 128-bit product of two uint64 values, as (high, low) words.

    This plain-Python body runs with the compiler off (``NUMBA_DISABLE_JIT=1``) and is the tests' reference;
    compiled code calls one 64 x 64 -> 128-bit multiplication instead (:func:`_wide_product`).
    """
    shift = np.uint64(32)
    a_low, a_high = a & _MASK32, a >> shift
    b_low, b_high = b & _MASK32, b >> shift
    low_low = a_low * b_low
    low_high = a_low * b_high
    high_low = a_high * b_low
    middle = (low_low >> shift) + (low_high & _MASK32) + high_low
    high = a_high * b_high + (middle >> shift) + (low_high >> shift)
    low = (middle << shift) | (low_low & _MASK32)
    return high, low


@intrinsic
def _wide_product(typingctx, a, b):
    """The 128-bit product of two uint64 values as (high, low) words, by LLVM's 128-bit multiplication."""
    if a != types.uint64 or b != types.uint64:
        return None
    sig = types.UniTuple(types.uint64, 2)(types.uint64, types.uint64)

    def codegen(context, builder, signature, args):
        wide = ir.IntType(128)
        product = builder.mul(builder.zext(args[0], wide), builder.zext(args[1], wide))
        high = builder.trunc(builder.lshr(product, ir.Constant(wide, 64)), ir.IntType(64))
        low = builder.trunc(product, ir.IntType(64))
        return context.make_tuple(builder, signature.return_type, (high, low))
    return sig, codegen


@overload(_multiply)
def _multiply_compiled(a, b):
    """Compiled :func:`_multiply`: the 128-bit multiplication."""
    return lambda a, b: _wide_product(a, b)


def _borrow(array):
    """``array`` itself; compiled (:func:`_borrowed_view`), a view of it that holds no reference.

    A compiled function passing an array to another that is not inlined counts a reference to it up and
    down at each call, by atomic operations on memory that the threads parsing share; a view without
    a reference (the caller keeps ``array`` alive) is passed at the cost of an argument. What it reads
    is unchanged, so the plain-Python run is this function.
    """
    return array


@intrinsic
def _borrowed_view(typingctx, array):
    """The array ``array`` with no owner (meminfo and parent null): not reference counted."""
    if not isinstance(array, types.Array):
        return None

    def codegen(context, builder, signature, args):
        view = context.make_array(signature.args[0])(context, builder, value=args[0])
        view.meminfo = ir.Constant(view.meminfo.type, None)
        view.parent = ir.Constant(view.parent.type, None)
        return view._getvalue()
    return array(array), codegen


@overload(_borrow)
def _borrow_compiled(array):
    """Compiled :func:`_borrow`: the view without a reference."""
    return lambda array: _borrowed_view(array)


@njit(cache=True, nogil=True)
def _leading_zeros(w):
    """Leading zero bits of a non-zero uint64."""
    count = 0
    for width in (32, 16, 8, 4, 2, 1):
        if w >> np.uint64(64 - width) == np.uint64(0):
            w = w << np.uint64(width)
            count += width
    return count


@njit(cache=True, nogil=True)
def _eisel_lemire(w, q):
    """``w * 10**q`` rounded to the nearest double, for a non-zero uint64 ``w``.

    Returns
    -------
    value : float
    decided : bool
        False when the result cannot be decided from 128 bits or is not a normal double.
    """
    if q < _SMALLEST_POWER or q > _LARGEST_POWER:
        return 0.0, False
    powers = _POWERS_OF_FIVE  # a global array: a constant of the compiled code
    zeros = _leading_zeros(w)
    w = w << np.uint64(zeros)
    index = q - _SMALLEST_POWER
    high, low = _multiply(w, powers[index, 0])
    precision_mask = _ALL_ONES >> np.uint64(55)  # 52 mantissa bits, the hidden bit, a rounding bit, one spare
    if high & precision_mask == precision_mask:
        second_high, _ = _multiply(w, powers[index, 1])
        room = _ALL_ONES - low  # add to the low word, carrying into the high one (without wrapping around)
        if second_high > room:
            low = second_high - room - np.uint64(1)
            high = high + np.uint64(1)
        else:
            low = low + second_high
    if low == _ALL_ONES and (q < -27 or q > 55):
        return 0.0, False
    upper_bit = int(high >> np.uint64(63))
    shift = np.uint64(upper_bit + 9)
    mantissa = high >> shift
    power2 = (((q * (152170 + 65536)) >> 16) + 63) + upper_bit - zeros + 1023
    if power2 <= 0:
        return 0.0, False
    if (low <= np.uint64(1) and -4 <= q <= 23 and mantissa & np.uint64(3) == np.uint64(1)
            and (mantissa << shift) == high):
        mantissa = mantissa & ~np.uint64(1)  # exactly halfway: round to even, down
    mantissa = (mantissa + (mantissa & np.uint64(1))) >> np.uint64(1)
    if mantissa >= np.uint64(2) << np.uint64(52):
        mantissa = np.uint64(1) << np.uint64(52)
        power2 += 1
    if power2 >= 0x7FF:
        return 0.0, False
    return float(mantissa) * _MANTISSA_SCALES[power2], True


@njit(cache=True, nogil=True)
def read_u64(buf, pos):
    """The little-endian uint64 at ``buf[pos:pos + 8]`` (a uint8 array; the bytes must be there).

    Indexed with an unsigned position, so that the compiler makes one load of it (a signed index is
    checked for wrapping around from the end, byte by byte).

    Parameters
    ----------
    buf : ndarray of uint8
        Bytes.
    pos : int
        Offset of the first byte.
    """
    at = np.uint64(pos)
    value = np.uint64(0)
    for k in range(8):
        value |= np.uint64(buf[at + np.uint64(k)]) << np.uint64(8 * k)
    return value


@njit(cache=True, nogil=True)
def _is_digit(byte):
    return 48 <= byte <= 57


@njit(cache=True, nogil=True)
def _eight_digits(buf, pos, stop):
    """The value of the eight decimal digits at ``buf[pos:pos + 8]``; -1 if they are not eight digits.

    The bytes are read as one word, checked to be digits all at once and combined in pairs, then fours
    (SIMD within a register); no step overflows 64 bits, so the plain-Python run gives the same.
    """
    if pos + 8 > stop:
        return -1
    word = read_u64(buf, pos)
    if word & _HIGH_NIBBLES != _ASCII_ZEROS:  # bytes 0x30 to 0x3F
        return -1
    if (word + _SIXES) & _HIGH_NIBBLES != _ASCII_ZEROS:  # and up to 0x39 ('9'), if adding 6 keeps them below 0x40
        return -1
    word = word - _ASCII_ZEROS
    word = word * np.uint64(10) + (word >> np.uint64(8))
    word = word & _EVEN_BYTES
    word = word * np.uint64(100) + (word >> np.uint64(16))
    return np.int64((word & _LANE) * np.uint64(10000) + ((word >> np.uint64(32)) & _LANE))


@njit(cache=True, nogil=True)
def _number(buf, pos, stop):
    """Parse the JSON number at ``buf[pos]``.

    Returns
    -------
    value : float
    end : int
        Position after the number.
    status : int
        ``_EXACT`` (value correctly rounded), ``_SLOW`` (valid, but to be converted by ``float``) or
        ``_INVALID`` (not a JSON number).
    """
    negative = buf[pos] == 45  # '-'
    if negative:
        pos += 1
    if pos >= stop or not _is_digit(buf[pos]):
        return 0.0, pos, _INVALID
    w = np.uint64(0)
    digits = 0  # significant digits in w
    too_long = False
    if buf[pos] == 48:  # '0' alone before the point
        pos += 1
        if pos < stop and _is_digit(buf[pos]):
            return 0.0, pos, _INVALID
    else:
        while digits <= 11:  # eight digits at a time while 19 significant ones hold
            eight = _eight_digits(buf, pos, stop)
            if eight < 0:
                break
            w = w * _TEN_TO_8 + np.uint64(eight)
            digits += 8
            pos += 8
        while pos < stop and _is_digit(buf[pos]):
            if digits < 19:
                w = w * np.uint64(10) + np.uint64(buf[pos] - 48)
                digits += 1
            else:
                too_long = True
            pos += 1
    exponent = 0
    if pos < stop and buf[pos] == 46:  # '.'
        pos += 1
        if pos >= stop or not _is_digit(buf[pos]):
            return 0.0, pos, _INVALID
        while pos < stop and buf[pos] == 48 and w == 0:  # leading zeros: not significant digits
            exponent -= 1
            pos += 1
        while digits <= 11:
            eight = _eight_digits(buf, pos, stop)
            if eight < 0:
                break
            w = w * _TEN_TO_8 + np.uint64(eight)
            digits += 8
            exponent -= 8
            pos += 8
        while pos < stop and _is_digit(buf[pos]):
            digit = buf[pos] - 48
            if w == 0 and digit == 0:
                exponent -= 1
            elif digits < 19:
                w = w * np.uint64(10) + np.uint64(digit)
                digits += 1
                exponent -= 1
            else:
                too_long = True
            pos += 1
    if pos < stop and (buf[pos] == 101 or buf[pos] == 69):  # 'e' or 'E'
        pos += 1
        sign = 1
        if pos < stop and (buf[pos] == 43 or buf[pos] == 45):
            sign = -1 if buf[pos] == 45 else 1
            pos += 1
        if pos >= stop or not _is_digit(buf[pos]):
            return 0.0, pos, _INVALID
        power = 0
        while pos < stop and _is_digit(buf[pos]):
            if power < 100000:
                power = power * 10 + (int(buf[pos]) - 48)
            pos += 1
        exponent += sign * power
    if too_long:
        return 0.0, pos, _SLOW
    if w == 0:
        return (-0.0 if negative else 0.0), pos, _EXACT
    if w <= _TWO_TO_53 and -22 <= exponent <= 22:
        value = float(w)
        value = value * _EXACT_POWERS_OF_TEN[exponent] if exponent >= 0 else value / _EXACT_POWERS_OF_TEN[-exponent]
    else:
        value, decided = _eisel_lemire(w, exponent)
        if not decided:
            return 0.0, pos, _SLOW
    return (-value if negative else value), pos, _EXACT


@njit(cache=True, nogil=True)
def _skip_space(buf, pos, stop):
    while pos < stop and (buf[pos] == 32 or buf[pos] == 10 or buf[pos] == 13 or buf[pos] == 9):
        pos += 1
    return pos


@njit(cache=True, nogil=True)
def _keys(buf, start, stop, max_keys):
    """Start and length of each key of the flat object ``buf[start:stop]``; -1 keys if it is not one.

    A key holding a backslash (an escape) or a value that is not a number or null also gives -1.
    """
    starts = np.empty(max_keys, np.int64)
    lengths = np.empty(max_keys, np.int64)
    pos = _skip_space(buf, start, stop)
    if pos >= stop or buf[pos] != 123:  # '{'
        return starts, lengths, -1
    pos = _skip_space(buf, pos + 1, stop)
    count = 0
    if pos < stop and buf[pos] == 125:  # '}': no keys
        return starts, lengths, -1
    while True:
        if count == max_keys or pos >= stop or buf[pos] != 34:  # '"'
            return starts, lengths, -1
        pos += 1
        first = pos
        while pos < stop and buf[pos] != 34:
            if buf[pos] == 92 or buf[pos] < 32:  # '\' or a control character
                return starts, lengths, -1
            pos += 1
        if pos >= stop:
            return starts, lengths, -1
        starts[count], lengths[count] = first, pos - first
        count += 1
        pos = _skip_space(buf, pos + 1, stop)
        if pos >= stop or buf[pos] != 58:  # ':'
            return starts, lengths, -1
        pos = _skip_space(buf, pos + 1, stop)
        pos = _value_end(buf, pos, stop)
        if pos < 0:
            return starts, lengths, -1
        pos = _skip_space(buf, pos, stop)
        if pos < stop and buf[pos] == 44:  # ','
            pos = _skip_space(buf, pos + 1, stop)
            continue
        if pos < stop and buf[pos] == 125 and _skip_space(buf, pos + 1, stop) == stop:
            return starts, lengths, count
        return starts, lengths, -1


@njit(cache=True, nogil=True)
def _value_end(buf, pos, stop):
    """End of the number or null at ``pos`` (its characters only, not its syntax); -1 if there is none."""
    first = pos
    if pos + 4 <= stop and buf[pos] == 110 and buf[pos + 1] == 117 and buf[pos + 2] == 108 and buf[pos + 3] == 108:
        return pos + 4
    while pos < stop and (_is_digit(buf[pos]) or buf[pos] == 45 or buf[pos] == 43 or buf[pos] == 46
                          or buf[pos] == 101 or buf[pos] == 69):
        pos += 1
    return pos if pos > first else -1


@njit(cache=True, nogil=True)
def _objects(buf, offsets, lengths, key_bytes, key_ends, out, slow):
    """Parse message ``row`` into ``out[:, row]``; numbers to convert slowly go to ``slow`` (row, key, start, end).

    Returns
    -------
    slow_count : int
        Numbers recorded in ``slow``; -1 if a message is not an object of the template's keys, in order, with
        number or null values, or if there are more slow numbers than rows of ``slow``.
    """
    n_keys = key_ends.shape[0]
    buf = _borrow(buf)  # passed to _number once per number: no reference counting
    slow_count = 0
    for row in range(offsets.shape[0]):
        start = offsets[row]
        stop = start + lengths[row]
        pos = _skip_space(buf, start, stop)
        if pos >= stop or buf[pos] != 123:
            return -1
        for key in range(n_keys):
            pos = _skip_space(buf, pos + 1, stop)
            first = 0 if key == 0 else key_ends[key - 1]
            size = key_ends[key] - first
            if pos + size + 2 > stop or buf[pos] != 34 or buf[pos + size + 1] != 34:
                return -1
            k = 0
            while k + 8 <= size:  # eight bytes at a time
                if read_u64(buf, pos + 1 + k) != read_u64(key_bytes, first + k):
                    return -1
                k += 8
            while k < size:
                if buf[pos + 1 + k] != key_bytes[first + k]:
                    return -1
                k += 1
            pos = _skip_space(buf, pos + size + 2, stop)
            if pos >= stop or buf[pos] != 58:
                return -1
            pos = _skip_space(buf, pos + 1, stop)
            if pos >= stop:
                return -1
            if buf[pos] == 110:  # null
                if pos + 4 > stop or buf[pos + 1] != 117 or buf[pos + 2] != 108 or buf[pos + 3] != 108:
                    return -1
                out[key, row] = np.nan
                pos += 4
            else:
                value, end, status = _number(buf, pos, stop)
                if status == _INVALID:
                    return -1
                if status == _SLOW:
                    if slow_count == slow.shape[0]:
                        return -1
                    slow[slow_count, 0], slow[slow_count, 1] = row, key
                    slow[slow_count, 2], slow[slow_count, 3] = pos, end
                    slow_count += 1
                out[key, row] = value
                pos = end
            pos = _skip_space(buf, pos, stop)
            if pos >= stop or buf[pos] != (125 if key == n_keys - 1 else 44):  # '}' after the last, ',' before
                return -1
        if _skip_space(buf, pos + 1, stop) != stop:
            return -1
    return slow_count


def parse_flat_objects(buf: np.ndarray, offsets: np.ndarray, lengths: np.ndarray, *,
                       threads: int | None = None) -> dict[str, np.ndarray] | None:
    """Read messages that are flat JSON objects of numbers, the same keys in the same order, into columns.

    Parameters
    ----------
    buf : ndarray of uint8
        Bytes holding the messages.
    offsets, lengths : ndarray of int64
        Where each message's JSON text starts in ``buf``, and its length [bytes].
    threads : int, optional
        Threads sharing the messages (in contiguous parts of at least :data:`MIN_MESSAGES_PER_THREAD`);
        default :func:`numba.get_num_threads`.

    Returns
    -------
    dict of str to ndarray of float64, or None
        One column per key, in the messages' order (``null`` read as NaN); None when a message is not such an
        object (then parse the batch with a general JSON reader).
    """
    if not offsets.size:
        return None
    offsets = np.ascontiguousarray(offsets, np.int64)
    lengths = np.ascontiguousarray(lengths, np.int64)
    starts, sizes, count = _keys(buf, offsets[0], offsets[0] + lengths[0], MAX_KEYS)
    if count <= 0:
        return None
    spans = list(zip(starts[:count].tolist(), sizes[:count].tolist()))
    try:
        names = [bytes(buf[start:start + size]).decode("utf-8") for start, size in spans]
    except UnicodeDecodeError:
        return None
    if len(set(names)) != count:
        return None
    key_bytes = np.concatenate([buf[start:start + size] for start, size in spans])
    key_ends = np.cumsum(sizes[:count])
    out = np.empty((count, offsets.size), np.float64)
    threads = numba.get_num_threads() if threads is None else threads
    parts = max(1, min(threads, offsets.size // MIN_MESSAGES_PER_THREAD))
    bounds = np.linspace(0, offsets.size, parts + 1).astype(np.int64)
    slow = np.empty((parts, MAX_SLOW_NUMBERS // parts, 4), np.int64)

    def part(k: int) -> int:
        rows = slice(bounds[k], bounds[k + 1])
        return _objects(buf, offsets[rows], lengths[rows], key_bytes, key_ends, out[:, rows], slow[k])

    others = [shared_pool(parts - 1).submit(part, k) for k in range(1, parts)] if parts > 1 else []
    slow_counts = [part(0)] + [other.result() for other in others]  # the first part on this thread
    if min(slow_counts) < 0:
        return None
    for k, slow_count in enumerate(slow_counts):
        for row, key, start, end in slow[k, :slow_count].tolist():
            out[key, bounds[k] + row] = float(bytes(buf[start:end]))
    return dict(zip(names, out))
