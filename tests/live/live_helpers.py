"""Helpers of the live tests: quick model settings, messages of a log, the joined output, a real broker."""

from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import time
from pathlib import Path

import numpy as np

import greybox.cli as cli
from greybox.models.augmented import AugmentedModel
from greybox.models.friction import CoulombModel, GMSModel, LuGreModel, StribeckModel
from greybox.models.friction.backlash import BacklashModel
from greybox.models.gmssvr import GMSSVRModel
from greybox.models.svr import SVRCurrentModel

EXAMPLE_AXIS = Path(__file__).resolve().parents[2] / "examples" / "axis_x.toml"
#: Quick settings of every kind a model file may hold (short searches, no Bayesian optimisation).
QUICK = {
    "coulomb": lambda: CoulombModel(fit_offset=True),
    "stribeck": lambda: StribeckModel(),
    "lugre": lambda: LuGreModel(n_starts=1, max_iter=40),
    "gms": lambda: GMSModel(n_starts=1, max_iter=40),
    "svr": lambda: SVRCurrentModel(optimize=False, n_subset=200),
    "gmssvr": lambda: GMSSVRModel(optimize=False, n_subset=200, gms=GMSModel(n_starts=1, max_iter=40)),
    "augmented": lambda: AugmentedModel(base=GMSModel(n_starts=1, max_iter=40), refine_shapes=False,
                                        effects=[("thermal_drift", 3.0), "constant_offset"]),
    "backlash": lambda: BacklashModel(base=GMSModel(n_starts=1, max_iter=40), width=0.05),
}


def run_cli(argv) -> int:
    return cli.main([str(part) for part in argv])


def json_batches(log, sizes) -> list[str]:
    """The samples of a log as JSON messages of the given sizes in turn (columns of the log's CSV names)."""
    columns = {"time_s": log.time, "position_mm": log.position, "current_A": log.effort}
    if log.velocity is not None:
        columns["velocity_mm_s"] = log.velocity
    if log.acceleration is not None:
        columns["acceleration_mm_s2"] = log.acceleration
    out, start, k = [], 0, 0
    while start < len(log):
        stop = start + sizes[k % len(sizes)]
        out.append(json.dumps({name: values[start:stop].tolist() for name, values in columns.items()}
                              | {"seq": k}))
        start, k = stop, k + 1
    return out


def joined(lines, ordered: bool = False) -> dict[str, np.ndarray]:
    """The estimate columns of JSON output lines (alarm messages left out), joined (in time order with
    ``ordered``: messages queued while the broker was away may arrive after newer ones)."""
    rows = [json.loads(line) for line in lines if line.strip()]
    rows = [row for row in rows if "alarm" not in row]
    if ordered:
        rows.sort(key=lambda row: row["time_s"][0])
    return {name: np.concatenate([np.asarray(row[name], dtype=float) for row in rows])
            for name in rows[0] if name != "seq"}


# --- a real Mosquitto broker -------------------------------------------------------------------------

#: Seconds a broker gets to accept connections.
BROKER_START_S = 10.0


def _program(name: str) -> str | None:
    """A program of the mosquitto package (also looked for in the sbin folders, where Debian installs the broker)."""
    path = os.pathsep.join([os.environ.get("PATH", ""), "/usr/sbin", "/usr/local/sbin"])
    return shutil.which(name, path=path)


def mosquitto_binary() -> str | None:
    """The ``mosquitto`` program."""
    return _program("mosquitto")


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _wait_for_port(port: int, deadline: float) -> bool:
    while time.monotonic() < deadline:
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=0.2):
                return True
        except OSError:
            time.sleep(0.05)
    return False


