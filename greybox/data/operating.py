"""The operating region of training runs: the motion they showed, whichever model is fitted on them.

A sample of a run lies inside the region when its position, velocity and acceleration lie within the
ranges of the training runs (the training record's ``ranges``) and its *motion* was seen in training: the
pair (speed ``|v|``, local span) falls in a cell of a grid that training samples occupied, or in a
neighbouring cell (:data:`NEIGHBOURS`). The local span is ``max - min`` of the position over the trailing window
:data:`SPAN_WINDOW_S` ending at the sample: a sweep has the span of its travel, a dwell none, and a small
oscillation a small span at a speed that in the training runs only came with a large one. The motion is
also outside when the position turned back more often within that window than the training runs ever did
at that span (:data:`REVERSALS_RULE`): a fast oscillation of a few tenths of a millimetre turns four times a
second, the slow sweeps of a harmonic test once in two seconds, also where their tapered starts are as
small. The region depends on the training runs alone, never on the model: every kind of model trained on
the same runs has the same region (docs/defaults.md, "What counts as inside the training region").

:func:`operating_record` builds the record the training record keeps as ``operating``;
:func:`check_operating_record` validates one read from a model file; :class:`OperatingRegion` flags the
samples of a run, chunk by chunk if need be (the trailing window carries over as its state).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["SPAN_WINDOW_S", "SPEED_DECADES", "SPAN_DECADES", "CELLS_PER_DECADE", "MIN_CELL_SAMPLES", "MIN_CELL_SHARE",
           "NEIGHBOURS", "REVERSALS_RULE",
           "OperatingRegion", "check_operating_record", "local_span", "most_reversals", "operating_record",
           "reversal_marks", "span_turns", "trailing_reversals"]

#: Trailing window of the local span [s]: long enough to hold a reversal of the slow sweeps of air cuts and
#: harmonic tests, short enough that a few small oscillations fill it.
SPAN_WINDOW_S = 0.5

#: Speed cells: ``|v|`` from ``10**-SPEED_DECADES`` of the largest training speed up to it; span cells:
#: from ``10**-SPAN_DECADES`` of the width of the training positions up to that width; both geometric, in
#: :data:`CELLS_PER_DECADE` cells a decade (values below the first edge share the first cell) [-].
SPEED_DECADES = 3
SPAN_DECADES = 4

#: Cells a decade of the grid [-]. This, :data:`MIN_CELL_SHARE` and :data:`NEIGHBOURS` are chosen on the
#: development air cuts by one rule (:func:`studies.operating_region.grid_rule`, docs/defaults.md): of 4, 8
#: or 16 cells a decade, a share of 0, 0.1 or 0.5 %, 0 or 1 neighbours, the setting that flags by motion the
#: most of the air cuts of another kind (twin X_B, Y_B from X_A, Y_A; axis_dev aircut_B from aircut_A)
#: while each held-out air cut of the same kind (X_C, Y_C, aircut_C) has at most 1 % flagged; ties go to
#: the coarser grid.
CELLS_PER_DECADE = 4

#: A cell counts as seen in training when at least this many training samples fall in it [-]: a stray
#: sample (a glitch, one step at a reversal) does not make a regime.
MIN_CELL_SAMPLES = 5

#: ... and at least this share of the training samples [-]: the settling of a run's first moments does not
#: make a regime either. Chosen with :data:`CELLS_PER_DECADE` and :data:`NEIGHBOURS` by the rule there.
MIN_CELL_SHARE = 0.0

#: A sample in a cell this many cells (in each direction of the grid) from a seen cell counts as inside [-]
#: (chosen by the rule of :data:`CELLS_PER_DECADE`).
NEIGHBOURS = 0

#: The rule of the reversals, in words (docs/defaults.md): within the trailing window of the local span, the
#: position may turn back at most as many times as the training runs did at the same span cell (the most
#: that at least :data:`MIN_CELL_SAMPLES` training samples of the cell reached). A reversal is a turn back by
#: the smallest span the grid resolves (the first span edge): finer turns are below the grid's resolution
#: (and in the noise of the position). The window is the span's own: of 0.5, 1 and 2 s, the one rule of
#: :data:`CELLS_PER_DECADE` (:func:`studies.operating_region.reversal_rule`) keeps only 0.5 s.
REVERSALS_RULE = "at most the training's reversals within the span window at that span cell"

#: The keys of an ``operating`` record; files of format version 5 on add :data:`_REVERSAL_KEY`.
_KEYS = {"window_s", "speed_edges", "span_edges", "cells"}
#: Per span cell, the most reversals within the window the training runs showed (-1: a cell they did not
#: show).
_REVERSAL_KEY = "reversals"
#: Most reversals a record may hold for a cell (a model file is never trusted).
_MAX_REVERSALS = 1 << 30

#: Most edges of one axis of the grid a record may hold (a model file is never trusted).
_MAX_EDGES = 257


def _window_samples(window_s: float, sample_time: float) -> int:
    """Samples of the trailing window at ``sample_time`` [s] (at least one)."""
    return max(int(round(window_s / sample_time)), 1)


def local_span(position: np.ndarray, samples: int, history: tuple | None = None) -> tuple[np.ndarray, tuple]:
    """``max - min`` of the position over the trailing window of ``samples`` samples ending at each sample.

    A running maximum and minimum whose queues carry over from chunk to chunk, so a chunk costs O(1)
    amortised a sample whatever the window (a live stream's message is not scanned together with the
    window before it).

    Parameters
    ----------
    position : ndarray, shape (n,)
        Position of consecutive samples [mm or deg].
    samples : int
        Window length [samples], at least 1.
    history : tuple, optional
        The window state a previous chunk left (its ``history``); none at the start of a run, where the
        window holds what the run has shown so far. It is updated in place and returned (a chunk consumes
        the state it is given).

    Returns
    -------
    span : ndarray, shape (n,)
        Local span [mm or deg].
    history : tuple of (ndarray, ndarray of int64, ndarray of int64)
        The window's positions in a ring (shape ``(samples,)``), the two monotone queues of sample
        indices (shape ``(2, samples)``) and their counters (samples seen, heads and tails; shape ``(5,)``):
        the ``history`` of the next chunk.
    """
    if history is None:
        history = (np.zeros(samples), np.zeros((2, samples), dtype=np.int64), np.zeros(5, dtype=np.int64))
    ring, queues, counters = history
    if ring.size != samples:
        raise ValueError(f"the window state holds {ring.size} samples, not the window's {samples}")
    span = np.empty(np.size(position))
    _span_kernel(np.ascontiguousarray(position, dtype=np.float64), ring, queues, counters, span)
    return span, history


@njit(cache=True, error_model="numpy")
def _span_kernel(position, ring, queues, counters, out):  # pragma: no cover - compiled; reference in the tests
    """``out[k]`` = ``max - min`` of the trailing window of ``ring.size`` samples ending at ``position[k]``
    (fewer at the start of a run: what it has shown so far, :func:`local_span`).

    A running maximum and minimum: two monotone queues of sample indices (``queues[0]``, the maximum's,
    values decreasing; ``queues[1]``, the minimum's, increasing), rings of the window's length addressed by
    ever-growing counters ``counters`` = [samples seen, maximum's head, tail, minimum's head, tail]; the
    window's values in ``ring``. Each index is pushed and popped once: O(1) amortised a sample, and the same
    values as taking ``max - min`` of each window. All state is updated in place.
    """
    window = ring.size
    high, low = queues[0], queues[1]
    t, high_head, high_tail, low_head, low_tail = counters[0], counters[1], counters[2], counters[3], counters[4]
    for k in range(position.size):
        value = position[k]
        oldest = t - window + 1
        while high_tail > high_head and high[high_head % window] < oldest:
            high_head += 1
        while low_tail > low_head and low[low_head % window] < oldest:
            low_head += 1
        ring[t % window] = value
        while high_tail > high_head and ring[high[(high_tail - 1) % window] % window] <= value:
            high_tail -= 1
        high[high_tail % window] = t
        high_tail += 1
        while low_tail > low_head and ring[low[(low_tail - 1) % window] % window] >= value:
            low_tail -= 1
        low[low_tail % window] = t
        low_tail += 1
        out[k] = ring[high[high_head % window] % window] - ring[low[low_head % window] % window]
        t += 1
    counters[0], counters[1], counters[2], counters[3], counters[4] = t, high_head, high_tail, low_head, low_tail


def reversal_marks(position: np.ndarray, deadband: float, detector: np.ndarray | None = None) -> tuple[np.ndarray,
                                                                                                       np.ndarray]:
    """Where the position turns back by at least ``deadband``: True at the sample that confirms a reversal.

    The turn is measured from the running extreme of the current direction of motion (a play operator of
    width ``deadband``): a reversal counts once the position lies ``deadband`` behind the furthest point
    of the stroke, so a ripple or noise smaller than ``deadband`` makes none. The first motion of a run by
    ``deadband`` sets a direction without counting a reversal.

    Parameters
    ----------
    position : ndarray, shape (n,)
        Position of consecutive samples [mm or deg].
    deadband : float
        Least turn that counts [mm or deg], positive.
    detector : ndarray, shape (4,), optional
        The state a previous chunk left (direction, extreme, highest and lowest position before a direction
        was set); none at the start of a run.

    Returns
    -------
    marks : ndarray of bool, shape (n,)
        True where a reversal is confirmed.
    detector : ndarray, shape (4,)
        The state for the next chunk.
    """
    position = np.ascontiguousarray(position, dtype=np.float64)
    state = np.full(4, np.nan) if detector is None else np.array(detector, dtype=np.float64)
    marks = np.zeros(position.size, dtype=np.bool_)
    _reversal_kernel(position, float(deadband), state, marks)
    return marks, state


@njit(cache=True, error_model="numpy")
def _reversal_kernel(position, deadband, state, marks):  # pragma: no cover - compiled; reference in the tests
    """``marks[k]`` = a reversal by ``deadband`` is confirmed at ``position[k]`` (:func:`reversal_marks`);
    ``state`` = [direction (+1, -1, 0 none yet; NaN before the first sample), extreme, highest, lowest],
    updated in place. O(1) a sample."""
    direction, extreme, high, low = state[0], state[1], state[2], state[3]
    for k in range(position.size):
        x = position[k]
        if np.isnan(direction):
            direction, extreme, high, low = 0.0, x, x, x
        if direction == 0.0:
            high = max(high, x)
            low = min(low, x)
            if x - low >= deadband:
                direction, extreme = 1.0, x
            elif high - x >= deadband:
                direction, extreme = -1.0, x
        elif direction > 0.0:
            if x > extreme:
                extreme = x
            elif extreme - x >= deadband:
                marks[k] = True
                direction, extreme = -1.0, x
        else:
            if x < extreme:
                extreme = x
            elif x - extreme >= deadband:
                marks[k] = True
                direction, extreme = 1.0, x
    state[0], state[1], state[2], state[3] = direction, extreme, high, low


def trailing_reversals(marks: np.ndarray, samples: int, history: tuple | None = None) -> tuple[np.ndarray, tuple]:
    """Reversals within the trailing window of ``samples`` samples ending at each sample.

    A running count: each sample adds its mark and drops the one that leaves the window, kept in a ring of the
    window's marks that carries over from chunk to chunk, so a chunk costs O(1) a sample whatever the window
    (a live stream flags each message without looking back over the window).

    Parameters
    ----------
    marks : ndarray of bool, shape (n,)
        :func:`reversal_marks` of consecutive samples.
    samples : int
        Window length [samples], at least 1.
    history : tuple, optional
        The window state a previous chunk left (its ``history``): none at the start of a run. It is
        updated in place and returned (a chunk consumes the state it is given).

    Returns
    -------
    count : ndarray of int64, shape (n,)
        Reversals within each window [-].
    history : tuple of (ndarray of bool, shape (samples,), ndarray of int64, shape (2,))
        The marks of the window in a ring, and the ring's next slot with the window's count: the ``history``
        of the next chunk.
    """
    if history is None:
        ring, cursor = np.zeros(samples, dtype=np.bool_), np.zeros(2, dtype=np.int64)
    else:
        ring, cursor = history
        if ring.size != samples:
            raise ValueError(f"the window state holds {ring.size} samples, not the window's {samples}")
    count = np.empty(np.size(marks), dtype=np.int64)
    _window_count_kernel(np.ascontiguousarray(marks, dtype=np.bool_), ring, cursor, count)
    return count, (ring, cursor)


@njit(cache=True, error_model="numpy")
def _window_count_kernel(marks, ring, cursor, out):  # pragma: no cover - compiled; reference in the tests
    """``out[k]`` = marks within the trailing window of ``ring.size`` samples ending at ``marks[k]``
    (:func:`trailing_reversals`); ``ring`` holds the window's marks, ``cursor`` = [next slot of the ring,
    marks in the ring], both updated in place. O(1) a sample."""
    slot, total = cursor[0], cursor[1]
    for k in range(marks.size):
        total += np.int64(marks[k]) - np.int64(ring[slot])
        ring[slot] = marks[k]
        out[k] = total
        slot += 1
        if slot == ring.size:
            slot = 0
    cursor[0], cursor[1] = slot, total


@njit(cache=True, error_model="numpy")
def _unseen_kernel(speed, span, count, speed_inner, span_inner, seen, most, out):  # pragma: no cover - compiled
    """``out[k]`` = the grid cell of (``speed[k]``, ``span[k]``) is not ``seen`` (outer cells take what lies
    beyond the outer edges), or ``count[k]`` exceeds the ``most`` reversals of its span cell."""
    for k in range(speed.size):
        j = np.searchsorted(span_inner, span[k], side="right")
        out[k] = not seen[np.searchsorted(speed_inner, speed[k], side="right"), j] or count[k] > most[j]


def _inner(edges) -> np.ndarray:
    """The inner edges of one axis of the grid, as :func:`_cells` takes them."""
    return np.asarray(edges[1:-1], dtype=np.float64)


def _cells(speed: np.ndarray, span: np.ndarray, speed_inner: np.ndarray, span_inner: np.ndarray):
    """Grid indices (speed, span) of the samples; values beyond the outer edges go to the outer cells."""
    return np.searchsorted(speed_inner, speed, side="right"), np.searchsorted(span_inner, span, side="right")


def operating_record(runs, *, cells_per_decade: int = CELLS_PER_DECADE, min_share: float = MIN_CELL_SHARE) -> dict:
    """The ``operating`` record of a training record: the grid of the motion the runs showed.

    Parameters
    ----------
    runs : list of AxisLog
        Prepared training runs (each starts its trailing window afresh).
    cells_per_decade : int, default :data:`CELLS_PER_DECADE`
        Resolution of the grid [-].
    min_share : float, default :data:`MIN_CELL_SHARE`
        Share of the training samples a cell must hold to count as seen [-] (and at least
        :data:`MIN_CELL_SAMPLES` samples).

    Returns
    -------
    dict
        ``window_s`` [s], ``speed_edges`` [mm/s or deg/s] (geometric, :data:`SPEED_DECADES` decades below
        the largest speed), ``span_edges`` [mm or deg] (geometric, :data:`SPAN_DECADES` decades below the
        width of the positions), ``cells``: the ``[speed cell, span cell]`` pairs that held ``min_share``
        of the training samples (at least :data:`MIN_CELL_SAMPLES`), sorted, and ``reversals``: per span
        cell the most reversals by the first span edge within the window that as many training samples of
        the cell reached, -1 for a cell that held fewer (:data:`REVERSALS_RULE`).
    """
    speeds = [np.abs(np.asarray(run.velocity, dtype=float)) for run in runs]
    top = float(max(np.max(s) for s in speeds))
    low = float(min(np.min(run.position) for run in runs))
    high = float(max(np.max(run.position) for run in runs))
    width = high - low if high > low else 1.0
    speed_edges = [float(value) for value in (top if top > 0 else 1.0) * np.logspace(
        -SPEED_DECADES, 0, SPEED_DECADES * cells_per_decade + 1)]
    span_edges = [float(value) for value in width * np.logspace(-SPAN_DECADES, 0, SPAN_DECADES * cells_per_decade + 1)]
    counts = np.zeros((len(speed_edges) - 1, len(span_edges) - 1), dtype=np.int64)
    turns = []  # per run: (span cell, reversals in the window) of each sample
    for run, speed in zip(runs, speeds):
        samples = _window_samples(SPAN_WINDOW_S, run.sample_time)
        span, _ = local_span(run.position, samples)
        i, j = _cells(speed, span, _inner(speed_edges), _inner(span_edges))
        np.add.at(counts, (i, j), 1)
        turns.append(span_turns(run.position, samples, span_edges, span_edges[0], span=span))
    least = max(MIN_CELL_SAMPLES, int(math.ceil(min_share * counts.sum())))
    cells = [[int(i), int(j)] for i, j in zip(*np.nonzero(counts >= least))]
    return {"window_s": SPAN_WINDOW_S, "speed_edges": speed_edges, "span_edges": span_edges, "cells": cells,
            _REVERSAL_KEY: most_reversals(turns, len(span_edges) - 1)}


def span_turns(position: np.ndarray, samples: int, span_edges, deadband: float, *,
               span: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The span cell of each sample of a whole run and its reversals within the same trailing window.

    Parameters
    ----------
    position : ndarray, shape (n,)
        Position of the run [mm or deg].
    samples : int
        Window length [samples], at least 1.
    span_edges : list of float
        Edges of the span cells [mm or deg].
    deadband : float
        Least turn that counts as a reversal [mm or deg] (:func:`reversal_marks`).
    span : ndarray, shape (n,), optional
        The run's :func:`local_span` over the same window [mm or deg], where the caller has it already.

    Returns
    -------
    cell : ndarray of int, shape (n,)
        Span cell of each sample (outer cells take what lies beyond the outer edges).
    count : ndarray of int64, shape (n,)
        Reversals within its window [-].
    """
    if span is None:
        span, _ = local_span(position, samples)
    marks, _ = reversal_marks(position, deadband)
    return np.searchsorted(_inner(span_edges), span, side="right"), trailing_reversals(marks, samples)[0]


