"""Value types of the command-line options: every number is checked against its range where it is parsed.

Each option that takes a number uses one of the :class:`NumberRange` values of this module as its
argparse ``type``, so that a value out of range ends the command before any work with argparse's
error, one line naming the option, the allowed range and the value given, exit status 2::

    greybox train: error: argument --time-tolerance: must be a fraction in (0, 1), got 6

rather than in a ``ValueError`` deep in the library. ``tests/cli/test_types.py`` finds every
option of every sub-command and fails for one whose type is not a :class:`NumberRange`.
"""

from __future__ import annotations

import argparse
import math

__all__ = [
    "NumberRange",
    "FINITE",
    "POSITIVE",
    "NON_NEGATIVE",
    "FRACTION",
    "POSITIVE_INT",
    "NON_NEGATIVE_INT",
    "SEED",
    "MAX_SEED",
    "WordOrNumber",
    "NumberSpan",
    "NumberList",
    "positive",
    "non_negative",
]

#: Largest seed: the seeds reach numpy's legacy ``RandomState`` (through scikit-optimize), which takes 32 bits.
MAX_SEED = 2**32 - 1


class NumberRange:
    """An argparse ``type``: a finite int or float within an interval, or an error that names the interval.

    Parameters
    ----------
    kind : {float, int}
        Type of the value. An integer option refuses ``1.5`` and ``1e3``.
    low, high : float or int, optional
        Bounds of the interval; None for none (but every value must be finite).
    low_open, high_open : bool, default False
        Whether the bound itself is excluded.
    description : str, optional
        The range in words, e.g. ``"a fraction in (0, 1)"``; default built from the bounds.
    unit : str, optional
        Unit in words appended to the description, e.g. ``"seconds"`` gives
        ``"a positive number of seconds"``.

    Examples
    --------
    >>> POSITIVE("0.5")
    0.5
    >>> FRACTION("6")
    Traceback (most recent call last):
    ...
    argparse.ArgumentTypeError: must be a fraction in (0, 1), got 6
    """

    def __init__(self, kind=float, *, low=None, high=None, low_open: bool = False, high_open: bool = False,
                 description: str | None = None, unit: str | None = None):
        if kind not in (int, float):
            raise TypeError(f"kind must be int or float, got {kind!r}")
        self.kind = kind
        self.low, self.high = low, high
        self.low_open, self.high_open = low_open, high_open
        text = description or self._describe()
        self.description = f"{text} of {unit}" if unit else text
        # argparse names the type in its message for a ValueError; ours raise ArgumentTypeError instead
        self.__name__ = self.description

    def _describe(self) -> str:
        noun = "integer" if self.kind is int else "number"
        low, high = self.low, self.high
        if high is None and low == 0:
            return f"a {'positive' if self.low_open else 'non-negative'} {noun}"
        if high is None and low == 1 and self.kind is int and not self.low_open:
            return f"a positive {noun}"
        if low is None and high is None:
            return f"a finite {noun}"
        if high is None:
            return f"a {noun} {'>' if self.low_open else '>='} {low:g}"
        if low is None:
            return f"a {noun} {'<' if self.high_open else '<='} {high:g}"
        if self.kind is int and not (self.low_open or self.high_open):
            return f"an integer from {low} to {high}"
        return f"a {noun} in {'(' if self.low_open else '['}{low:g}, {high:g}{')' if self.high_open else ']'}"

    def contains(self, value) -> bool:
        """Whether ``value`` lies in the range (and is finite).

        Parameters
        ----------
        value : int or float
            Number to test against the bounds.
        """
        if not math.isfinite(value):
            return False
        if self.low is not None and (value <= self.low if self.low_open else value < self.low):
            return False
        if self.high is not None and (value >= self.high if self.high_open else value > self.high):
            return False
        return True

    def __call__(self, text: str):
        """Parse ``text``; raise :class:`argparse.ArgumentTypeError` unless it is a number in the range."""
        stripped = str(text).strip()
        try:
            value = int(stripped, 10) if self.kind is int else float(stripped)
        except ValueError:
            value = None
        if value is None or not self.contains(value):
            raise argparse.ArgumentTypeError(f"must be {self.description}, got {text}")
        return value

    def outside(self) -> list[str]:
        """Texts this type refuses: values just beyond each bound, non-finite values, not a number."""
        bad = ["nan", "inf", "-inf", "ten"]
        step = 1 if self.kind is int else 0.5
        if self.low is not None:
            bad.append(f"{self.low if self.low_open else self.low - step:g}")
        if self.high is not None:
            bad.append(f"{self.high if self.high_open else self.high + step:g}")
        if self.kind is int:
            bad.append("1.5")
        return bad

    def __repr__(self) -> str:
        return f"NumberRange({self.description!r})"