class Broker:
    """A Mosquitto broker on 127.0.0.1 at a free port, for one test; ``restart()`` stops and starts it.

    With ``users`` (``{name: password}``) it takes only those users (a password file made by
    ``mosquitto_passwd``), and with ``acl`` (lines of an ACL file) only what it allows; with ``tls`` (a
    :class:`Certificates`) the listener is TLS, requiring a client certificate; with ``persistence`` the
    sessions and their queued messages survive a restart.
    """

    def __init__(self, binary: str, folder: Path, *, users: dict | None = None, acl: list[str] | None = None,
                 tls: "Certificates | None" = None, persistence: bool = False):
        self.binary = binary
        self.port = free_port()
        self.tls = tls
        self.config = folder / "mosquitto.conf"
        lines = [f"listener {self.port} 127.0.0.1", f"allow_anonymous {'false' if users else 'true'}",
                 f"persistence {'true' if persistence else 'false'}", "set_tcp_nodelay true"]
        if hasattr(os, "geteuid") and os.geteuid() == 0:
            lines.append("user root")  # as root, mosquitto would become 'mosquitto' and not read the test's files
        if persistence:
            lines += [f"persistence_location {folder}/", "autosave_interval 1"]
        if users:
            passwords = folder / "passwords"
            passwords.write_text("")
            for name, password in users.items():
                subprocess.run([_program("mosquitto_passwd"), "-b", str(passwords), name, password], check=True,
                               capture_output=True)
            lines.append(f"password_file {passwords}")
        if acl is not None:
            (folder / "acl").write_text("\n".join(acl) + "\n")
            lines.append(f"acl_file {folder / 'acl'}")
        if tls is not None:
            lines += [f"cafile {tls.ca}", f"certfile {tls.server_cert}", f"keyfile {tls.server_key}",
                      "require_certificate true"]
        self.config.write_text("\n".join(lines) + "\n")
        self.log = folder / "mosquitto.log"
        self.process = None
        self._this_start_log = ""

    def start(self) -> None:
        """Start the broker and wait until it runs on its port.

        A port taken meanwhile by another process (a broker of a test in another pytest-xdist worker took the
        same free port) makes Mosquitto exit: then a new free port is taken, up to three times; a restart keeps
        its port, as the clients reconnect to it.
        """
        for _ in range(3):
            if self._started():
                return
            if "Address already in use" not in self._this_start_log:
                break
            self.port = self._move_to(free_port())
        raise RuntimeError(f"mosquitto did not run on port {self.port} within {BROKER_START_S} s: "
                           f"{self._this_start_log[-500:]}")

    def _started(self) -> bool:
        """Start Mosquitto once; True when it listens and has said it runs (its own log, not another broker)."""
        offset = self.log.stat().st_size if self.log.exists() else 0
        with open(self.log, "ab") as log:
            self.process = subprocess.Popen([self.binary, "-c", str(self.config)], stdout=log, stderr=log)
        deadline = time.monotonic() + BROKER_START_S
        while time.monotonic() < deadline:
            self._this_start_log = self.log.read_bytes()[offset:].decode(errors="replace")
            if self.process.poll() is not None:
                break
            if "running" in self._this_start_log and _wait_for_port(self.port, deadline):
                return True
            time.sleep(0.05)
        self.stop()
        self._this_start_log = self.log.read_bytes()[offset:].decode(errors="replace")
        return False

    def _move_to(self, port: int) -> int:
        """Rewrite the configuration's listener for ``port``; returns it."""
        lines = self.config.read_text().splitlines()
        self.config.write_text("\n".join(f"listener {port} 127.0.0.1" if line.startswith("listener ") else line
                                         for line in lines) + "\n")
        return port

    def stop(self) -> None:
        if self.process is not None and self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(timeout=5)
        self.process = None

    def restart(self, down_s: float = 0.5) -> None:
        self.stop()
        time.sleep(down_s)
        self.start()

    def url(self, topic: str, user: str | None = None) -> str:
        scheme = "mqtts" if self.tls is not None else "mqtt"
        return f"{scheme}://{user + '@' if user else ''}127.0.0.1:{self.port}/{topic}"

    def kill(self) -> None:
        """Stop the broker at once (SIGKILL)."""
        if self.process is not None:
            self.process.kill()
            self.process.wait(timeout=5)
            self.process = None


