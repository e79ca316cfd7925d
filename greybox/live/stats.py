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

__all__ = ["LiveStats"]


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

    def write(self, path) -> None:
        """Write the counters as JSON, atomically.

        Parameters
        ----------
        path : path-like
            The stats file (replaced each time).
        """
        write_text_atomic(path, json.dumps(self.to_dict(), indent=1) + "\n")
