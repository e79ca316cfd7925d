"""Progress reports of a running identification.

An identification calls its progress callback after every cost evaluation
with a :class:`ProgressEvent`. :func:`make_progress` turns the ``progress``
argument of ``fit`` into such a callback: ``None``/``False`` gives ``None``
(silent), ``True`` a :class:`ProgressPrinter` on stderr, and a callable is
used as it is.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from typing import Callable, TextIO

__all__ = ["ProgressEvent", "ProgressPrinter", "make_progress"]


@dataclass(frozen=True)
class ProgressEvent:
    """State of an identification after one cost evaluation.

    Attributes
    ----------
    stage : str
        Name of the running stage, e.g. ``"GMS pre-sliding"``.
    start : int
        Index of the current start of a multi-start search (0-based).
    n_starts : int
        Number of starts of the stage.
    evaluation : int
        Cost evaluations so far in this start (1-based).
    cost : float
        Cost of the latest evaluation (normalised mean squared error, 1 = variance of the effort).
    best : float
        Lowest cost seen so far in the stage.
    done : bool
        True for the last event of a start.
    """

    stage: str
    start: int
    n_starts: int
    evaluation: int
    cost: float
    best: float
    done: bool = False


class ProgressPrinter:
    """Print progress lines (stage, start, evaluation, cost, best) to a stream.

    Parameters
    ----------
    stream : file-like, optional
        Where to write; stderr by default.
    interval : float, default 1.0
        Least time between two lines of the same start [s]; the last event of
        every start is always printed.
    """

    def __init__(self, stream: TextIO | None = None, interval: float = 1.0):
        self.stream = stream
        self.interval = interval
        self._last = float("-inf")

    def __call__(self, event: ProgressEvent) -> None:
        now = time.monotonic()
        if not event.done and now - self._last < self.interval:
            return
        self._last = now
        stream = self.stream if self.stream is not None else sys.stderr
        status = "done" if event.done else "running"
        print(f"{event.stage}: start {event.start + 1}/{event.n_starts} eval {event.evaluation:5d} "
              f"cost {event.cost:.6g} best {event.best:.6g} ({status})", file=stream, flush=True)


def make_progress(progress) -> Callable[[ProgressEvent], None] | None:
    """Return the progress callback for a ``progress`` argument.

    Parameters
    ----------
    progress : None, bool or callable
        ``None``/``False``: silent; ``True``: :class:`ProgressPrinter` on
        stderr; a callable taking a :class:`ProgressEvent` is returned as is.

    Raises
    ------
    TypeError
        For any other value.
    """
    if progress is None or progress is False:
        return None
    if progress is True:
        return ProgressPrinter()
    if callable(progress):
        return progress
    raise TypeError(f"progress must be None, a bool or a callable, got {type(progress).__name__}")