class Certificates:
    """A CA, a broker certificate for 127.0.0.1 and a client certificate, as PEM files in ``folder`` (trustme)."""

    def __init__(self, folder: Path):
        import trustme

        ca = trustme.CA()
        server = ca.issue_cert("127.0.0.1", "localhost")
        client = ca.issue_cert("greybox-client@example.org")
        self.ca, self.server_cert, self.server_key = folder / "ca.pem", folder / "server.pem", folder / "server.key"
        self.client_cert, self.client_key = folder / "client.pem", folder / "client.key"
        ca.cert_pem.write_to_path(str(self.ca))
        server.cert_chain_pems[0].write_to_path(str(self.server_cert))
        server.private_key_pem.write_to_path(str(self.server_key))
        client.cert_chain_pems[0].write_to_path(str(self.client_cert))
        client.private_key_pem.write_to_path(str(self.client_key))
        other = trustme.CA()  # a CA the broker does not know
        self.other_ca = folder / "other-ca.pem"
        other.cert_pem.write_to_path(str(self.other_ca))




class Subscriber:
    """A paho-mqtt client of the test that collects the messages of a topic filter."""

    def __init__(self, port: int, topic: str, *, user: tuple[str, str] | None = None,
                 tls: "Certificates | None" = None, qos: int = 0, retained: bool = True):
        import threading

        import paho.mqtt.client as mqtt

        self.messages: list[tuple[str, bytes, float]] = []
        self.retained: dict[str, bytes] = {}
        self.connections = 0
        self.qos = qos
        self._lock = threading.Lock()
        self.client = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2, client_id=f"test-{os.getpid()}-{topic}",
                                  clean_session=qos == 0)
        self.client.reconnect_delay_set(min_delay=1, max_delay=1)
        if user is not None:
            self.client.username_pw_set(*user)
        if tls is not None:
            self.client.tls_set(ca_certs=str(tls.ca), certfile=str(tls.client_cert), keyfile=str(tls.client_key))

        def connected(client, userdata, flags, reason_code, properties=None):
            client.subscribe(topic, qos=qos)

        def subscribed(client, userdata, mid, reason_codes, properties=None):
            with self._lock:
                self.connections += 1

        self.client.on_connect = connected
        self.client.on_subscribe = subscribed
        self.client.on_message = lambda client, userdata, message: self._add(message)
        self.client.connect("127.0.0.1", port, keepalive=10)
        self.client.loop_start()
        wait_until(lambda: self.connections >= 1, "the test's subscriber to connect")

    def _add(self, message) -> None:
        with self._lock:
            self.messages.append((message.topic, message.payload, time.time()))
            self.retained[message.topic] = message.payload

    def payloads(self, topic: str) -> list[str]:
        with self._lock:
            return [payload.decode() for name, payload, _ in self.messages if name == topic]

    def publish(self, topic: str, payload: str, wait: bool = True) -> None:
        info = self.client.publish(topic, payload.encode(), qos=self.qos)
        if wait:
            info.wait_for_publish(5)

    def close(self) -> None:
        self.client.disconnect()
        self.client.loop_stop()


def wait_until(condition, what: str, timeout_s: float = 30.0) -> None:
    """Wait (bounded) until ``condition()`` is true."""
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout_s} s waiting for {what}")
        time.sleep(0.02)


class LiveProcess:
    """``greybox live`` in a subprocess, its stderr lines collected by a thread."""

    def __init__(self, *args, env: dict | None = None):
        import sys
        import threading

        self.process = subprocess.Popen([sys.executable, "-m", "greybox", "live", *map(str, args)], text=True,
                                        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        env=None if env is None else {**os.environ, **env})
        self.lines: list[str] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        for line in self.process.stderr:
            self.lines.append(line.rstrip("\n"))

    def said(self, words: str) -> bool:
        return any(words in line for line in list(self.lines))

    def stop(self, timeout_s: float = 30.0) -> int:
        import signal

        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
        try:
            status = self.process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            self.process.kill()
            raise
        self._reader.join(timeout=5)
        return status