def most_reversals(turns, cells: int, least: int = MIN_CELL_SAMPLES) -> list[int]:
    """Per span cell, the most reversals that at least ``least`` samples of the cell reached (-1 for a cell
    of fewer samples): the ``reversals`` of an ``operating`` record.

    Parameters
    ----------
    turns : list of tuple
        Per training run, :func:`span_turns`.
    cells : int
        Span cells of the grid.
    least : int, default :data:`MIN_CELL_SAMPLES`
        Samples that must reach a count [-].

    Returns
    -------
    list of int
    """
    span_cell = np.concatenate([j for j, _ in turns])
    count = np.concatenate([c for _, c in turns])
    most = []
    for cell in range(cells):
        reached = np.sort(count[span_cell == cell])[::-1]  # the k-th largest: reached by k samples
        most.append(int(reached[least - 1]) if reached.size >= least else -1)
    return most


def _edges(values, name: str) -> list[float]:
    if not isinstance(values, list) or not 2 <= len(values) <= _MAX_EDGES:
        raise ValueError(f"operating.{name} must be a list of 2 to {_MAX_EDGES} numbers")
    numbers = []
    for value in values:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ValueError(f"operating.{name} must hold finite numbers, got {value!r}")
        numbers.append(float(value))
    if any(b <= a for a, b in zip(numbers, numbers[1:])) or numbers[0] < 0.0:
        raise ValueError(f"operating.{name} must be non-negative and strictly increasing")
    return numbers


