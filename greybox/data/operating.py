"""The operating region of training runs: the motion they showed, whichever model is fitted on them.

A sample of a run lies inside the region when its position, velocity and acceleration lie within the
ranges of the training runs (the training record's ``ranges``) and its *motion* was seen in training: the
pair (speed ``|v|``, local span) falls in a cell of a grid that training samples occupied, or in a
neighbouring cell (:data:`NEIGHBOURS`). The local span is ``max - min`` of the position over the trailing window
:data:`SPAN_WINDOW_S` ending at the sample: a sweep has the span of its travel, a dwell none, and a small
oscillation a small span at a speed that in the training runs only came with a large one. The region
depends on the training runs alone, never on the model: every kind of model trained on the same runs has
the same region (docs/defaults.md, "What counts as inside the training region").

:func:`operating_record` builds the record the training record keeps as ``operating``;
:func:`check_operating_record` validates one read from a model file; :class:`OperatingRegion` flags the
samples of a run, chunk by chunk if need be (the trailing window carries over as its state).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["SPAN_WINDOW_S", "SPEED_DECADES", "SPAN_DECADES", "CELLS_PER_DECADE", "MIN_CELL_SAMPLES", "MIN_CELL_SHARE",
           "NEIGHBOURS",
           "OperatingRegion", "check_operating_record", "local_span", "operating_record"]

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

#: The keys of an ``operating`` record.
_KEYS = {"window_s", "speed_edges", "span_edges", "cells"}

#: Most edges of one axis of the grid a record may hold (a model file is never trusted).
_MAX_EDGES = 257


def _window_samples(window_s: float, sample_time: float) -> int:
    """Samples of the trailing window at ``sample_time`` [s] (at least one)."""
    return max(int(round(window_s / sample_time)), 1)


def local_span(position: np.ndarray, samples: int, history: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``max - min`` of the position over the trailing window of ``samples`` samples ending at each sample.

    Parameters
    ----------
    position : ndarray, shape (n,)
        Position of consecutive samples [mm or deg].
    samples : int
        Window length [samples], at least 1.
    history : ndarray, optional
        The positions before the first sample (the state a previous chunk left); none at the start of a run,
        where the window holds what the run has shown so far.

    Returns
    -------
    span : ndarray, shape (n,)
        Local span [mm or deg].
    history : ndarray
        The last ``samples - 1`` positions: the ``history`` of the next chunk.
    """
    position = np.ascontiguousarray(position, dtype=np.float64)
    past = np.empty(0) if history is None else np.ascontiguousarray(history, dtype=np.float64)
    span = np.empty(position.size)
    if position.size == 0:
        return span, past
    values = np.concatenate((past, position))
    _span_kernel(values, past.size, samples, span)
    keep = samples - 1
    return span, values[-keep:].copy() if keep else np.empty(0)


@njit(cache=True, error_model="numpy")
def _span_kernel(values, first, window, out):  # pragma: no cover - compiled; reference in the tests
    """``out[k]`` = ``max - min`` of the trailing ``window`` of ``values`` ending at ``values[first + k]``
    (fewer at the start: what the sequence has shown so far, :func:`local_span`).

    A running maximum and minimum: two monotone queues of indices (the maximum's values decreasing, the
    minimum's increasing), each index pushed and popped once: O(1) amortised a sample whatever the window,
    and the same values as taking ``max - min`` of each window.
    """
    high = np.empty(values.size, dtype=np.int64)
    low = np.empty(values.size, dtype=np.int64)
    high_head, high_tail, low_head, low_tail = 0, 0, 0, 0
    for t in range(values.size):
        value = values[t]
        while high_tail > high_head and values[high[high_tail - 1]] <= value:
            high_tail -= 1
        high[high_tail] = t
        high_tail += 1
        while low_tail > low_head and values[low[low_tail - 1]] >= value:
            low_tail -= 1
        low[low_tail] = t
        low_tail += 1
        oldest = t - window + 1
        while high[high_head] < oldest:
            high_head += 1
        while low[low_head] < oldest:
            low_head += 1
        if t >= first:
            out[t - first] = values[high[high_head]] - values[low[low_head]]


@njit(cache=True, error_model="numpy")
def _unseen_kernel(speed, span, speed_inner, span_inner, seen, out):  # pragma: no cover - compiled
    """``out[k]`` = the grid cell of (``speed[k]``, ``span[k]``) is not ``seen`` (outer cells take what lies
    beyond the outer edges)."""
    for k in range(speed.size):
        out[k] = not seen[np.searchsorted(speed_inner, speed[k], side="right"),
                          np.searchsorted(span_inner, span[k], side="right")]


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
        width of the positions) and ``cells``: the ``[speed cell, span cell]`` pairs that held ``min_share``
        of the training samples (at least :data:`MIN_CELL_SAMPLES`), sorted.
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
    for run, speed in zip(runs, speeds):
        span, _ = local_span(run.position, _window_samples(SPAN_WINDOW_S, run.sample_time))
        i, j = _cells(speed, span, _inner(speed_edges), _inner(span_edges))
        np.add.at(counts, (i, j), 1)
    least = max(MIN_CELL_SAMPLES, int(math.ceil(min_share * counts.sum())))
    cells = [[int(i), int(j)] for i, j in zip(*np.nonzero(counts >= least))]
    return {"window_s": SPAN_WINDOW_S, "speed_edges": speed_edges, "span_edges": span_edges, "cells": cells}


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
    if not isinstance(record, dict) or set(record) != _KEYS:
        raise ValueError(f"operating must hold exactly {', '.join(sorted(_KEYS))}")
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
        return None

    def flags(self, log, state, *, sample_time: float) -> tuple[dict[str, np.ndarray], np.ndarray]:
        """Samples of one chunk of a run outside the region, from the state the previous chunk left.

        Parameters
        ----------
        log : AxisLog
            Prepared chunk: consecutive samples of one run.
        state : object
            :meth:`start` at the start of a run, else what the previous chunk returned.
        sample_time : float
            Step [s] of the whole run.

        Returns
        -------
        flags : dict of str to ndarray of bool
            ``"position"``, ``"velocity"``, ``"acceleration"`` (each where the record holds its range):
            True outside the training range; ``"motion"``: True where the pair (speed, local span) lies in
            no cell seen in training nor within ``neighbours`` cells of one.
        state : ndarray
            The positions of the trailing window: the ``state`` of the next chunk.
        """
        out = {}
        for channel, low, high in self._bounds:
            values = getattr(log, channel, None)
            if values is not None:
                out[channel] = (values < low) | (values > high)
        span, state = local_span(log.position, _window_samples(self.operating["window_s"], sample_time), state)
        out["motion"] = np.empty(span.size, dtype=np.bool_)
        _unseen_kernel(np.abs(np.asarray(log.velocity, dtype=np.float64)), span, self._speed_inner,
                       self._span_inner, self._seen, out["motion"])
        return out, state
