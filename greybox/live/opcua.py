"""An OPC UA server's axis variables as the source of ``greybox live`` (``--source opc.tcp://HOST:PORT``).

Many controllers (SINUMERIK with its OPC UA server, Heidenhain) publish axis variables on an OPC UA server
rather than on MQTT. :class:`OpcUaSource` logs in (anonymous, or a user name and password; optionally a
security policy with a client certificate), checks at the start that every variable named exists, and
subscribes to them: data-change notifications at a sampling interval, a queue per variable so that none is
lost between two publishing intervals, and a notification for every new source time stamp (also for an
unchanged value). The values are assembled into samples (:mod:`greybox.live.opcua_samples`) and given as
JSON messages of the stream's columns, so they take the same path as the messages of every other source.

The client (asyncua) runs its event loop in a thread of its own. A lost connection (the server restarted,
the network gone) is given as a :class:`~greybox.live.source_base.ConnectionChange`; the client reconnects
every 1 to 2 s and re-creates the subscription on the server, and says when it is back.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import json
import logging
import queue
import threading
import time
from dataclasses import dataclass, field
from typing import Iterator, Mapping
from urllib.parse import urlsplit

from ..errors import GreyboxError
from .opcua_samples import SampleAssembler
from .source_base import ConnectionChange, Idle, Received, Source, polled

__all__ = ["DEFAULT_PORT", "OPCUA_PASSWORD_ENV", "SECURITY_MODES", "SECURITY_POLICIES", "OpcUaAddress",
           "OpcUaOptions", "is_opcua_address", "parse_opcua_address", "parse_nodes", "OpcUaSource"]

#: Port of ``opc.tcp://HOST`` without one.
DEFAULT_PORT = 4840

#: The environment variable holding the OPC UA user's password when no ``--opcua-password-file`` is given.
OPCUA_PASSWORD_ENV = "GREYBOX_OPCUA_PASSWORD"

#: The message security modes taken by ``--opcua-security POLICY,MODE``.
SECURITY_MODES = ("Sign", "SignAndEncrypt")

#: The security policies taken (those asyncua implements with a certificate).
SECURITY_POLICIES = ("Basic256Sha256", "Aes128Sha256RsaOaep", "Aes256Sha256RsaPss")

#: What the return of the server means for the stream (said after it).
_RESUMED = ("the subscription is made anew; values the server changed meanwhile are missing, a gap in the time stamps "
            "(the model's state re-initialised)")

# asyncua reports its reconnection attempts (and their tracebacks) through logging: the source says them in its own
# lines instead, so the library's records go nowhere unless the application configures a handler for them.
logging.getLogger("asyncua").addHandler(logging.NullHandler())
logging.getLogger("asyncua").propagate = False


@dataclass(frozen=True)
class OpcUaAddress:
    """An OPC UA server.

    Attributes
    ----------
    host : str
        Server host name or address.
    port : int
        TCP port.
    path : str
        The endpoint's path ("" for none).
    username : str or None
        The user name given in the address.
    """

    host: str
    port: int
    path: str = ""
    username: str | None = None

    @property
    def url(self) -> str:
        """The endpoint URL without the user name."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"opc.tcp://{host}:{self.port}" + (f"/{self.path}" if self.path else "")

    def __str__(self) -> str:
        return self.url