def check_operating_record(record) -> dict:
    """Check an ``operating`` record read from a model file (never trusted); return it.

    Parameters
    ----------
    record : object
        The record.

    Returns
    -------
    dict
        The same record.

    Raises
    ------
    ValueError
        Naming the first key that is missing, of the wrong type or out of range.
    """
    if not isinstance(record, dict) or set(record) - {_REVERSAL_KEY} != _KEYS:
        raise ValueError(f"operating must hold exactly {', '.join(sorted(_KEYS))} (and {_REVERSAL_KEY})")
    window = record["window_s"]
    if isinstance(window, bool) or not isinstance(window, (int, float)) or not 0.0 < window <= 60.0:
        raise ValueError(f"operating.window_s must be a number of seconds in (0, 60], got {window!r}")
    speed = _edges(record["speed_edges"], "speed_edges")
    span = _edges(record["span_edges"], "span_edges")
    cells = record["cells"]
    shape = (len(speed) - 1, len(span) - 1)
    if not isinstance(cells, list) or len(cells) > shape[0] * shape[1]:
        raise ValueError(f"operating.cells must be a list of at most {shape[0] * shape[1]} cells")
    for cell in cells:
        if not (isinstance(cell, list) and len(cell) == 2 and all(
                isinstance(k, int) and not isinstance(k, bool) and 0 <= k < n for k, n in zip(cell, shape))):
            raise ValueError(f"operating.cells must hold [speed cell, span cell] pairs within the grid "
                             f"{shape[0]} x {shape[1]}, got {cell!r}")
    most = record.get(_REVERSAL_KEY, [])
    if not isinstance(most, list) or (_REVERSAL_KEY in record and len(most) != shape[1]) or not all(
            isinstance(k, int) and not isinstance(k, bool) and -1 <= k <= _MAX_REVERSALS for k in most):
        raise ValueError(f"operating.{_REVERSAL_KEY} must be a list of {shape[1]} whole numbers from -1 to "
                         f"{_MAX_REVERSALS}, one per span cell")
    return record