#: Any finite number (a position, a signed strength).
FINITE = NumberRange(float)
#: A number > 0.
POSITIVE = NumberRange(float, low=0, low_open=True)
#: A number >= 0.
NON_NEGATIVE = NumberRange(float, low=0)
#: A number in (0, 1), both bounds excluded.
FRACTION = NumberRange(float, low=0, high=1, low_open=True, high_open=True, description="a fraction in (0, 1)")
#: A number in [-1, 1], both bounds included (a relative force of either sign).
SIGNED_FRACTION = NumberRange(float, low=-1, high=1, description="a number in [-1, 1]")
#: A number of time steps above 1 (--max-gap).
GAP_STEPS = NumberRange(float, low=1, low_open=True, description="a number of steps above 1")
#: An integer >= 1.
POSITIVE_INT = NumberRange(int, low=1)
#: An integer >= 0.
NON_NEGATIVE_INT = NumberRange(int, low=0)
#: A seed of the random-number generators: an integer from 0 to 2**32 - 1.
SEED = NumberRange(int, low=0, high=MAX_SEED)


def positive(unit: str) -> NumberRange:
    """A number > 0 of ``unit`` (e.g. ``"seconds"``), named so in the message.

    Parameters
    ----------
    unit : str
        Unit in words, appended to the range's description.
    """
    return NumberRange(float, low=0, low_open=True, unit=unit)


def non_negative(unit: str) -> NumberRange:
    """A number >= 0 of ``unit`` (e.g. ``"seconds"``), named so in the message.

    Parameters
    ----------
    unit : str
        Unit in words, appended to the range's description.
    """
    return NumberRange(float, low=0, unit=unit)


class WordOrNumber:
    """An argparse ``type``: one of some words, or a number of a :class:`NumberRange`.

    The text is returned as given (stripped), so that the command reads the word or the number itself;
    only a value that is neither is refused, in one line naming both.

    Parameters
    ----------
    words : sequence of str
        Words accepted (case-insensitive), e.g. ``("plant", "model")``.
    number : NumberRange
        Range of the numbers accepted.
    """

    def __init__(self, words, number: NumberRange):
        self.words = tuple(words)
        self.number = number
        self.description = f"{', '.join(self.words)} or {number.description}"
        self.__name__ = self.description

    def __call__(self, text: str) -> str:
        """Return ``text`` stripped if it is one of the words or a number in range; else raise ArgumentTypeError."""
        stripped = str(text).strip()
        if stripped.lower() in self.words:
            return stripped
        try:
            self.number(stripped)
        except argparse.ArgumentTypeError:
            raise argparse.ArgumentTypeError(f"must be {self.description}, got {text}") from None
        return stripped

    def outside(self) -> list[str]:
        """Texts this type refuses: the number range's, and a word that is none of the words."""
        return self.number.outside() + ["none-of-these"]

    def __repr__(self) -> str:
        return f"WordOrNumber({self.description!r})"


class NumberSpan:
    """An argparse ``type``: ``LOW:HIGH``, two numbers of a :class:`NumberRange` with LOW < HIGH.

    Parameters
    ----------
    number : NumberRange
        Range of each end, e.g. :data:`FINITE` for positions, :data:`POSITIVE` for feeds.
    """

    def __init__(self, number: NumberRange):
        self.number = number
        self.description = f"LOW:HIGH, LOW < HIGH, each {number.description}"
        self.__name__ = self.description

    def __call__(self, text: str) -> tuple[float, float]:
        """Return ``(low, high)``; raise :class:`argparse.ArgumentTypeError` for anything else."""
        parts = str(text).strip().split(":")
        try:
            low, high = (self.number(part) for part in parts)
        except (ValueError, argparse.ArgumentTypeError):
            raise argparse.ArgumentTypeError(f"must be {self.description}, got {text}") from None
        if not low < high:
            raise argparse.ArgumentTypeError(f"must be {self.description}, got {text}")
        return float(low), float(high)

    def outside(self) -> list[str]:
        """Texts this type refuses: ends out of range, a reversed or empty span, not two numbers."""
        return [f"{value}:{value}" for value in self.number.outside()] + ["5:1", "1:1", "3", "1:2:3"]

    def __repr__(self) -> str:
        return f"NumberSpan({self.description!r})"


class NumberList:
    """An argparse ``type``: one or more numbers of a :class:`NumberRange`, separated by commas.

    Parameters
    ----------
    number : NumberRange
        Range of every number.
    """

    def __init__(self, number: NumberRange):
        self.number = number
        self.description = f"numbers separated by commas, each {number.description}"
        self.__name__ = self.description

    def __call__(self, text: str) -> tuple[float, ...]:
        """Return the numbers; raise :class:`argparse.ArgumentTypeError` for anything else."""
        try:
            return tuple(float(self.number(part)) for part in str(text).split(","))
        except argparse.ArgumentTypeError:
            raise argparse.ArgumentTypeError(f"must be {self.description}, got {text}") from None

    def outside(self) -> list[str]:
        """Texts this type refuses: a number out of range among good ones, an empty entry."""
        return [f"600,{value}" for value in self.number.outside()] + ["600,,1800"]

    def __repr__(self) -> str:
        return f"NumberList({self.description!r})"
