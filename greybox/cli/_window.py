"""The time-window option of the commands that draw logs (``plot --window``, ``predict --plot-window``)."""

from __future__ import annotations

import argparse

from ._types import FINITE

__all__ = ["add_window_argument"]


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

