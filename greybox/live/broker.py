"""MQTT addresses and connections (paho-mqtt) of the live sources and sinks.

An address is ``mqtt://HOST[:PORT]/TOPIC`` (port 1883 by default; the topic may hold ``/`` and, for a
source, the wildcards ``+`` and ``#``). A connection reconnects by itself after the broker goes away
(paho's network loop, retrying within a second) and reports each loss and return. Its socket sends each
message at once (``TCP_NODELAY``); a broker does the same for its clients with ``set_tcp_nodelay true``
in its configuration (Mosquitto).
"""

from __future__ import annotations

import itertools
import os
import socket
import threading
import time
from dataclasses import dataclass
from typing import Callable
from urllib.parse import urlsplit

from ..errors import GreyboxError

__all__ = ["DEFAULT_PORT", "BrokerAddress", "parse_address", "is_address", "Connection"]

#: The MQTT port when an address gives none.
DEFAULT_PORT = 1883

_client_ids = itertools.count()


@dataclass(frozen=True)
class BrokerAddress:
    """Where a stream comes from or goes to.

    Attributes
    ----------
    host : str
        Broker host name or address.
    port : int
        Broker TCP port.
    topic : str
        MQTT topic.
    """

    host: str
    port: int
    topic: str

    def __str__(self) -> str:
        return f"mqtt://{self.host}:{self.port}/{self.topic}"


def is_address(text: str) -> bool:
    """Whether ``text`` names a broker (``mqtt://...``) rather than ``-``.

    Parameters
    ----------
    text : str
        A --source or --sink value.
    """
    return text.lower().startswith("mqtt://")


def parse_address(text: str, option: str) -> BrokerAddress:
    """The broker address of ``mqtt://HOST[:PORT]/TOPIC``.

    Parameters
    ----------
    text : str
        The address.
    option : str
        The option it came from, named in errors.

    Raises
    ------
    GreyboxError
        For a scheme other than mqtt, a missing host or topic, or a port out of range.
    """
    parts = urlsplit(text)
    if parts.scheme.lower() != "mqtt":
        raise GreyboxError(f"{option} {text}: give '-' or mqtt://HOST[:PORT]/TOPIC")
    try:
        port = parts.port or DEFAULT_PORT
    except ValueError:
        raise GreyboxError(f"{option} {text}: the port must be a number from 1 to 65535") from None
    topic = parts.path.lstrip("/")
    if not parts.hostname or not topic:
        raise GreyboxError(f"{option} {text}: the address needs a host and a topic, mqtt://HOST[:PORT]/TOPIC")
    return BrokerAddress(parts.hostname, port, topic)


def _no_delay(client, userdata, sock) -> None:
    """Send each message at once: Nagle's algorithm holds a small write back until the previous one is
    acknowledged, which with delayed acknowledgements costs up to 40 ms a message."""
    try:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    except (OSError, AttributeError):  # not a TCP socket (e.g. a websocket wrapper): leave it as it is
        pass


class Connection:
    """A paho-mqtt client connected to a broker, reconnecting by itself.

    Parameters
    ----------
    address : BrokerAddress
        The broker (its topic is not used here).
    on_message : callable, optional
        ``on_message(topic, payload, arrived_s)`` for each message of a subscription, from paho's thread.
    on_state : callable, optional
        ``on_state(connected, time_s)`` on each loss (False) and return (True) of the connection after the
        first, from paho's thread (``time_s`` is ``time.time()``).
    subscribe : str, optional
        Topic to subscribe to on every (re)connection.
    connect_timeout : float, default 10.0
        Seconds to wait for the first connection.

    Raises
    ------
    GreyboxError
        When the broker cannot be reached within ``connect_timeout``.
    """

    def __init__(self, address: BrokerAddress, *, on_message: Callable | None = None,
                 on_state: Callable | None = None, subscribe: str | None = None, connect_timeout: float = 10.0):
        import paho.mqtt.client as mqtt

        self.address = address
        self._on_message = on_message
        self._on_state = on_state
        self._subscribe = subscribe
        self._connected = threading.Event()
        self._subscribed = threading.Event()
        self._ever = False
        client_id = f"greybox-live-{os.getpid()}-{next(_client_ids)}"
        self.client = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2, client_id=client_id)
        self.client.reconnect_delay_set(min_delay=1, max_delay=2)
        self.client.on_connect = self._connected_cb
        self.client.on_disconnect = self._disconnected_cb
        self.client.on_subscribe = lambda *args: self._subscribed.set()
        self.client.on_socket_open = _no_delay
        if on_message is not None:
            self.client.on_message = lambda client, userdata, message: on_message(
                message.topic, message.payload, time.time())
        try:
            self.client.connect_async(address.host, address.port, keepalive=10)
        except (OSError, ValueError) as exc:
            raise GreyboxError(f"{address}: cannot connect ({exc})") from None
        self.client.loop_start()
        if not self._connected.wait(connect_timeout) or (subscribe and not self._subscribed.wait(connect_timeout)):
            self.close()
            raise GreyboxError(f"{address}: no broker answered within {connect_timeout:g} s")

    @property
    def connected(self) -> bool:
        """Whether the client is connected now."""
        return self._connected.is_set()

    def _connected_cb(self, client, userdata, flags, reason_code, properties=None):
        if reason_code.is_failure:
            return
        if self._subscribe:
            client.subscribe(self._subscribe, qos=0)
        self._connected.set()
        if self._ever and self._on_state is not None:
            self._on_state(True, time.time())
        self._ever = True

    def _disconnected_cb(self, client, userdata, flags, reason_code, properties=None):
        was = self._connected.is_set()
        self._connected.clear()
        if was and self._on_state is not None:
            self._on_state(False, time.time())

    def publish(self, topic: str, payload: str) -> bool:
        """Publish one message (QoS 0); False when the connection is down and the message is lost.

        Parameters
        ----------
        topic : str
            MQTT topic.
        payload : str
            The message text (UTF-8).
        """
        if not self._connected.is_set():
            return False
        info = self.client.publish(topic, payload.encode(), qos=0)
        return info.rc == 0

    def close(self) -> None:
        """Disconnect and stop the network thread (publishing what is queued first)."""
        try:
            self.client.disconnect()
        finally:
            self.client.loop_stop()
