"""An asyncua OPC UA server in a thread of the test process, on a free loopback port: one axis's variables
(time, position, velocity, current) under ``ns=2;s=X.<name>``, written one sample at a time as a controller
writes them (every variable of a sample with one source time stamp)."""

from __future__ import annotations

import asyncio
import datetime
import ipaddress
import logging
import threading
from pathlib import Path

from live_helpers import free_port

#: The variables of an axis of the test server: ``{column: name}``; the node ids are ``ns=2;s=<axis>.<name>``.
VARIABLES = {"time_s": "Time", "position_mm": "Position", "velocity_mm_s": "Velocity", "current_A": "Current"}

logging.getLogger("asyncua").addHandler(logging.NullHandler())
logging.getLogger("asyncua").propagate = False


class _Users:
    """Anonymous log-ins, and the user ``user`` with the password ``secret``; any other user is refused."""

    def get_user(self, iserver, username=None, password=None, certificate=None):
        from asyncua.crypto.permission_rules import User, UserRole

        return User(role=UserRole.User) if username is None or (username, password) == ("user", "secret") else None


class Axis:
    """The variables of one axis on the server, written one sample at a time as a controller writes them (every
    variable of a sample with one source time stamp)."""

    def __init__(self, server: "OpcUaServer", name: str, nodes: dict):
        self.server = server
        self.name = name
        self.nodes = nodes
        self.text = set()  # the columns holding text now

    def node_options(self, columns=VARIABLES) -> list[str]:
        """``--node COLUMN=NODEID`` options of the axis's variables."""
        return [item for column in columns for item in ("--node", f"{column}=ns=2;s={self.name}.{VARIABLES[column]}")]

    def node_ids(self, columns=VARIABLES) -> dict[str, str]:
        return {column: f"ns=2;s={self.name}.{VARIABLES[column]}" for column in columns}

    def publish_stamped(self, log, stamps: dict, start: int = 0, stop: int | None = None, *, every: int = 5) -> None:
        """Write the samples ``start:stop`` of an axis log as :meth:`publish` does, only the columns of ``stamps``,
        each value with its column's source time stamp ``stamps[column][k]`` [s since 1970] (a server that stamps
        each variable as it writes it)."""
        columns = {"time_s": log.time, "position_mm": log.position, "velocity_mm_s": log.velocity,
                   "current_A": log.effort}

        async def run():
            for k in range(start, len(log) if stop is None else stop):
                await self._write({column: float(columns[column][k]) for column in stamps},
                                  {column: float(values[k]) for column, values in stamps.items()})
                if (k + 1) % every == 0:
                    await asyncio.sleep(0.001)

        self.server.run(run(), timeout=120.0)

    async def _write(self, values: dict, stamps: dict | None = None):
        """Write ``{column: value}``, with one source time stamp or each column's of ``stamps`` ([s since 1970])."""
        from asyncua import ua

        self.server.stamp += datetime.timedelta(microseconds=1)
        for column, value in values.items():
            stamp = self.server.stamp if stamps is None else \
                datetime.datetime.fromtimestamp(stamps[column], tz=datetime.timezone.utc)
            variant = ua.Variant(value, ua.VariantType.String if isinstance(value, str) else ua.VariantType.Double)
            if isinstance(value, str) or column in self.text:  # the server takes another type after a null value
                self.text.symmetric_difference_update({column} if isinstance(value, str) != (column in self.text)
                                                      else set())
                await self.server.server.write_attribute_value(self.nodes[column].nodeid, ua.DataValue(
                    StatusCode=ua.StatusCode(ua.StatusCodes.BadNoData), SourceTimestamp=stamp))
            await self.server.server.write_attribute_value(self.nodes[column].nodeid,
                                                           ua.DataValue(variant, SourceTimestamp=stamp))

    def write(self, values: dict) -> None:
        """Write one sample: ``{column: value}`` with one source time stamp."""
        self.server.run(self._write(values))

    def publish(self, log, start: int = 0, stop: int | None = None, *, every: int = 5) -> None:
        """Write the samples ``start:stop`` of an axis log, one sample at a time, pausing 1 ms after ``every``
        samples (the server publishes meanwhile, as it does between a controller's cycles; written without a
        pause, more samples than a variable's queue holds would pile up before the next publish)."""
        columns = {"time_s": log.time, "position_mm": log.position, "velocity_mm_s": log.velocity,
                   "current_A": log.effort}

        async def run():
            for k in range(start, len(log) if stop is None else stop):
                await self._write({column: float(values[k]) for column, values in columns.items()})
                if (k + 1) % every == 0:
                    await asyncio.sleep(0.001)

        self.server.run(run(), timeout=120.0)


