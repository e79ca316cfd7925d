"""Where the estimates of a live stream go: lines on a text stream (stdout) or messages on an MQTT topic.

Every sink takes the JSON text of an estimate message (:func:`greybox.live.messages.estimate_message`)
and of an alarm. On MQTT the alarms go to the topic ``<TOPIC>/alarm/<column>`` beside the estimates, retained.
"""

from __future__ import annotations

from collections import deque
from typing import TextIO

from .broker import BrokerAddress, BrokerOptions, Connection
from .sources import ConnectionChange

__all__ = ["LineSink", "MqttSink"]


class LineSink:
    """Estimates and alarms as JSON lines of a text stream.

    Parameters
    ----------
    stream : text file
        E.g. ``sys.stdout``.

    Attributes
    ----------
    lost : int
        Messages that could not be delivered (always 0 here).
    """

    def __init__(self, stream: TextIO):
        self.stream = stream
        self.lost = 0

    def estimate(self, text: str, subtopic: str | None = None) -> None:
        """Write one estimate message as a line.

        Parameters
        ----------
        text : str
            JSON text.
        subtopic : str, optional
            Not used (the JSON names the axis of a machine).
        """
        self.stream.write(text + "\n")
        self.stream.flush()

    def alarm(self, text: str, subtopic: str | None = None, column: str = "limit") -> None:
        """Write one alarm message (raised or cleared) as a line.

        Parameters
        ----------
        text : str
            JSON text.
        subtopic : str, optional
            Not used.
        column : str, default "limit"
            Not used (the JSON names it).
        """
        self.estimate(text)

    @property
    def queued(self) -> int:
        """Messages waiting to go out (always 0 here)."""
        return 0

    def changes(self) -> list:
        """Changes of a connection (none here)."""
        return []

    def close(self) -> None:
        """Flush the stream (it is the caller's)."""
        self.stream.flush()


class MqttSink:
    """Estimates on an MQTT topic, alarms on ``<topic>/alarm/<column>`` (retained: the state of each limit).

    Messages go out at the connection's QoS (1 by default); while the broker is away they are queued (at
    most ``options.queue_size``, beyond that counted as lost) and sent once it is back.

    Parameters
    ----------
    address : BrokerAddress
        Broker and topic.
    options : BrokerOptions, optional
        Log-in, TLS, client id, QoS, queue.
    will : tuple of (str, str), optional
        ``(topic, text)`` the broker publishes, retained, when the connection is lost without a goodbye.

    Attributes
    ----------
    lost : int
        Messages not published (the queue full, or the broker away at QoS 0).

    Raises
    ------
    GreyboxError
        When the broker cannot be reached or refuses the connection at the start.
    """

    def __init__(self, address: BrokerAddress, options: BrokerOptions | None = None, *,
                 will: tuple[str, str] | None = None):
        self.address = address
        self._closed = False
        self._changes: deque = deque()
        self.connection = Connection(address, options, role="out", will=will,
                                     on_state=lambda *change: self._changes.append(ConnectionChange(*change)))

    @property
    def lost(self) -> int:
        """Messages not published."""
        return self.connection.refused

    @property
    def queued(self) -> int:
        """Messages published and not yet acknowledged by the broker (waiting for it while it is away)."""
        return self.connection.queued

    def changes(self) -> list:
        """The losses and returns of the sink's connection since the last call (:class:`ConnectionChange`)."""
        out = []
        while self._changes:
            out.append(self._changes.popleft())
        return out

    def _topic(self, subtopic: str | None) -> str:
        return self.address.topic if subtopic is None else f"{self.address.topic}/{subtopic}"

    def estimate(self, text: str, subtopic: str | None = None) -> None:
        """Publish one estimate message on the topic (``<topic>/<subtopic>`` with a subtopic).

        Parameters
        ----------
        text : str
            JSON text.
        subtopic : str, optional
            The axis of a machine.
        """
        self.connection.publish(self._topic(subtopic), text)

    def alarm(self, text: str, subtopic: str | None = None, column: str = "limit") -> None:
        """Publish one alarm message (raised or cleared), retained, on ``<topic>[/<subtopic>]/alarm/<column>``.

        Parameters
        ----------
        text : str
            JSON text.
        subtopic : str, optional
            The axis of a machine.
        column : str, default "limit"
            The column of the limit.
        """
        self.connection.publish(f"{self._topic(subtopic)}/alarm/{column}", text, retain=True)

    def close(self, wait_s: float = 5.0) -> None:
        """Wait (at most ``wait_s``) for the queued messages to be acknowledged, then disconnect; closing
        again does nothing.

        Parameters
        ----------
        wait_s : float, default 5.0
            Most seconds to wait for the queue.
        """
        if not self._closed:
            self._closed = True
            if self.connection.connected:
                self.connection.wait_for_queue(wait_s)
            self.connection.close()
