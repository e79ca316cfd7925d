"""Fixtures of the live tests: small fitted models of every kind a model file may hold, a cutting log as CSV
with the table ``greybox predict`` writes for it, and a real Mosquitto broker on a free loopback port."""

from __future__ import annotations

from pathlib import Path

import live_helpers
import pandas as pd
import pytest
from live_helpers import EXAMPLE_AXIS, QUICK, Broker, Certificates, run_cli

from greybox.data.io import write_log
from greybox.data.prepare import prepare
from greybox.models.files import save_model
from greybox.twin import make_dataset


@pytest.fixture(scope="session")
def live_root(tmp_path_factory):
    return tmp_path_factory.mktemp("live")


@pytest.fixture(scope="session")
def train_run():
    return prepare([make_dataset("X", "A", seed=3, duration_s=5)])[0]


@pytest.fixture(scope="session")
def cut_raw():
    """A cutting log as the controller records it (velocity logged, no acceleration), 1.6 s at 2 ms."""
    return make_dataset("X", "C", seed=4, duration_s=1.6, cutting=True).replace(extras={})


@pytest.fixture(scope="session")
def model_file(live_root, train_run):
    """``model_file(kind)``: the path of a small fitted model of that kind (fitted once)."""
    made = {}

    def get(kind: str) -> Path:
        if kind not in made:
            path = live_root / f"{kind}.gbm"
            save_model(QUICK[kind]().fit(train_run), path)
            made[kind] = path
        return made[kind]

    return get


@pytest.fixture(scope="session")
def offline(live_root, cut_raw):
    """``offline(kind, log=cut_raw, name="cut")``: the table ``greybox predict`` writes, as a DataFrame."""
    done = {}

    def get(model_path: Path, log=None, name: str = "cut", extra=()) -> pd.DataFrame:
        key = (str(model_path), name, tuple(extra))
        if key not in done:
            log_path = live_root / f"{name}.csv"
            if not log_path.exists():
                write_log(cut_raw if log is None else log, log_path)
            out = live_root / f"{Path(model_path).stem}-{name}-{len(done)}.csv"
            assert run_cli(["predict", model_path, log_path, "--out", out, "--axis-config", EXAMPLE_AXIS, "--quiet",
                            *extra]) == 0
            done[key] = pd.read_csv(out)
        return done[key]

    return get


def _mosquitto() -> str:
    binary = live_helpers.mosquitto_binary()
    if binary is None:
        pytest.skip("the mosquitto broker is not installed (Debian/Ubuntu package 'mosquitto': "
                    "apt-get install mosquitto)")
    return binary


@pytest.fixture
def broker(tmp_path):
    """A running Mosquitto broker of its own; skips (naming the Debian package) when mosquitto is absent."""
    running = Broker(_mosquitto(), tmp_path)
    running.start()
    try:
        yield running
    finally:
        running.stop()


@pytest.fixture
def make_broker(tmp_path):
    """``make_broker(users=..., acl=..., tls=..., persistence=...)``: a running Mosquitto broker of those settings
    (:class:`live_helpers.Broker`), in a folder of its own; stopped after the test."""
    made = []

    def make(**settings) -> Broker:
        folder = tmp_path / f"broker{len(made)}"
        folder.mkdir()
        running = Broker(_mosquitto(), folder, **settings)
        made.append(running)
        running.start()
        return running

    yield make
    for running in made:
        running.stop()


@pytest.fixture
def certificates(tmp_path) -> Certificates:
    """A CA, a broker and a client certificate made for the test (PEM files)."""
    folder = tmp_path / "pki"
    folder.mkdir()
    return Certificates(folder)


@pytest.fixture(scope="session")
def opcua_server(tmp_path_factory):
    """An asyncua OPC UA server in the test process, shared by the tests (its start takes seconds); each test makes
    its own axis of variables (:meth:`opcua_helpers.OpcUaServer.axis`)."""
    from opcua_helpers import OpcUaServer

    running = OpcUaServer(tmp_path_factory.mktemp("opcua")).start()
    yield running
    running.close()


@pytest.fixture
def own_opcua_server(tmp_path):
    """An asyncua OPC UA server of the test's own, for tests that stop and restart it (a server that others' clients
    were connected to can take long to stop)."""
    from opcua_helpers import OpcUaServer

    running = OpcUaServer(tmp_path / "opcua").start()
    yield running
    running.close()
