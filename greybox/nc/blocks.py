"""The blocks of a one-axis NC program: moves at a feed, rapid moves and dwells.

This module imports nothing else of greybox.
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["AXIS_LETTERS", "Move", "Dwell", "Program"]

#: NC address letters of the axes and their kind: X, Y, Z move in mm, A, B, C turn in deg.
AXIS_LETTERS = {"X": "linear", "Y": "linear", "Z": "linear", "A": "rotary", "B": "rotary", "C": "rotary"}


@dataclass(frozen=True)
class Move:
    """A straight move of the axis to a position.

    Parameters
    ----------
    target : float
        Position at the end of the move [mm, or deg for a rotary axis].
    feed : float or None
        Feed [mm/min or deg/min]; None for a rapid move (G0: the machine's rapid feed).
    line : int, default 0
        Line of the program text (1-based; 0 for a block not read from text).
    """

    target: float
    feed: float | None
    line: int = 0


@dataclass(frozen=True)
class Dwell:
    """A dwell: the axis rests.

    Parameters
    ----------
    seconds : float
        Length of the dwell [s].
    line : int, default 0
        Line of the program text.
    """

    seconds: float
    line: int = 0


@dataclass(frozen=True)
class Program:
    """A one-axis NC program: where the axis starts and the blocks it runs.

    Parameters
    ----------
    axis : str
        Address letter of the axis (a key of :data:`AXIS_LETTERS`).
    blocks : tuple of Move or Dwell
        The blocks in order; the first is a move to the start position.
    sections : tuple of (int, str)
        ``(index of the first block, title)`` of each section (warm-up, dataset A, ...).
    source : str, default ""
        File the program was read from.
    """

    axis: str
    blocks: tuple
    sections: tuple = field(default_factory=tuple)
    source: str = ""

    @property
    def motion(self) -> str:
        """``"linear"`` (mm) or ``"rotary"`` (deg), from the axis letter."""
        return AXIS_LETTERS[self.axis]

    @property
    def positions(self) -> list[float]:
        """Targets of every move, in order."""
        return [block.target for block in self.blocks if isinstance(block, Move)]
