"""MQTT addresses and connections (paho-mqtt, MQTT 5) of the live sources and sinks.

An address is ``mqtt://[USER@]HOST[:PORT]/TOPIC``, or ``mqtts://...`` for TLS (port 1883, 8883 for TLS, by
default). The topic is everything after the first ``/`` following the host, as it is: it may hold ``/`` and,
for a source, the wildcards ``+`` (one level) and ``#`` (the rest; not a URL fragment here). A password is
never taken from the address, where it would show in the process list and the logs: it comes from a file
or the environment (:func:`read_password`); an address holding one is refused.

A :class:`Connection` logs in (user name and password, TLS with a CA, a client certificate and key), with
a client id unique per host and process unless one is given (:func:`default_client_id`), and keeps an
MQTT session on the broker across losses of the connection (``clean_start`` false, a session expiry
interval): the broker holds the QoS 1 messages of the subscription while the connection is down, and the
connection holds its own unacknowledged messages (a bounded queue) until the broker is back. A refusal by
the broker (not authorised, bad user name or password) or of the TLS handshake ends the start with one
line naming it. The connection reconnects by itself after the broker goes away (paho's network loop,
retrying every 1-2 s) and reports each loss and return. Its socket sends each message at once
(``TCP_NODELAY``); a broker does the same for its clients with ``set_tcp_nodelay true`` in its
configuration (Mosquitto).
"""

from __future__ import annotations

import os
import secrets
import socket
import ssl
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable
from urllib.parse import urlsplit

from ..errors import GreyboxError

__all__ = ["DEFAULT_PORT", "DEFAULT_TLS_PORT", "PASSWORD_ENV", "BrokerAddress", "BrokerOptions", "parse_address",
           "is_address", "read_password", "default_client_id", "topic_matches", "Connection"]

#: The MQTT port when an address gives none.
DEFAULT_PORT = 1883

#: The MQTT port of ``mqtts://`` when an address gives none.
DEFAULT_TLS_PORT = 8883

#: The environment variable holding the broker password when no password file is given.
PASSWORD_ENV = "GREYBOX_MQTT_PASSWORD"

