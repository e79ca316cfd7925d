"""ISO G-code of one-axis air-cut programs: written as SINUMERIK and most controls accept it, and read back.

Written (``dialect="sinumerik"``)::

    ; comment
    N10 G90 G94 G64       ; absolute positions, feed per minute, continuous path
    N20 G0 X-250.0        ; rapid move
    N30 G1 X-275.0 F600   ; straight move at 600 mm/min (deg/min for a rotary axis)
    N40 G4 F0.5           ; dwell 0.5 s
    N50 M30

``dialect="fanuc"`` writes the dwell ``G04 X0.5``, comments in parentheses, every number with a decimal
point (``X-250.``: without calculator-type input a Fanuc reads ``X-250`` as -0.25 mm) and the program
between ``%`` lines with a number ``O1000``. A rotary axis's program turns by increments (``G91``) after
its first, absolute move, so that a modulo table (0..360 deg) turns the programmed angle, say from -180
to 180 deg, instead of standing still at the same angle.

Read: blocks of address letters and numbers, optional ``N`` numbers, comments after ``;`` or in
``( )``, ``G0``/``G00`` (rapid), ``G1``/``G01`` (feed move, ``F`` modal), ``G90``/``G91``
(absolute, incremental), ``G4``/``G04`` dwell with ``F`` or ``X`` in s or ``P`` in ms (its ``F``
does not change the feed), ``G94``, ``G21``/``G71`` (metric), ``G17``/``G18``/``G19``, ``G60``,
``G64``, ``G9`` (path modes: the twin stops at every reversal and dwell anyway), ``M30``/``M2``/``M17``
(end; later blocks are ignored), ``M0``/``M1``. Anything else (another axis, inch units, feed per
revolution, a spindle word) is an error naming the line: the program is meant for one axis moving
without cutting.
"""

from __future__ import annotations

import os
import re

from ..errors import GreyboxError
from .blocks import AXIS_LETTERS, Dwell, Move, Program

__all__ = ["DIALECTS", "write_program", "parse_program", "read_program"]

#: Dialects the writer knows: how a dwell and a comment are written.
DIALECTS = ("sinumerik", "fanuc")

_WORD = re.compile(r"([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")
_ACCEPTED_G = {0, 1, 4, 9, 17, 18, 19, 21, 60, 64, 71, 90, 91, 94}
_REFUSED_G = {20: "inch units (G20)", 70: "inch units (G70)", 95: "feed per revolution (G95)"}
_END_M = {2, 17, 30}


def _number(value: float, point: bool = False) -> str:
    """Shortest text of ``value`` at 4 decimals; with ``point`` always with a decimal point (``-250.``)."""
    text = f"{value:.4f}".rstrip("0").rstrip(".")
    text = "0" if text in ("-0", "") else text
    return text + "." if point and "." not in text else text


def write_program(program: Program, *, dialect: str = "sinumerik", header=()) -> str:
    """The program as ISO G-code text.

    Parameters
    ----------
    program : Program
        Blocks to write; positions with 4 decimals (0.1 um, 0.0001 deg), feeds and dwells likewise.
    dialect : {"sinumerik", "fanuc"}, default "sinumerik"
        Dwell as ``G4 F<s>`` and comments after ``;`` (SINUMERIK), or ``G04 X<s>`` and comments
        in parentheses (Fanuc and most ISO controls).
    header : iterable of str
        Comment lines written first.

    Returns
    -------
    str
        The program, one block per line, numbered N10, N20, ...
    """
    if dialect not in DIALECTS:
        raise GreyboxError(f"unknown G-code dialect {dialect!r}; choose {' or '.join(DIALECTS)}")

    def comment(text: str) -> str:
        return f"; {text}" if dialect == "sinumerik" else f"({text.replace('(', '[').replace(')', ']')})"

    fanuc = dialect == "fanuc"
    lines = ["%", "O1000 (GREYBOX AIR CUT)"] if fanuc else []  # Fanuc: tape start and a program number
    lines += [comment(text) for text in header]
    number = 0

    def block(text: str, note: str = "") -> None:
        nonlocal number
        number += 10
        lines.append(f"N{number} {text}" + (f" {comment(note)}" if note else ""))

    def number_text(value: float) -> str:  # Fanuc reads "250" as 0.250 mm without calculator-type input
        return _number(value, point=fanuc)

    unit = "mm" if program.motion == "linear" else "deg"
    block("G90 G94 G64", f"absolute positions, feed in {unit}/min, continuous path")
    titles = dict(program.sections)
    feed = None
    position = None
    rotary = program.motion == "rotary"
    for index, item in enumerate(program.blocks):
        if index in titles:
            lines.append(comment(titles[index]))
        if isinstance(item, Dwell):
            block(f"G4 F{number_text(item.seconds)}" if not fanuc else f"G04 X{number_text(item.seconds)}")
            continue
        if rotary and position is not None:  # incremental: a modulo table turns by the angle programmed
            target = round(item.target, 4) - round(position, 4)
        else:
            target = item.target
        if item.feed is None:
            block(f"G0 {program.axis}{number_text(target)}")
        else:
            words = f"G1 {program.axis}{number_text(target)}"
            if item.feed != feed:
                words += f" F{number_text(item.feed)}"
                feed = item.feed
            block(words)
        if rotary and position is None:
            block("G91", "incremental from here: the table turns by each angle, also on a modulo axis")
        position = item.target
    block("M30")
    if fanuc:
        lines.append("%")
    return "\n".join(lines) + "\n"


