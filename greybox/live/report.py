"""The lines a live stream says while it runs: each one bounded, and their rate too.

A message of several megabytes, or a publisher sending thousands of malformed messages a second, must not
turn the log into a flood. :class:`LineLimiter` cuts every line to ``max_chars`` characters and lets at most
``burst`` lines out per ``interval_s`` seconds; the lines held back are counted, and once the interval is
over one summary line says how many there were and repeats the last of them.
"""

from __future__ import annotations

import time
from typing import Callable

__all__ = ["MAX_LINE_CHARS", "LINES_PER_INTERVAL", "LINE_INTERVAL_S", "clip", "LineLimiter"]

#: Most characters of one line by default.
MAX_LINE_CHARS = 300

#: Lines let out per interval by default.
LINES_PER_INTERVAL = 20

#: The interval [s] of the line rate by default.
LINE_INTERVAL_S = 10.0


def clip(line: str, max_chars: int = MAX_LINE_CHARS) -> str:
    """``line`` cut to ``max_chars`` characters, saying how many were left out.

    Parameters
    ----------
    line : str
        The line.
    max_chars : int, default MAX_LINE_CHARS
        Most characters kept (the note on the cut comes on top).
    """
    line = line.replace("\n", " ").replace("\r", " ")
    if len(line) <= max_chars:
        return line
    return f"{line[:max_chars]}... ({len(line) - max_chars} more characters)"


class LineLimiter:
    """``say`` with each line cut short and the lines per interval bounded.

    Parameters
    ----------
    say : callable
        ``say(line)``: where the lines let out go.
    burst : int, default LINES_PER_INTERVAL
        Lines let out per interval.
    interval_s : float, default LINE_INTERVAL_S
        The interval [s].
    max_chars : int, default MAX_LINE_CHARS
        Most characters of a line.
    clock : callable, default time.monotonic
        The clock [s].

    Attributes
    ----------
    held_back : int
        Lines held back since the start.
    """

    def __init__(self, say: Callable[[str], None], *, burst: int = LINES_PER_INTERVAL,
                 interval_s: float = LINE_INTERVAL_S, max_chars: int = MAX_LINE_CHARS,
                 clock: Callable[[], float] = time.monotonic):
        if burst < 1 or not interval_s > 0 or max_chars < 1:
            raise ValueError(f"burst and max_chars must be positive, interval_s above 0: got {burst!r}, "
                             f"{max_chars!r}, {interval_s!r}")
        self.say = say
        self.burst = int(burst)
        self.interval_s = float(interval_s)
        self.max_chars = int(max_chars)
        self.clock = clock
        self.held_back = 0
        self._start = clock()
        self._said = 0
        self._held = 0
        self._last_held = ""

    def __call__(self, line: str) -> None:
        """Say one line (cut short), unless the interval's lines are used up.

        Parameters
        ----------
        line : str
            The line.
        """
        self.tick()
        if self._said < self.burst:
            self._said += 1
            self.say(clip(line, self.max_chars))
        else:
            self._held += 1
            self.held_back += 1
            self._last_held = line

    def tick(self) -> None:
        """At the end of an interval: the summary of the lines held back in it, and a new interval."""
        now = self.clock()
        if now - self._start < self.interval_s:
            return
        if self._held:
            self.say(f"{self._held} more line(s) held back in the last {now - self._start:.0f} s; the last: "
                     f"{clip(self._last_held, self.max_chars)}")
        self._start, self._said, self._held, self._last_held = now, 0, 0, ""

    def flush(self) -> None:
        """Say the summary of the lines held back so far (at the end of the stream)."""
        if self._held:
            self._start -= self.interval_s
            self.tick()
