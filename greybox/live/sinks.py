"""Where the estimates of a live stream go: lines on a text stream (stdout) or messages on an MQTT topic.

Every sink takes the JSON text of an estimate message (:func:`greybox.live.messages.estimate_message`)
and of an alarm. On MQTT the alarms go to the topic ``<TOPIC>/alarm`` beside the estimates.
"""

from __future__ import annotations

from typing import TextIO

from .broker import BrokerAddress, Connection

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

    def alarm(self, text: str, subtopic: str | None = None) -> None:
        """Write one alarm message as a line.

        Parameters
        ----------
        text : str
            JSON text.
        subtopic : str, optional
            Not used.
        """
        self.estimate(text)

    def close(self) -> None:
        """Flush the stream (it is the caller's)."""
        self.stream.flush()


class MqttSink:
    """Estimates on an MQTT topic, alarms on ``<topic>/alarm``.

    Parameters
    ----------
    address : BrokerAddress
        Broker and topic.
    connect_timeout : float, default 10.0
        Seconds to wait for the broker at the start.

    Attributes
    ----------
    lost : int
        Messages not published because the broker was away.

    Raises
    ------
    GreyboxError
        When the broker cannot be reached at the start.
    """

    def __init__(self, address: BrokerAddress, *, connect_timeout: float = 10.0):
        self.address = address
        self.lost = 0
        self._closed = False
        self.connection = Connection(address, connect_timeout=connect_timeout)

    def estimate(self, text: str, subtopic: str | None = None) -> None:
        """Publish one estimate message on the topic (``<topic>/<subtopic>`` with a subtopic).

        Parameters
        ----------
        text : str
            JSON text.
        subtopic : str, optional
            The axis of a machine.
        """
        topic = self.address.topic if subtopic is None else f"{self.address.topic}/{subtopic}"
        if not self.connection.publish(topic, text):
            self.lost += 1

    def alarm(self, text: str, subtopic: str | None = None) -> None:
        """Publish one alarm message on ``<topic>/alarm`` (``<topic>/<subtopic>/alarm`` with a subtopic).

        Parameters
        ----------
        text : str
            JSON text.
        subtopic : str, optional
            The axis of a machine.
        """
        topic = self.address.topic if subtopic is None else f"{self.address.topic}/{subtopic}"
        if not self.connection.publish(f"{topic}/alarm", text):
            self.lost += 1

    def close(self) -> None:
        """Disconnect (after the queued messages are out); closing again does nothing."""
        if not self._closed:
            self._closed = True
            self.connection.close()