def _strip_comments(line: str) -> str:
    line = re.sub(r"\([^)]*\)", " ", line)
    return line.split(";", 1)[0]


def parse_program(text: str, *, source: str = "") -> Program:
    """Read the blocks of a one-axis G-code program.

    Parameters
    ----------
    text : str
        Program text (see the module docstring for what is understood).
    source : str, default ""
        File name for error messages.

    Returns
    -------
    Program
        Its axis is the one axis the program moves; rapid moves carry ``feed=None``.

    Raises
    ------
    GreyboxError
        For a word the twin does not run, a move before any feed, two axes, a dwell without its
        time, or a program without moves; the message names the file and line.
    """
    where = source or "<program>"
    axis = None
    absolute = True
    feed = None
    motion = None  # 0 rapid, 1 feed move: modal
    position = None
    blocks = []
    for number, raw in enumerate(text.splitlines(), 1):
        line = _strip_comments(raw).strip().upper()
        if not line or line.startswith("/") or line.startswith("%"):
            continue
        rest = _WORD.sub(" ", line).strip()
        if rest:
            raise GreyboxError(f"{where}: line {number}: cannot read {rest.split()[0]!r} in {raw.strip()!r}")
        words = [(letter, float(value)) for letter, value in _WORD.findall(line)]
        codes = {int(value) for letter, value in words if letter == "G"}
        for letter, value in words:
            if letter == "G" and (value != int(value) or int(value) not in _ACCEPTED_G):
                reason = _REFUSED_G.get(int(value), "not a code the twin runs")
                raise GreyboxError(f"{where}: line {number}: G{_number(value)}: {reason} (it runs G0, G1, G4, G90, "
                                   "G91, G94, G21/G71, G9/G60/G64)")
        if 90 in codes and 91 in codes:
            raise GreyboxError(f"{where}: line {number}: G90 and G91 in one block")
        absolute = False if 91 in codes else True if 90 in codes else absolute
        if {0, 1} <= codes:
            raise GreyboxError(f"{where}: line {number}: G0 and G1 in one block")
        motion = 0 if 0 in codes else 1 if 1 in codes else motion
        if any(letter == "M" for letter, _ in words):
            codes_m = {int(value) for letter, value in words if letter == "M"}
            if codes_m & _END_M:
                break
            if codes_m - {0, 1}:
                raise GreyboxError(f"{where}: line {number}: M{min(codes_m - {0, 1})}: the twin runs M0, M1 and "
                                   "ends at M30, M2 or M17")
        if 4 in codes:
            times = {letter: value for letter, value in words if letter in "FXP"}
            if len(times) != 1:
                raise GreyboxError(f"{where}: line {number}: a dwell G4 needs its time as F or X (s) or P (ms)")
            (letter, value), = times.items()
            seconds = value / 1000.0 if letter == "P" else value
            if not seconds >= 0:
                raise GreyboxError(f"{where}: line {number}: dwell of {seconds:g} s")
            blocks.append(Dwell(seconds, number))
            continue
        for letter, value in words:
            if letter in "GMNO":  # O: the program number
                continue
            if letter == "F":
                if not value > 0:
                    raise GreyboxError(f"{where}: line {number}: feed F{_number(value)} must be positive")
                feed = value
            elif letter in AXIS_LETTERS:
                if axis is not None and letter != axis:
                    raise GreyboxError(f"{where}: line {number}: moves {letter} after {axis}; the program must move "
                                       "one axis only")
                axis = letter
            else:
                raise GreyboxError(f"{where}: line {number}: word {letter}{_number(value)} is not run by the twin "
                                   "(a one-axis air cut: G, F, the axis, N, M)")
        targets = [value for letter, value in words if letter == axis]
        if not targets:
            continue
        target = targets[0] if absolute or position is None else position + targets[0]
        if not absolute and position is None:
            raise GreyboxError(f"{where}: line {number}: an incremental move (G91) before any absolute position")
        if motion is None:
            raise GreyboxError(f"{where}: line {number}: a move before any G0 or G1")
        rapid = motion == 0
        if not rapid and feed is None:
            raise GreyboxError(f"{where}: line {number}: a feed move without a feed; give F (mm/min or deg/min)")
        blocks.append(Move(target, None if rapid else feed, number))
        position = target
    if axis is None or not any(isinstance(block, Move) for block in blocks):
        raise GreyboxError(f"{where}: no move of an axis ({', '.join(AXIS_LETTERS)})")
    return Program(axis=axis, blocks=tuple(blocks), source=source)


def read_program(path) -> Program:
    """Read a G-code program file (``.mpf``, ``.nc``, ``.gcode``, any text).

    Parameters
    ----------
    path : str or path-like
        Program file, UTF-8 or Latin-1 text.

    Raises
    ------
    GreyboxError
        For a missing or unreadable file, text that is not UTF-8 or Latin-1, or a program
        :func:`parse_program` refuses.
    """
    path = os.fspath(path)
    try:
        with open(path, "rb") as stream:
            data = stream.read()
    except FileNotFoundError:
        raise GreyboxError(f"{path}: no such NC program") from None
    except IsADirectoryError:
        raise GreyboxError(f"{path}: is a directory, not an NC program") from None
    except OSError as exc:
        raise GreyboxError(f"{path}: cannot read the NC program ({exc.strerror or exc})") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")  # controls' own editors write Latin-1
    if "\0" in text:
        raise GreyboxError(f"{path}: not a text file (an NC program is G-code text)")
    return parse_program(text, source=path)