_SCHEMES = {"mqtt": False, "mqtts": True}


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
        MQTT topic (or topic filter of a source).
    tls : bool
        Whether the connection is TLS (``mqtts://``).
    username : str or None
        The user name given in the address.
    """

    host: str
    port: int
    topic: str
    tls: bool = False
    username: str | None = None

    def __str__(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"{'mqtts' if self.tls else 'mqtt'}://{host}:{self.port}/{self.topic}"


@dataclass(frozen=True)
class BrokerOptions:
    """How to log in to a broker and what the connection keeps.

    Attributes
    ----------
    username : str or None
        User name (over one in the address).
    password : str or None
        Password (never shown: not in the repr).
    ca_file : str or None
        CA certificate (PEM) that signed the broker's certificate; with TLS and none, the system's CAs.
    cert_file, key_file : str or None
        Client certificate and its key (PEM), for brokers that require one.
    client_id : str or None
        Client id; default :func:`default_client_id`. The source's connection appends ``-in``, the sink's
        ``-out``. Give a fixed one so that a restarted service takes up its session on the broker.
    qos : int
        QoS of the subscription and of the messages published (0 or 1).
    session_expiry_s : int
        Seconds the broker keeps the session (subscription, queued messages) after the connection is lost.
    queue_size : int
        Most messages published and not yet acknowledged that the connection holds (while the broker is
        away); beyond, a message is not published and counted as lost.
    connect_timeout : float
        Seconds to wait for the broker at the start.
    """

    username: str | None = None
    password: str | None = field(default=None, repr=False)
    ca_file: str | None = None
    cert_file: str | None = None
    key_file: str | None = None
    client_id: str | None = None
    qos: int = 1
    session_expiry_s: int = 3600
    queue_size: int = 100_000
    connect_timeout: float = 10.0

    def __post_init__(self):
        if self.qos not in (0, 1):
            raise GreyboxError(f"--qos {self.qos}: give 0 or 1")
        if self.key_file and not self.cert_file:
            raise GreyboxError("--tls-key needs --tls-cert (the client certificate it belongs to)")
        if self.client_id is not None and not (0 < len(self.client_id) <= 200 and self.client_id.isprintable()):
            raise GreyboxError(f"--client-id {self.client_id!r}: give 1 to 200 printable characters")


def is_address(text: str) -> bool:
    """Whether ``text`` names a broker (``mqtt://...`` or ``mqtts://...``) rather than ``-``.

    Parameters
    ----------
    text : str
        A --source or --sink value.
    """
    return text.lower().startswith(("mqtt://", "mqtts://"))


def _check_topic(topic: str, option: str, wildcards: bool) -> None:
    levels = topic.split("/")
    for k, level in enumerate(levels):
        if ("+" in level and level != "+") or ("#" in level and (level != "#" or k != len(levels) - 1)):
            raise GreyboxError(f"{option}: topic {topic!r}: '+' must be a whole level and '#' the whole last level")
    if not wildcards and ("+" in levels or "#" in levels):
        raise GreyboxError(f"{option}: topic {topic!r}: a topic to publish on cannot hold the wildcards + or #")
    if "\0" in topic:
        raise GreyboxError(f"{option}: topic {topic!r} holds a NUL character")


def parse_address(text: str, option: str, *, wildcards: bool = True) -> BrokerAddress:
    """The broker address of ``mqtt[s]://[USER@]HOST[:PORT]/TOPIC``.

    Parameters
    ----------
    text : str
        The address.
    option : str
        The option it came from, named in errors.
    wildcards : bool, default True
        Whether the topic may hold ``+`` and ``#`` (a source's filter; not a sink's topic).

    Raises
    ------
    GreyboxError
        For another scheme, a missing host or topic, a port out of range, a password in the address, or a
        topic with misplaced (or, without ``wildcards``, any) wildcards.
    """
    scheme, sep, rest = text.partition("://")
    if not sep or scheme.lower() not in _SCHEMES:
        raise GreyboxError(f"{option} {text}: give '-' or mqtt://HOST[:PORT]/TOPIC (mqtts:// for TLS)")
    tls = _SCHEMES[scheme.lower()]
    netloc, _, topic = rest.partition("/")
    userinfo, at, hostport = netloc.rpartition("@")
    shown = f"{scheme}://{hostport}/{topic}"  # never the user information in a message
    username = None
    if at:
        username, colon, _ = userinfo.partition(":")
        if colon:
            raise GreyboxError(f"{option} {scheme}://{username}:***@{hostport}/{topic}: a password in the address "
                               f"would show in the process list and the logs; give --password-file FILE or the "
                               f"environment variable {PASSWORD_ENV}")
        if not username:
            raise GreyboxError(f"{option} {shown}: an empty user name before '@'")
    parts = urlsplit(f"//{hostport}")
    try:
        port = parts.port or (DEFAULT_TLS_PORT if tls else DEFAULT_PORT)
    except ValueError:
        raise GreyboxError(f"{option} {shown}: the port must be a number from 1 to 65535") from None
    if not parts.hostname or not topic:
        raise GreyboxError(f"{option} {shown}: the address needs a host and a topic, mqtt://HOST[:PORT]/TOPIC")
    _check_topic(topic, option, wildcards)
    return BrokerAddress(parts.hostname, port, topic, tls=tls, username=username)


def read_password(path=None, *, environ=None, variable: str = PASSWORD_ENV,
                  option: str = "--password-file") -> str | None:
    """A password: the first line of ``path``, else the environment variable ``variable``.

    Parameters
    ----------
    path : path-like, optional
        A file holding the password on its first line (readable by the service's user alone).
    environ : mapping, optional
        The environment (default ``os.environ``).
    variable : str, default :data:`PASSWORD_ENV`
        The environment variable read without ``path`` (the broker's by default).
    option : str, default "--password-file"
        The option that gave ``path``, named in errors.

    Returns
    -------
    str or None
        None when neither gives one.

    Raises
    ------
    GreyboxError
        When the file cannot be read or its first line is empty.
    """
    if path is None:
        value = (os.environ if environ is None else environ).get(variable)
        return value or None
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise GreyboxError(f"{option} {path}: cannot read it ({getattr(exc, 'strerror', None) or exc})") \
            from None
    lines = text.splitlines()
    if not lines or not lines[0]:
        raise GreyboxError(f"{option} {path}: the first line (the password) is empty")
    return lines[0]


def default_client_id() -> str:
    """A client id unique per host and process: ``greybox-<host>-<pid>-<random>``.

    The random part keeps apart two processes of the same id on hosts of the same name (containers, where
    every service may be PID 1).
    """
    host = "".join(ch for ch in socket.gethostname() if ch.isalnum() or ch in "-_.")[:40] or "host"
    return f"greybox-{host}-{os.getpid()}-{secrets.token_hex(4)}"


def topic_matches(topic_filter: str, topic: str) -> bool:
    """Whether ``topic`` is received by a subscription to ``topic_filter`` (wildcards ``+`` and ``#``).

    Parameters
    ----------
    topic_filter : str
        The subscription.
    topic : str
        A topic (no wildcards).
    """
    from paho.mqtt.client import topic_matches_sub

    return topic_matches_sub(topic_filter, topic)


def _no_delay(client, userdata, sock) -> None:
    """Send each message at once: Nagle's algorithm holds a small write back until the previous one is
    acknowledged, which with delayed acknowledgements costs up to 40 ms a message."""
    try:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    except (OSError, AttributeError):  # not a TCP socket (e.g. a websocket wrapper): leave it as it is
        pass


class Connection:
    """A paho-mqtt client logged in to a broker, keeping its session, reconnecting by itself.

    Parameters
    ----------
    address : BrokerAddress
        The broker (its topic is not used here).
    options : BrokerOptions, optional
        Log-in, TLS, client id, QoS, session, queue.
    role : str, default "out"
        Appended to the client id (``<id>-<role>``), so that a source and a sink of one command differ.
    on_message : callable, optional
        ``on_message(topic, payload, arrived_s)`` for each message of a subscription, from paho's thread.
    on_state : callable, optional
        ``on_state(connected, time_s, reason)`` on each loss (False) and return (True) of the connection after
        the first, from paho's thread (``time_s`` is ``time.time()``, ``reason`` the broker's or paho's words).
    subscribe : str, optional
        Topic filter to subscribe to on every (re)connection.
    will : tuple of (str, str), optional
        ``(topic, text)`` the broker publishes (QoS 1, retained) when the connection is lost without a goodbye.

    Attributes
    ----------
    client_id : str
        The client id used.
    published : int
        Messages handed to the connection.
    acknowledged : int
        Messages the broker acknowledged (all of them at QoS 0 once sent).
    refused : int
        Messages not published because the queue was full.

    Raises
    ------
    GreyboxError
        When the TLS files cannot be read, the broker cannot be reached within the connect timeout, or it
        refuses the connection or the subscription.
    """

    def __init__(self, address: BrokerAddress, options: BrokerOptions | None = None, *, role: str = "out",
                 on_message: Callable | None = None, on_state: Callable | None = None, subscribe: str | None = None,
                 will: tuple[str, str] | None = None):
        import paho.mqtt.client as mqtt
        from paho.mqtt.packettypes import PacketTypes
        from paho.mqtt.properties import Properties

        options = options or BrokerOptions()
        self.address = address
        self.options = options
        self._on_state = on_state
        self._subscribe = subscribe
        self._connected = threading.Event()
        self._answered = threading.Event()
        self._subscribed = threading.Event()
        self._refusal: str | None = None
        self._ever = False
        self._lock = threading.Lock()  # of the counters only: never held while paho runs (its own locks)
        self.published = self.acknowledged = self.refused = 0
        self.client_id = f"{options.client_id or default_client_id()}-{role}"
        self.client = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2, client_id=self.client_id,
                                  protocol=mqtt.MQTTv5)
        self.client.reconnect_delay_set(min_delay=1, max_delay=2)
        self.client.max_queued_messages_set(options.queue_size)
        self.client.on_connect = self._connected_cb
        self.client.on_disconnect = self._disconnected_cb
        self.client.on_subscribe = self._subscribed_cb
        self.client.on_publish = self._published_cb
        self.client.on_socket_open = _no_delay
        username = options.username or address.username
        if options.username and address.username and options.username != address.username:
            raise GreyboxError(f"{address}: the user name of the address and --username differ")
        if username:
            self.client.username_pw_set(username, options.password)
        elif options.password is not None:
            raise GreyboxError("a broker password needs a user name: give --username or mqtt://USER@HOST/TOPIC")
        if address.tls:
            self._tls(options)
        elif options.ca_file or options.cert_file:
            raise GreyboxError(f"{address}: TLS files given for a plain connection; use mqtts://")
        if will is not None:
            self.client.will_set(will[0], will[1].encode(), qos=1, retain=True)
        if on_message is not None:
            self.client.on_message = lambda client, userdata, message: on_message(
                message.topic, message.payload, time.time())
        properties = Properties(PacketTypes.CONNECT)
        properties.SessionExpiryInterval = int(options.session_expiry_s)
        self._first_connect(properties)

    def _tls(self, options: BrokerOptions) -> None:
        for name, path in (("--tls-ca", options.ca_file), ("--tls-cert", options.cert_file),
                           ("--tls-key", options.key_file)):
            if path and not Path(path).is_file():
                raise GreyboxError(f"{name} {path}: no such file")
        try:
            self.client.tls_set(ca_certs=options.ca_file, certfile=options.cert_file, keyfile=options.key_file,
                                cert_reqs=ssl.CERT_REQUIRED)
        except (ssl.SSLError, OSError, ValueError) as exc:
            raise GreyboxError(f"{self.address}: the TLS files cannot be used ({exc})") from None

    def _first_connect(self, properties) -> None:
        """Connect (retrying while the broker is not there, until the connect timeout), then start the loop."""
        timeout = self.options.connect_timeout
        deadline = time.monotonic() + timeout
        while True:
            try:
                self.client.connect(self.address.host, self.address.port, keepalive=10, clean_start=False,
                                    properties=properties)
                break
            except ssl.SSLError as exc:
                raise GreyboxError(f"{self.address}: the TLS handshake failed ({exc.reason or exc})") from None
            except (OSError, ValueError) as exc:
                if isinstance(exc, ValueError) or time.monotonic() + 0.2 > deadline:
                    raise GreyboxError(f"{self.address}: no broker answered within {timeout:g} s "
                                       f"({getattr(exc, 'strerror', None) or exc})") from None
                time.sleep(0.2)
        self.client.loop_start()
        left = max(0.0, deadline - time.monotonic()) + 1.0
        if not self._answered.wait(left):
            self.close()
            raise GreyboxError(f"{self.address}: no broker answered within {timeout:g} s")
        if self._refusal is not None:
            self.close()
            raise GreyboxError(f"{self.address}: the broker refused the connection: {self._refusal}")
        if self._subscribe and not self._subscribed.wait(left):
            self.close()
            raise GreyboxError(f"{self.address}: the broker did not confirm the subscription within {timeout:g} s")
        if self._refusal is not None:
            self.close()
            raise GreyboxError(f"{self.address}: the broker refused the subscription to {self._subscribe}: "
                               f"{self._refusal}")

    @property
    def connected(self) -> bool:
        """Whether the client is connected now."""
        return self._connected.is_set()

    @property
    def queued(self) -> int:
        """Messages published and not yet acknowledged by the broker."""
        with self._lock:  # the acknowledgement may be counted before the message (paho's thread is quicker)
            return max(0, self.published - self.acknowledged)

    def _connected_cb(self, client, userdata, flags, reason_code, properties=None):
        if reason_code.is_failure:
            if not self._ever:
                self._refusal = str(reason_code)
                self._answered.set()
                client.disconnect()
            return
        if self._subscribe:
            client.subscribe(self._subscribe, qos=self.options.qos)
        self._connected.set()
        self._answered.set()
        if self._ever and self._on_state is not None:
            self._on_state(True, time.time(), "")
        self._ever = True

    def _subscribed_cb(self, client, userdata, mid, reason_codes, properties=None):
        failed = [code for code in reason_codes if code.is_failure]
        if failed and self._refusal is None and not self._subscribed.is_set():
            self._refusal = str(failed[0])
        self._subscribed.set()

    def _published_cb(self, client, userdata, mid, reason_code=None, properties=None):
        with self._lock:
            self.acknowledged += 1

    def _disconnected_cb(self, client, userdata, flags, reason_code, properties=None):
        was = self._connected.is_set()
        self._connected.clear()
        if was and self._on_state is not None:
            self._on_state(False, time.time(), str(reason_code))

    def publish(self, topic: str, payload: str, *, retain: bool = False) -> bool:
        """Publish one message at the connection's QoS; False when it is not taken.

        At QoS 1 a message published while the broker is away is queued and sent once it is back; False
        when the queue is full (or, at QoS 0, when the connection is down).

        Parameters
        ----------
        topic : str
            MQTT topic.
        payload : str
            The message text (UTF-8).
        retain : bool, default False
            Whether the broker keeps it for later subscribers.
        """
        qos = self.options.qos
        if qos == 0 and not self._connected.is_set():
            return False
        from paho.mqtt.enums import MQTTErrorCode

        info = self.client.publish(topic, payload.encode(), qos=qos, retain=retain)
        # at QoS 1, "no connection" means queued: paho sends it once the connection is back
        taken = info.rc == MQTTErrorCode.MQTT_ERR_SUCCESS or (qos and info.rc == MQTTErrorCode.MQTT_ERR_NO_CONN)
        with self._lock:
            if taken:
                self.published += 1
            else:
                self.refused += 1
        return bool(taken)

    def wait_for_queue(self, timeout_s: float) -> bool:
        """Wait (bounded) until the broker acknowledged every message published; whether it did.

        Parameters
        ----------
        timeout_s : float
            Most seconds to wait.
        """
        deadline = time.monotonic() + timeout_s
        while self.queued and time.monotonic() < deadline:
            time.sleep(0.01)
        return not self.queued

    def close(self) -> None:
        """Disconnect (a goodbye: the broker does not publish the will) and stop the network thread."""
        try:
            self.client.disconnect()
        finally:
            self.client.loop_stop()
