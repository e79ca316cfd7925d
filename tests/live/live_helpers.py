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


def joined(lines) -> dict[str, np.ndarray]:
    """The estimate columns of JSON output lines (alarm messages left out), joined."""
    rows = [json.loads(line) for line in lines if line.strip()]
    rows = [row for row in rows if "alarm" not in row]
    return {name: np.concatenate([np.asarray(row[name], dtype=float) for row in rows])
            for name in rows[0] if name != "seq"}


# --- a real Mosquitto broker -------------------------------------------------------------------------

#: Seconds a broker gets to accept connections.
BROKER_START_S = 10.0


def mosquitto_binary() -> str | None:
    """The ``mosquitto`` program (also looked for in the sbin folders, where Debian installs it)."""
    path = os.pathsep.join([os.environ.get("PATH", ""), "/usr/sbin", "/usr/local/sbin"])
    return shutil.which("mosquitto", path=path)


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
    """A Mosquitto broker on 127.0.0.1 at a free port, for one test; ``restart()`` stops and starts it."""

    def __init__(self, binary: str, folder: Path):
        self.binary = binary
        self.port = free_port()
        self.config = folder / "mosquitto.conf"
        self.config.write_text(f"listener {self.port} 127.0.0.1\nallow_anonymous true\npersistence false\n")
        self.log = folder / "mosquitto.log"
        self.process = None

    def start(self) -> None:
        with open(self.log, "ab") as log:
            self.process = subprocess.Popen([self.binary, "-c", str(self.config)], stdout=log, stderr=log)
        if not _wait_for_port(self.port, time.monotonic() + BROKER_START_S):
            self.stop()
            raise RuntimeError(f"mosquitto did not listen on port {self.port} within {BROKER_START_S} s: "
                               f"{self.log.read_text()[-500:]}")

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

    def url(self, topic: str) -> str:
        return f"mqtt://127.0.0.1:{self.port}/{topic}"




class Subscriber:
    """A paho-mqtt client of the test that collects the messages of a topic filter."""

    def __init__(self, port: int, topic: str):
        import threading

        import paho.mqtt.client as mqtt

        self.messages: list[tuple[str, bytes, float]] = []
        self.connections = 0
        self._lock = threading.Lock()
        self.client = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2, client_id=f"test-{os.getpid()}-{topic}")
        self.client.reconnect_delay_set(min_delay=1, max_delay=1)

        def connected(client, userdata, flags, reason_code, properties=None):
            client.subscribe(topic)

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

    def payloads(self, topic: str) -> list[str]:
        with self._lock:
            return [payload.decode() for name, payload, _ in self.messages if name == topic]

    def publish(self, topic: str, payload: str) -> None:
        self.client.publish(topic, payload.encode(), qos=0).wait_for_publish(5)

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

    def __init__(self, *args):
        import sys
        import threading

        self.process = subprocess.Popen([sys.executable, "-m", "greybox", "live", *map(str, args)], text=True,
                                        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
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
