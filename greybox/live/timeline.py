"""The time base of a live stream: the nominal step, and samples late, early, backwards or after a gap.

Offline, a log must be uniform within a tolerance of its median step (:func:`greybox.data.validate.check_time`)
and the models integrate at that step. Live, the nominal step is given (``--sample-time``) or taken as the
median step of the first :data:`SETTLE_SAMPLES` samples; from then on every sample is compared with the
last one kept:

* a step within the tolerance of the nominal step: kept (jitter the readers accept too);
* time standing still or going backwards: the sample is dropped and counted;
* a step shorter than the tolerance allows: the sample is dropped and counted;
* a step longer than the tolerance allows: a gap; the run ends there and a new one starts with the
  sample (the model's state re-initialised, as the readers split a log at gaps).

With ``max_gap`` (``greybox live --max-gap``) short glitches are bridged as ``greybox predict --resample
--max-gap`` bridges them: every sample after the last one kept is kept, whatever its step, and the run is
resampled onto its grid of nominal steps from its first sample by linear interpolation
(:func:`greybox.data.prepare.resample`, piece by piece); only a step longer than ``max_gap`` nominal steps
(:func:`greybox.data.prepare.gap_steps`) is a gap. Jittered time stamps, or a sample left out (a NaN in a
message), then keep the run and the model's state going.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..data.blocks import concatenate
from ..data.log import AxisLog
from ..data.prepare import gap_steps, resample

__all__ = ["SETTLE_SAMPLES", "Dropped", "Gap", "Timeline"]

#: Samples whose median step is the nominal step when none is given.
SETTLE_SAMPLES = 16


@dataclass(frozen=True)
class Dropped:
    """Samples of a message dropped for their time stamps.

    Attributes
    ----------
    count : int
        Samples dropped.
    time_s : float
        Time stamp of the first one [s].
    after_s : float
        Time of the last sample kept before it [s].
    reason : str
        "backwards" (time standing still or going back) or "early" (a step shorter than the tolerance).
    """

    count: int
    time_s: float
    after_s: float
    reason: str


@dataclass(frozen=True)
class Gap:
    """A step longer than the tolerance: the run ends before ``time_s``.

    Attributes
    ----------
    time_s : float
        Time of the first sample after the gap [s].
    step_s : float
        The step [s].
    missing : int
        Samples missing at the nominal step, about ``step_s / nominal - 1``.
    """

    time_s: float
    step_s: float
    missing: int


class Timeline:
    """Checks the time stamps of a stream sample by sample against a nominal step.

    Parameters
    ----------
    sample_time : float, optional
        Nominal step [s]; default the median step of the first :data:`SETTLE_SAMPLES` samples.
    tolerance : float, default 0.25
        Allowed deviation of a step from the nominal step, as a fraction of it (as in ``greybox predict``).
    max_gap : float, optional
        Bridge steps up to this many nominal steps (> 1) by resampling onto the nominal grid, as ``greybox
        predict --resample --max-gap`` does; ``tolerance`` then no longer applies. Default: no resampling.

    Attributes
    ----------
    nominal : float or None
        The nominal step [s] once known.
    """

    def __init__(self, *, sample_time: float | None = None, tolerance: float = 0.25, max_gap: float | None = None):
        if not 0.0 < tolerance < 1.0:
            raise ValueError(f"tolerance must lie in (0, 1), got {tolerance!r}")
        if max_gap is not None and not max_gap > 1.0:
            raise ValueError(f"max_gap must be larger than 1, got {max_gap!r}")
        self.nominal = None if sample_time is None else float(sample_time)
        self.tolerance = float(tolerance)
        self.max_gap = None if max_gap is None else float(max_gap)
        self._tail: AxisLog | None = None  # with max_gap: the run's raw samples from the last before the next point
        self._origin = 0.0  # with max_gap: time of the run's grid point 0 [s]
        self._next = 0  # with max_gap: the run's next grid point
        self._held: list[AxisLog] = []  # samples before the nominal step is known
        self._last: float | None = None

    @property
    def held(self) -> int:
        """Samples held until the nominal step is known."""
        return sum(len(log) for log in self._held)

    def push(self, log: AxisLog) -> list:
        """The events of a message's samples, in order: kept samples (AxisLog), :class:`Dropped`, :class:`Gap`.

        Parameters
        ----------
        log : AxisLog
            The samples of one message.

        Returns
        -------
        list
            Until the nominal step is known, nothing (the samples are held); then the events of every
            sample held or given.
        """
        if self.nominal is None:
            self._held.append(log)
            held = concatenate(self._held)
            steps = np.diff(held.time)
            steps = steps[steps > 0.0]
            if steps.size < SETTLE_SAMPLES - 1:
                return []
            self.nominal = float(np.median(steps))
            self._held = []
            log = held
        return self._events(log)

    def flush(self) -> list:
        """The events of samples still held at the end of the stream (fewer than :data:`SETTLE_SAMPLES`).

        Their nominal step is their own median step; with fewer than two samples nothing is kept. With
        ``max_gap``, the next sample starts a new run's grid.
        """
        self._tail = None
        if self.nominal is not None or not self._held:
            return []
        held = concatenate(self._held)
        self._held = []
        steps = np.diff(held.time)
        steps = steps[steps > 0.0]
        if not steps.size:
            return [Dropped(len(held), float(held.time[0]), float("nan"), "backwards")] if len(held) > 1 else \
                [Dropped(1, float(held.time[0]), float("nan"), "alone")]
        self.nominal = float(np.median(steps))
        return self._events(held)

    def _events(self, log: AxisLog) -> list:
        if self.max_gap is not None:
            return self._bridged(log)
        low, high = (1.0 - self.tolerance) * self.nominal, (1.0 + self.tolerance) * self.nominal
        time = log.time
        if self._last is not None and len(time) and low <= time[0] - self._last <= high:
            steps = time[1:] - time[:-1]  # the usual message: every step within the tolerance
            if not steps.size or (steps.min() >= low and steps.max() <= high):
                self._last = float(time[-1])
                return [log]
        events: list = []
        keep = np.zeros(len(log), dtype=bool)
        start = 0  # first sample of the current kept stretch
        last = self._last

        def close(stop: int) -> None:
            kept = np.flatnonzero(keep[start:stop])
            if kept.size == len(log):  # every sample of the message kept: the message itself
                events.append(log)
            elif kept.size:
                events.append(log.select(kept + start))

        for k, t in enumerate(log.time.tolist()):
            if last is None:
                keep[k], last = True, t
                continue
            step = t - last
            if step <= 0.0 or step < low:
                reason = "backwards" if step <= 0.0 else "early"
                previous = events[-1] if events and isinstance(events[-1], Dropped) and k > 0 and not keep[k - 1] \
                    else None
                close(k)
                start = k + 1
                if previous is not None and previous.reason == reason:
                    events[-1] = Dropped(previous.count + 1, previous.time_s, previous.after_s, reason)
                else:
                    events.append(Dropped(1, t, last, reason))
                continue
            if step > high:
                close(k)
                start = k
                events.append(Gap(t, step, max(0, int(round(step / self.nominal)) - 1)))
            keep[k], last = True, t
        close(len(log))
        self._last = last
        return events

    def _bridged(self, log: AxisLog) -> list:
        """The events of a message's samples with ``max_gap``: resampled pieces, drops and gaps."""
        events: list = []
        before = -np.inf if self._last is None else self._last
        latest = np.maximum.accumulate(np.concatenate(([before], log.time)))[:-1]  # the newest time before each
        keep = log.time > latest
        if not keep.all():
            k = int(np.flatnonzero(~keep)[0])
            events.append(Dropped(int(np.count_nonzero(~keep)), float(log.time[k]), float(latest[k]), "backwards"))
            log = log.select(np.flatnonzero(keep))
            if not len(log):
                return events
        steps = np.diff(log.time, prepend=log.time[0] if self._last is None else self._last)
        starts = [int(k) for k in gap_steps(steps, self.nominal, self.max_gap)]
        edges = sorted({0, *starts, len(log)})
        for a, b in zip(edges[:-1], edges[1:]):
            if a in starts:
                events.append(Gap(float(log.time[a]), float(steps[a]), max(0, int(round(steps[a] / self.nominal)) - 1)))
                self._tail = None
            piece = self._grid(log.select(slice(a, b)))
            if len(piece):
                events.append(piece)
        self._last = float(log.time[-1])
        return events

    def _grid(self, piece: AxisLog) -> AxisLog:
        """The run's grid points that the samples of ``piece`` (after those held) reach."""
        if self._tail is None:
            self._origin, self._next, window = float(piece.time[0]), 0, piece
        else:
            window = concatenate([self._tail, piece])
        if len(window) < 2:
            self._tail = window
            return window.select(slice(0, 0))
        out = resample(window, self.nominal, origin=self._origin, first=self._next)
        self._next += len(out)
        after = int(np.searchsorted(window.time, self._origin + self._next * self.nominal, side="right")) - 1
        self._tail = window.select(slice(max(after, 0), None))
        return out