class OperatingRegion:
    """Flags the samples of a run outside the operating region of a training record.

    Parameters
    ----------
    ranges : dict
        The training record's ``ranges``: ``[low, high]`` of ``position``, ``velocity`` and
        ``acceleration`` (those it holds) [mm, mm/s, mm/s^2 or deg, ...].
    operating : dict
        The training record's ``operating`` record (:func:`operating_record`), checked.
    neighbours : int, default :data:`NEIGHBOURS`
        Cells next to a seen one that count as seen too, in each direction of the grid [-].
    """

    def __init__(self, ranges: dict, operating: dict, *, neighbours: int = NEIGHBOURS):
        self.ranges = ranges
        self.operating = operating
        self.neighbours = neighbours
        speed, span = operating["speed_edges"], operating["span_edges"]
        seen = np.zeros((len(speed) - 1, len(span) - 1), dtype=bool)
        for i, j in operating["cells"]:
            seen[max(i - neighbours, 0):i + neighbours + 1, max(j - neighbours, 0):j + neighbours + 1] = True
        self._seen = seen
        most = operating.get(_REVERSAL_KEY)  # None: a file of format version 4, without the rule
        self._reversals = most is not None
        self._most = np.asarray(most, dtype=np.int64) if self._reversals else np.full(seen.shape[1], _MAX_REVERSALS)
        self._speed_inner, self._span_inner = _inner(speed), _inner(span)
        self._bounds = [(channel, *ranges[channel]) for channel in ("position", "velocity", "acceleration")
                        if ranges.get(channel) is not None]

    @classmethod
    def of(cls, training: dict | None) -> "OperatingRegion | None":
        """The region of a training record; None for a record without one (a file that predates it).

        Parameters
        ----------
        training : dict or None
            A checked training record (:func:`greybox.provenance.check_training_record`).
        """
        if not training or "operating" not in training:
            return None
        return cls(training["ranges"], training["operating"])

    def start(self):
        """The state at the start of a run: no position seen yet."""
        return None, None, None

    def flags(self, log, state, *, sample_time: float) -> tuple[dict[str, np.ndarray], np.ndarray]:
        """Samples of one chunk of a run outside the region, from the state the previous chunk left.

        Parameters
        ----------
        log : AxisLog
            Prepared chunk: consecutive samples of one run.
        state : object
            :meth:`start` at the start of a run, else what the previous chunk returned (consumed: the
            window's span and reversal count in it are updated in place).
        sample_time : float
            Step [s] of the whole run.

        Returns
        -------
        flags : dict of str to ndarray of bool
            ``"position"``, ``"velocity"``, ``"acceleration"`` (each where the record holds its range):
            True outside the training range; ``"motion"``: True where the pair (speed, local span) lies in
            no cell seen in training nor within ``neighbours`` cells of one, or (where the record holds
            ``reversals``) where the position turned back more often within the window than the training
            runs did at that span cell.
        state : tuple
            The trailing window's running span (:func:`local_span`), the reversal detector and the window's
            reversal count (:func:`trailing_reversals`), carried over and updated in place: the ``state`` of
            the next chunk.
        """
        out = {}
        for channel, low, high in self._bounds:
            values = getattr(log, channel, None)
            if values is not None:
                out[channel] = (values < low) | (values > high)
        spans, detector, window = state
        samples = _window_samples(self.operating["window_s"], sample_time)
        span, spans = local_span(log.position, samples, spans)
        if self._reversals:
            marks, detector = reversal_marks(log.position, self.operating["span_edges"][0], detector)
            count, window = trailing_reversals(marks, samples, window)
        else:  # a file of format version 4: no count exceeds the most of every cell
            count = np.zeros(span.size, dtype=np.int64)
        out["motion"] = np.empty(span.size, dtype=np.bool_)
        _unseen_kernel(np.abs(np.asarray(log.velocity, dtype=np.float64)), span, count, self._speed_inner,
                       self._span_inner, self._seen, self._most, out["motion"])
        return out, (spans, detector, window)
