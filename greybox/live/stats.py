"""The count of everything a live stream received, estimated, dropped or lost.

Every sample of a message that was read is counted once, in one of: estimated, dropped (its time stamp:
backwards, early), lost (a run too short to derive, a run's lone last sample, waiting when the command
was stopped) or still waiting. Messages that could not be read at all are counted as rejected (their
samples are unknown).
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field

from ..atomic import write_text_atomic

__all__ = ["LiveStats", "StatsFile"]


@dataclass
class LiveStats:
    """Counters of a live stream.

    Attributes
    ----------
    messages : int
        Messages received (headers and comments included).
    rejected : int
        Messages skipped as malformed or out of range.
    samples_received : int
        Samples of the messages read.
    samples_estimated : int
        Samples whose estimate went out.
    dropped : dict of str to int
        Samples dropped for their time stamps, per reason.
    lost : dict of str to int
        Samples received but never estimated, per reason.
    waiting : int
        Samples received, not yet estimated (their look-ahead missing).
    gaps : int
        Gaps in the time stamps (each re-initialised the model's state).
    disconnections : int
        Losses of the connection to the broker.
    offline_s : float
        Time without a broker connection [s].
    alarms : int
        Alarms raised.
    alarms_cleared : int
        Alarms cleared.
    outputs_lost : int
        Estimate or alarm messages that could not be published (the queue full while the broker was away).
    outputs_queued : int
        Estimate or alarm messages published and not yet acknowledged by the broker.
    output_disconnections : int
        Losses of the sink's connection to the broker.
    """

    messages: int = 0
    rejected: int = 0
    samples_received: int = 0
    samples_estimated: int = 0
    dropped: dict = field(default_factory=dict)
    lost: dict = field(default_factory=dict)
    waiting: int = 0
    gaps: int = 0
    disconnections: int = 0
    offline_s: float = 0.0
    alarms: int = 0
    alarms_cleared: int = 0
    outputs_lost: int = 0
    outputs_queued: int = 0
    output_disconnections: int = 0

    def drop(self, reason: str, count: int) -> None:
        """Count samples dropped for their time stamps.

        Parameters
        ----------
        reason : str
            Why ("backwards", "early").
        count : int
            Samples.
        """
        self.dropped[reason] = self.dropped.get(reason, 0) + int(count)

    def lose(self, reason: str, count: int) -> None:
        """Count samples received but never estimated.

        Parameters
        ----------
        reason : str
            Why.
        count : int
            Samples.
        """
        self.lost[reason] = self.lost.get(reason, 0) + int(count)

    @property
    def skipped(self) -> int:
        """Samples dropped or lost."""
        return sum(self.dropped.values()) + sum(self.lost.values())

    def line(self) -> str:
        """The counters in one line."""
        def parts(counts: dict) -> str:
            return f" ({', '.join(f'{name} {count}' for name, count in sorted(counts.items()))})" if counts else ""

        return (f"stats: {self.messages} messages ({self.rejected} rejected), {self.samples_received} samples "
                f"received, {self.samples_estimated} estimated, {sum(self.dropped.values())} dropped"
                f"{parts(self.dropped)}, {sum(self.lost.values())} lost{parts(self.lost)}, {self.waiting} waiting; "
                f"{self.gaps} gap(s), {self.disconnections} disconnection(s) ({self.offline_s:.1f} s offline), "
                f"{self.alarms} alarm(s) ({self.alarms_cleared} cleared), {self.outputs_lost} output message(s) "
                f"lost, {self.outputs_queued} queued, {self.output_disconnections} sink disconnection(s)")

    def to_dict(self) -> dict:
        """JSON-able counters, with ``skipped`` (dropped + lost)."""
        return {**asdict(self), "skipped": self.skipped}


class StatsFile:
    """The counters file of a stream, written by a thread of its own while the stream runs.

    Writing a file atomically syncs it to the disk, which on a busy disk takes from milliseconds to
    seconds; done by the main thread it held up the messages behind it. :meth:`write` takes the
    counters as they are (in the caller's thread) and leaves the file to a writer thread; a write that falls
    due while the previous one is still going is left out (the next one brings the counters up to date).
    :meth:`close` writes the last counters and waits for it: the file then holds them.

    Parameters
    ----------
    path : path-like
        The stats file (replaced each time).

    Attributes
    ----------
    written : int
        Writes done.
    skipped : int
        Writes left out because the previous one was still going.
    """

    def __init__(self, path):
        from concurrent.futures import ThreadPoolExecutor

        self.path = path
        self.written = self.skipped = 0
        self._writer = ThreadPoolExecutor(max_workers=1, thread_name_prefix="greybox-stats")
        self._pending = None

    def write(self, counters: dict) -> None:
        """Write ``counters`` (JSON-able) in the writer thread, unless the previous write is still going.

        Parameters
        ----------
        counters : dict
            The counters as they are now.

        Raises
        ------
        OSError
            The previous write's error (e.g. the folder is gone).
        """
        if self._pending is not None:
            if not self._pending.done():
                self.skipped += 1
                return
            self._pending.result()
        self._pending = self._writer.submit(self._write, json.dumps(counters, indent=1) + "\n")

    def close(self, counters: dict) -> None:
        """Wait for the write in progress, then write ``counters`` and wait for it.

        Parameters
        ----------
        counters : dict
            The last counters.
        """
        try:
            if self._pending is not None:
                self._pending.result()
            self._pending = None
            self._writer.submit(self._write, json.dumps(counters, indent=1) + "\n").result()
        finally:
            self._writer.shutdown(wait=True)

    def _write(self, text: str) -> None:
        write_text_atomic(self.path, text)
        self.written += 1
