"""Where the messages of a live stream come from: lines of a text stream (stdin) or an MQTT topic.

(An OPC UA server's variables: :mod:`greybox.live.opcua`.) A source (:class:`~greybox.live.source_base.Source`)
is an iterable of :class:`Received` messages and :class:`ConnectionChange` events, in the order
they happened; it ends when the stream does (end of the text stream; an MQTT source runs until the
command is stopped). An MQTT source also gives an :class:`Idle` each time no message came for its poll
interval, so that the command can do what is due while the stream is quiet.
"""

from __future__ import annotations

import queue
import time
from typing import Iterator, TextIO

from .broker import BrokerAddress, BrokerOptions, Connection
from .source_base import ConnectionChange, Idle, Received, Source, polled

__all__ = ["DEFAULT_IDLE_S", "Received", "ConnectionChange", "Idle", "LineSource", "MqttSource"]

#: Seconds without a message after which the samples waiting are estimated as the end of a run (``--idle-s``).
DEFAULT_IDLE_S = 0.5


#: What the return of the broker means for the stream (said after it).
_RESUMED = ("the messages the broker kept for the session (QoS 1) come now, any missing make a gap in the time "
            "stamps (the model's state re-initialised)")


class LineSource(Source):
    """Messages as lines of a text stream: JSON lines, or CSV lines after a header line.

    Parameters
    ----------
    stream : text file
        E.g. ``sys.stdin``.
    name : str, default "stdin"
        The stream's name in messages.
    """

    def __init__(self, stream: TextIO, *, name: str = "stdin"):
        self.stream = stream
        self.name = name

    def __iter__(self) -> Iterator[Received]:
        for number, line in enumerate(self.stream, start=1):
            if line.strip():
                yield Received(line, f"{self.name} line {number}", time.time())

    def close(self) -> None:
        """Nothing to release (the stream is the caller's)."""


class MqttSource(Source):
    """Messages of an MQTT topic, taken in arrival order; connection losses and returns in between.

    Parameters
    ----------
    address : BrokerAddress
        Broker and topic (wildcards allowed).
    options : BrokerOptions, optional
        Log-in, TLS, client id, QoS of the subscription, session.
    will : tuple of (str, str), optional
        ``(topic, text)`` the broker publishes, retained, when the connection is lost without a goodbye.
    poll_s : float, default 0.1
        How long the iteration waits for a message before it gives an :class:`Idle` (the command stays
        responsive to signals and does what is due while the stream is quiet).

    Raises
    ------
    GreyboxError
        When the broker cannot be reached at the start.
    """

    def __init__(self, address: BrokerAddress, options: BrokerOptions | None = None, *,
                 will: tuple[str, str] | None = None, poll_s: float = 0.1):
        self.address = address
        self.poll_s = float(poll_s)
        self._queue: queue.Queue = queue.Queue()
        self._count = 0
        self.connection = Connection(address, options, role="in", subscribe=address.topic, will=will,
                                     on_message=self._message, on_state=self._state)

    def _message(self, topic: str, payload: bytes, arrived_s: float) -> None:
        self._queue.put((topic, payload, arrived_s))

    def _state(self, connected: bool, time_s: float, reason: str) -> None:
        self._queue.put(ConnectionChange(connected, time_s, reason, after=_RESUMED if connected else ""))

    def __iter__(self) -> Iterator[Received | ConnectionChange | Idle]:
        for item in polled(self._queue, self.poll_s):
            if isinstance(item, (Idle, ConnectionChange)):
                yield item
                continue
            topic, payload, arrived_s = item
            self._count += 1
            yield Received(payload, f"message {self._count} on {topic}", arrived_s, topic)

    def close(self) -> None:
        """Disconnect from the broker (after the status it carries is acknowledged, at most 2 s)."""
        if self.connection.connected:
            self.connection.wait_for_queue(2.0)
        self.connection.close()