@dataclass(frozen=True)
class OpcUaOptions:
    """How to log in to an OPC UA server and what to subscribe to.

    Attributes
    ----------
    nodes : mapping of str to str
        ``{column: node id}``: the message column each variable gives (``time_s``, ``position_mm``, ...;
        ``X_position_mm`` for an axis of a machine) and the node id of the variable (``ns=2;s=X.Position``).
    password : str or None
        Password of the user named in the address (never shown: not in the repr).
    security : str or None
        ``POLICY,MODE``, e.g. ``Basic256Sha256,SignAndEncrypt``; None for no security.
    cert_file, key_file : str or None
        Client certificate and its key (PEM or DER), needed with ``security``.
    server_cert_file : str or None
        The server's certificate, to accept that one only.
    sampling_ms : float
        Sampling interval requested for each variable [ms] (0: as fast as the server samples).
    publishing_ms : float
        Publishing interval of the subscription [ms].
    queue_size : int
        Values the server holds per variable between two publishes.
    connect_timeout : float
        Seconds to wait for the server at the start.
    stamp_tolerance_ms : float
        Largest difference between the source time stamps of one sample's variables [ms]
        (:class:`~greybox.live.opcua_samples.SampleAssembler`); 0: one stamp per sample.
    """

    nodes: Mapping[str, str] = field(default_factory=dict)
    password: str | None = field(default=None, repr=False)
    security: str | None = None
    cert_file: str | None = None
    key_file: str | None = None
    server_cert_file: str | None = None
    sampling_ms: float = 0.0
    publishing_ms: float = 20.0
    queue_size: int = 1000
    connect_timeout: float = 10.0
    stamp_tolerance_ms: float = 0.5

    def __post_init__(self):
        if not self.stamp_tolerance_ms >= 0.0:
            raise GreyboxError(f"--opcua-stamp-tolerance-ms {self.stamp_tolerance_ms}: give 0 or more milliseconds")
        if not self.nodes:
            raise GreyboxError("an opc.tcp:// source needs --node COLUMN=NODEID for each variable (time_s, "
                               "position_mm, velocity_mm_s, current_A, ...)")
        if len(set(self.nodes.values())) != len(self.nodes):
            raise GreyboxError("--node: two columns name the same node id; give each variable one column")
        if self.security is not None:
            policy, _, mode = self.security.partition(",")
            if policy not in SECURITY_POLICIES or mode not in SECURITY_MODES:
                raise GreyboxError(f"--opcua-security {self.security}: give POLICY,MODE with POLICY one of "
                                   f"{', '.join(SECURITY_POLICIES)} and MODE one of {', '.join(SECURITY_MODES)}")
            if not (self.cert_file and self.key_file):
                raise GreyboxError(f"--opcua-security {self.security}: needs the client certificate and its key "
                                   "(--opcua-cert, --opcua-key)")
        if self.sampling_ms < 0 or self.publishing_ms <= 0 or self.queue_size < 1:
            raise GreyboxError("--sampling-ms must be >= 0, --publishing-ms > 0 and the queue size >= 1")


def is_opcua_address(text: str) -> bool:
    """Whether ``text`` names an OPC UA server (``opc.tcp://...``).

    Parameters
    ----------
    text : str
        A --source value.
    """
    return text.lower().startswith("opc.tcp://")


def parse_opcua_address(text: str, option: str = "--source") -> OpcUaAddress:
    """The server of ``opc.tcp://[USER@]HOST[:PORT][/PATH]``.

    Parameters
    ----------
    text : str
        The address.
    option : str, default "--source"
        The option it came from, named in errors.

    Raises
    ------
    GreyboxError
        For another scheme, a missing host, a port out of range or a password in the address.
    """
    scheme, sep, rest = text.partition("://")
    if not sep or scheme.lower() != "opc.tcp":
        raise GreyboxError(f"{option} {text}: give opc.tcp://HOST[:PORT]")
    netloc, _, path = rest.partition("/")
    userinfo, at, hostport = netloc.rpartition("@")
    shown = f"opc.tcp://{hostport}" + (f"/{path}" if path else "")
    username = None
    if at:
        username, colon, _ = userinfo.partition(":")
        if colon:
            raise GreyboxError(f"{option} opc.tcp://{username}:***@{hostport}: a password in the address would show "
                               f"in the process list and the logs; give --opcua-password-file FILE or "
                               f"{OPCUA_PASSWORD_ENV}")
        if not username:
            raise GreyboxError(f"{option} {shown}: an empty user name before '@'")
    parts = urlsplit(f"//{hostport}")
    try:
        port = parts.port or DEFAULT_PORT
    except ValueError:
        raise GreyboxError(f"{option} {shown}: the port must be a number from 1 to 65535") from None
    if not parts.hostname:
        raise GreyboxError(f"{option} {shown}: the address needs a host, opc.tcp://HOST[:PORT]")
    return OpcUaAddress(parts.hostname, port, path, username)


def parse_nodes(items) -> dict[str, str]:
    """The ``{column: node id}`` of ``--node COLUMN=NODEID`` options.

    Parameters
    ----------
    items : iterable of str
        ``COLUMN=NODEID`` each, e.g. ``position_mm=ns=2;s=Axis.X.Position``.

    Raises
    ------
    GreyboxError
        For an item without ``=``, an empty column or node id, or a column given twice.
    """
    nodes: dict[str, str] = {}
    for item in items:
        column, sep, node = item.partition("=")
        column, node = column.strip(), node.strip()
        if not sep or not column or not node:
            raise GreyboxError(f"--node {item}: give COLUMN=NODEID, e.g. position_mm=ns=2;s=Axis.X.Position")
        if column in nodes:
            raise GreyboxError(f"--node {item}: the column {column} is given twice")
        nodes[column] = node
    return nodes