class OpcUaServer:
    """A running asyncua server (anonymous log-ins, and ``user``/``secret``; no security, or Basic256Sha256 with
    SignAndEncrypt and the certificates it makes in ``folder``), in a thread of its own.

    Parameters
    ----------
    folder : path-like
        Where the certificates go.
    port : int, optional
        Default a free one.
    """

    def __init__(self, folder, port: int | None = None):
        self.folder = Path(folder)
        self.port = port or free_port()
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        self.server = None
        self.axes = 0
        self.stamp = datetime.datetime(2026, 1, 1, tzinfo=datetime.timezone.utc)

    @property
    def url(self) -> str:
        return f"opc.tcp://127.0.0.1:{self.port}"

    def run(self, coroutine, timeout: float = 30.0):
        return asyncio.run_coroutine_threadsafe(coroutine, self.loop).result(timeout)

    async def _init(self):
        from asyncua import Server, ua

        server = Server(user_manager=_Users())
        await server.init()
        server.set_endpoint(self.url)
        server.set_identity_tokens([ua.AnonymousIdentityToken, ua.UserNameIdentityToken])
        server.set_security_policy([ua.SecurityPolicyType.NoSecurity,
                                    ua.SecurityPolicyType.Basic256Sha256_SignAndEncrypt])
        await server.load_certificate(str(self.server_cert))
        await server.load_private_key(str(self.server_key))
        assert await server.register_namespace("urn:greybox:test") == 2
        await server.start()
        self.server = server

    def _certificates(self) -> None:
        """A certificate and key of the server and of a client (self-signed, as OPC UA applications use)."""
        self.folder.mkdir(parents=True, exist_ok=True)
        from asyncua.crypto import cert_gen
        from cryptography import x509
        from cryptography.hazmat.primitives import serialization
        from cryptography.x509.oid import ExtendedKeyUsageOID

        for role, uri, use in (("server", "urn:greybox:test:server", ExtendedKeyUsageOID.SERVER_AUTH),
                               ("client", "urn:greybox:test:client", ExtendedKeyUsageOID.CLIENT_AUTH)):
            key = cert_gen.generate_private_key()
            names = [x509.UniformResourceIdentifier(uri), x509.DNSName("localhost"),
                     x509.IPAddress(ipaddress.ip_address("127.0.0.1"))]
            certificate = cert_gen.generate_self_signed_app_certificate(key, f"greybox test {role}", {}, names, [use])
            (self.folder / f"{role}.pem").write_bytes(certificate.public_bytes(serialization.Encoding.PEM))
            (self.folder / f"{role}-key.pem").write_bytes(cert_gen.dump_private_key_as_pem(key))
        self.server_cert, self.server_key = self.folder / "server.pem", self.folder / "server-key.pem"
        self.client_cert, self.client_key = self.folder / "client.pem", self.folder / "client-key.pem"

    def start(self) -> "OpcUaServer":
        self._certificates()
        self.run(self._init(), timeout=120.0)
        return self

    def axis(self) -> Axis:
        """A new axis of variables (its own names, so that tests sharing the server do not meet)."""
        from asyncua import ua

        self.axes += 1
        name = f"A{self.axes}"

        async def make():
            folder = await self.server.nodes.objects.add_object(ua.NodeId(name, 2), name)
            anything = ua.NodeId(ua.ObjectIds.Number)  # after a null value, of the type written next
            return {column: await folder.add_variable(ua.NodeId(f"{name}.{variable}", 2), f"{name}.{variable}", 0.0,
                                                      datatype=anything)
                    for column, variable in VARIABLES.items()}

        return Axis(self, name, self.run(make()))

    def restart(self, down_s: float = 0.0) -> None:
        """Stop the server (every connection closed, the sessions and subscriptions gone) and start it again."""
        import time

        self.run(self._stop())
        time.sleep(down_s)
        self.run(self.server.start())

    async def _stop(self):
        # asyncua closes the clients' connections before its listening socket: a client that connects again in
        # between keeps the stop waiting for its connection; refuse new ones first
        listening = getattr(self.server.bserver, "_server", None)
        if listening is not None:
            listening.close()
        await self.server.stop()

    def close(self) -> None:
        if self.server is not None:
            self.run(self._stop())
            self.server = None
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(5.0)
