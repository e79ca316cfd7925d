"""What every source of ``greybox live`` gives: the items of a stream, and the interface a source implements.

A source (stdin lines, an MQTT topic, an OPC UA server's variables) is an iterable of :class:`Received`
messages, :class:`ConnectionChange` events and :class:`Idle` ticks, in the order they happened, with a
``close``. The session that estimates (:mod:`greybox.live.session`) sees only these items, so the
transports are interchangeable. This module imports nothing else of the package.
"""

from __future__ import annotations

import abc
import queue
import time
from dataclasses import dataclass
from typing import Iterator

__all__ = ["Received", "ConnectionChange", "Idle", "Source", "polled"]


@dataclass(frozen=True)
class Received:
    """One message as it arrived.

    Attributes
    ----------
    payload : str or bytes
        The message text.
    name : str
        How errors name it, e.g. "line 12" or "message 12 on axis/X".
    arrived_s : float
        Arrival time, ``time.time()`` [s].
    topic : str
        The MQTT topic ("" for a line of a text stream or a sample of an OPC UA server).
    """

    payload: str | bytes
    name: str
    arrived_s: float
    topic: str = ""


@dataclass(frozen=True)
class ConnectionChange:
    """The connection to the broker or server was lost (``connected`` False) or is back.

    Attributes
    ----------
    connected : bool
        The new state.
    time_s : float
        When, ``time.time()`` [s].
    reason : str
        Why, in the transport's words ("" for a return).
    peer : str
        What the connection goes to, as the lines name it ("broker", "OPC UA server").
    after : str
        What a return means for the stream, said after it ("" for nothing).
    """

    connected: bool
    time_s: float
    reason: str = ""
    peer: str = "broker"
    after: str = ""


@dataclass(frozen=True)
class Idle:
    """No message came for the source's poll interval.

    Attributes
    ----------
    time_s : float
        When, ``time.time()`` [s].
    """

    time_s: float


class Source(abc.ABC):
    """Where the messages of a live stream come from.

    A subclass opens its transport in ``__init__`` (raising :class:`~greybox.errors.GreyboxError` in one line
    when it cannot), yields the stream's items from ``__iter__`` until the stream ends, and releases the
    transport in :meth:`close`. ``address`` is what the start line names.
    """

    #: What the start line says the command reads (an address, or "stdin").
    address: object = "stdin"

    @abc.abstractmethod
    def __iter__(self) -> Iterator[Received | ConnectionChange | Idle]:
        """The items of the stream, in the order they happened."""

    @abc.abstractmethod
    def close(self) -> None:
        """Release the transport (idempotent)."""


def polled(items: queue.Queue, poll_s: float) -> Iterator[object]:
    """The items of a queue as they come (put there by a transport's thread), and an :class:`Idle` each time
    none came for ``poll_s`` seconds (so that the command stays responsive to signals and does what is due
    while the stream is quiet).

    Parameters
    ----------
    items : queue.Queue
        The queue.
    poll_s : float
        Seconds to wait for an item [s].
    """
    while True:
        try:
            yield items.get(timeout=poll_s)
        except queue.Empty:
            yield Idle(time.time())
