"""Consecutive blocks of one axis log: joined, and cut to a given length."""

from __future__ import annotations

from typing import Iterable, Iterator

import numpy as np

from .log import AxisLog

__all__ = ["CannotStream", "concatenate", "reblock"]


class CannotStream(Exception):
    """A log that cannot be read block by block (e.g. MCAP messages stored out of time order): read it whole."""


def concatenate(blocks: Iterable[AxisLog]) -> AxisLog:
    """One log of consecutive blocks of the same log (channels joined; names and attrs of the first).

    Parameters
    ----------
    blocks : iterable of AxisLog
        Consecutive blocks of one log, in time order, all with the same channels.

    Raises
    ------
    ValueError
        For no block at all.
    """
    blocks = list(blocks)
    if not blocks:
        raise ValueError("no block to join")
    if len(blocks) == 1:
        return blocks[0]
    first = blocks[0]

    def joined(name):
        values = [getattr(block, name) for block in blocks]
        return None if values[0] is None else np.concatenate(values)

    return first.replace(time=joined("time"), position=joined("position"), effort=joined("effort"),
                         velocity=joined("velocity"), acceleration=joined("acceleration"),
                         extras={name: np.concatenate([block.extras[name] for block in blocks])
                                 for name in first.extras})


def reblock(pieces: Iterable[AxisLog], size: int) -> Iterator[AxisLog]:
    """Consecutive pieces of a log as blocks of ``size`` samples; the last may be shorter.

    A last piece of a single sample joins the block before it, so that every block holds a time step.

    Parameters
    ----------
    pieces : iterable of AxisLog
        Consecutive pieces of one log, of any lengths.
    size : int
        Samples per block, at least 1.
    """
    pending: list[AxisLog] = []
    held = 0
    ready = None  # a full block held back: a last piece of one sample joins it
    for piece in pieces:
        pending.append(piece)
        held += len(piece)
        while held >= size:
            whole = concatenate(pending)
            if ready is not None:
                yield ready
            ready = whole.select(slice(0, size))
            rest = whole.select(slice(size, None))
            pending, held = ([rest], len(rest)) if len(rest) else ([], 0)
    rest = concatenate(pending) if held else None
    if ready is not None and rest is not None and len(rest) < 2:
        ready, rest = concatenate([ready, rest]), None
    if ready is not None:
        yield ready
    if rest is not None:
        yield rest