def _status_name(exc: BaseException) -> str:
    code = getattr(exc, "code", None)
    if code is not None:
        from asyncua import ua

        return ua.StatusCode(code).name
    return str(exc) or type(exc).__name__


async def _application_uri(path) -> str | None:
    """The application URI a certificate names (its subject alternative name URI), which the client must give."""
    from asyncua.crypto import uacrypto
    from cryptography import x509

    certificate = await uacrypto.load_certificate(path)
    try:
        names = certificate.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    except x509.ExtensionNotFound:
        return None
    uris = names.get_values_for_type(x509.UniformResourceIdentifier)
    return uris[0] if uris else None


class _Handler:
    """The subscription's callbacks: each value, with its variable's column and source time stamp, to the queue."""

    def __init__(self, columns: Mapping, put):
        self.columns = columns
        self.put = put

    def datachange_notification(self, node, val, data) -> None:
        value = data.monitored_item.Value
        stamp = value.SourceTimestamp or value.ServerTimestamp
        self.put(("value", self.columns[node.nodeid], stamp, val))

    def status_change_notification(self, status) -> None:
        """The server's word on the subscription (lost at a restart): the connection watch says it."""


class OpcUaSource(Source):
    """Samples of an OPC UA server's variables, in time-stamp order, as the messages of a stream.

    Parameters
    ----------
    address : OpcUaAddress
        The server.
    options : OpcUaOptions
        The variables, the log-in, the security, the subscription's intervals.
    poll_s : float, default 0.1
        How long the iteration waits for a value before it gives an :class:`Idle`.

    Raises
    ------
    GreyboxError
        When the server cannot be reached, refuses the log-in, or lacks a variable named (one line each).
    """

    def __init__(self, address: OpcUaAddress, options: OpcUaOptions, *, poll_s: float = 0.1):
        self.address = address
        self.options = options
        self.poll_s = float(poll_s)
        self._queue: queue.Queue = queue.Queue()
        self._assembler = SampleAssembler(list(options.nodes), tolerance_s=1e-3 * options.stamp_tolerance_ms)
        self._count = 0
        self._client = None
        self._watch = None
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, name="greybox-opcua", daemon=True)
        self._thread.start()
        try:
            try:  # each step of the start is bounded by the connect timeout: this bound is the last resort
                self._call(self._open(), 3 * options.connect_timeout + 10.0)
            except concurrent.futures.TimeoutError:
                raise GreyboxError(f"--source {address}: the server did not complete the start (log-in, checking "
                                   f"the variables, subscribing) within {3 * options.connect_timeout + 10.0:g} s") \
                    from None
        except BaseException:
            self.close()
            raise

    def _call(self, coroutine, timeout: float):
        return asyncio.run_coroutine_threadsafe(coroutine, self._loop).result(timeout)

    async def _open(self) -> None:
        from asyncua import Client, ua

        options, where = self.options, f"--source {self.address}"
        client = Client(self.address.url, timeout=max(1.0, min(options.connect_timeout, 4.0)), watchdog_intervall=1.0,
                        auto_reconnect=True, reconnect_max_delay=2.0)
        username = self.address.username
        if username:
            client.set_user(username)
            client.set_password(options.password or "")
        try:
            if options.server_cert_file:  # before the security is set: the endpoints are read without it
                await self._check_server_certificate(client)
            await self._secure(client)
            await asyncio.wait_for(client.connect(), options.connect_timeout)
        except GreyboxError:
            await self._abandon(client)
            raise
        except (OSError, asyncio.TimeoutError) as exc:
            await self._abandon(client)
            raise GreyboxError(f"{where}: no OPC UA server answered within {options.connect_timeout:g} s "
                               f"({_status_name(exc)})") from None
        except ua.UaStatusCodeError as exc:
            await self._abandon(client)
            raise GreyboxError(f"{where}: the server refused the connection: {_status_name(exc)}") from None
        except Exception as exc:  # asyncua raises plain errors for a failed handshake (policy, certificate)
            await self._abandon(client)
            raise GreyboxError(f"{where}: the connection failed: {_status_name(exc)}") from None
        self._client = client
        columns = {}
        for column, text in options.nodes.items():
            try:
                node = client.get_node(text)
            except (ValueError, ua.UaError) as exc:
                raise GreyboxError(f"--node {column}={text}: not a node id ({exc})") from None
            try:
                await node.read_data_value()
            except ua.UaStatusCodeError as exc:
                raise GreyboxError(f"--node {column}={text}: no such variable on {self.address} "
                                   f"({_status_name(exc)})") from None
            columns[node.nodeid] = column
        requests = []
        for handle, nodeid in enumerate(columns, start=1):
            parameters = ua.MonitoringParameters(
                ClientHandle=handle, SamplingInterval=options.sampling_ms, QueueSize=options.queue_size,
                DiscardOldest=True, Filter=ua.DataChangeFilter(Trigger=ua.DataChangeTrigger.StatusValueTimestamp))
            requests.append(ua.MonitoredItemCreateRequest(
                ItemToMonitor=ua.ReadValueId(NodeId=nodeid, AttributeId=ua.AttributeIds.Value),
                MonitoringMode=ua.MonitoringMode.Reporting, RequestedParameters=parameters))
        subscription = await client.create_subscription(options.publishing_ms, _Handler(columns, self._queue.put))
        results = await subscription.create_monitored_items(requests)
        for column, result in zip(columns.values(), results):
            if isinstance(result, ua.StatusCode):
                raise GreyboxError(f"--node {column}={options.nodes[column]}: the server refused to watch it "
                                   f"({result.name})")
        self._watch = asyncio.ensure_future(self._watch_state())

    async def _secure(self, client) -> None:
        """Set the security policy with the client's certificate (and the server's, when pinned)."""
        options = self.options
        if not options.security:
            return
        files = [options.cert_file, options.key_file] + ([options.server_cert_file] if options.server_cert_file
                                                         else [])
        try:
            client.application_uri = await _application_uri(options.cert_file) or client.application_uri
            await client.set_security_string(",".join([options.security, *files]))
        except (OSError, ValueError) as exc:
            raise GreyboxError(f"--opcua-security {options.security}: cannot load the certificates ({exc})") from None

    async def _check_server_certificate(self, client) -> None:
        """Refuse a server whose endpoints do not show the certificate of ``--opcua-server-cert`` (a server that
        cannot decrypt what is sent for another certificate would otherwise just not answer)."""
        from asyncua.crypto import uacrypto
        from cryptography.hazmat.primitives.serialization import Encoding

        options = self.options
        pinned = (await uacrypto.load_certificate(options.server_cert_file)).public_bytes(Encoding.DER)
        endpoints = await asyncio.wait_for(client.connect_and_get_server_endpoints(), options.connect_timeout)
        if not any(bytes(endpoint.ServerCertificate or b"").startswith(pinned) for endpoint in endpoints):
            raise GreyboxError(f"--source {self.address}: the server's certificate is not the one of "
                               f"--opcua-server-cert {options.server_cert_file}; refused")

    @staticmethod
    async def _abandon(client) -> None:
        try:
            await asyncio.wait_for(client.disconnect(), 2.0)
        except Exception:  # nothing to close: the connection never was
            pass

    async def _watch_state(self) -> None:
        """Say each loss and return of the connection (asyncua reconnects by itself)."""
        from asyncua.client.ua_client import UaClientState

        connected = True
        while True:
            await asyncio.sleep(0.05)
            now = self._client.uaclient.state is UaClientState.CONNECTED
            if now != connected:
                connected = now
                self._queue.put(ConnectionChange(now, time.time(), "" if now else "the connection to the server closed",
                                                 peer="OPC UA server", after=_RESUMED if now else ""))

    def __iter__(self) -> Iterator[Received | ConnectionChange | Idle]:
        for item in polled(self._queue, self.poll_s):
            if isinstance(item, Idle):
                yield item
                continue
            changes = []  # the values that came meanwhile taken at once, their samples given first
            while True:
                if isinstance(item, ConnectionChange):
                    changes.append(item)
                else:
                    _, column, stamp, value = item
                    self._assembler.add(column, stamp, value)
                try:
                    item = self._queue.get_nowait()
                except queue.Empty:
                    break
            arrived = time.time()
            for stamp, columns in self._assembler.take():
                self._count += 1
                when = stamp.isoformat() if hasattr(stamp, "isoformat") else stamp
                yield Received(json.dumps(columns, default=str), f"message {self._count} of {self.address} "
                               f"(source time {when})", arrived)
            yield from changes

    def close(self) -> None:
        """Disconnect from the server and stop the client's thread (idempotent)."""
        if self._loop.is_closed():
            return
        if self._client is not None:
            if self._watch is not None:
                self._loop.call_soon_threadsafe(self._watch.cancel)
            try:
                self._call(self._abandon(self._client), 5.0)
            except Exception:  # the thread is stopped below in any case
                pass
            self._client = None
        self._loop.call_soon_threadsafe(self._loop.stop)
        self._thread.join(5.0)
        if not self._thread.is_alive():
            self._loop.close()
