"""The time-window option of the commands that draw logs (``plot --window``, ``predict --plot-window``)."""

from __future__ import annotations

import argparse
import math

from ..errors import GreyboxError
from ._types import FINITE

__all__ = ["add_window_argument", "check_window"]


def add_window_argument(parser: argparse.ArgumentParser, flag: str = "--window") -> None:
    """Add ``flag START END``: the time window [s] of a picture.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        Parser of the sub-command.
    flag : str, default "--window"
        Option name.
    """
    parser.add_argument(
        flag,
        nargs=2,
        type=FINITE,
        metavar=("START", "END"),
        help="draw only the samples from START to END seconds of log time (default: the whole log; a long log "
        "is drawn as its envelope, the minimum and maximum of each pixel column)",
    )


def check_window(window, time, flag: str = "--window", name: str = "the log") -> tuple[float, float] | None:
    """Return the window ``(start, end)`` [s], or None; refuse one that is empty, reversed or off the log.

    Parameters
    ----------
    window : sequence of two floats or None
        The option's value.
    time : ndarray
        The log's time [s].
    flag : str, default "--window"
        Option name, for the message.
    name : str
        The log, for the message.

    Raises
    ------
    GreyboxError
        If START or END is not finite, START >= END, or no sample lies in the window.
    """
    if window is None:
        return None
    start, end = (float(v) for v in window)
    text = f"{flag} {start:g} {end:g}"
    if not (math.isfinite(start) and math.isfinite(end)) or start >= end:
        raise GreyboxError(f"{text}: give START < END, both finite, in seconds of log time")
    first, last = float(time[0]), float(time[-1])
    if not ((time >= start) & (time <= end)).any():
        raise GreyboxError(f"{text}: no sample in the window; {name} runs from {first:g} to {last:g} s")
    return start, end
