"""``greybox live`` against a real Mosquitto broker (started by the test on a free loopback port): the
estimates published per message equal ``greybox predict``; a broker restart is survived, the gap
reported and the state re-initialised; SIGTERM ends with 143."""

from __future__ import annotations

import json
import time

import numpy as np
import pytest
from live_helpers import EXAMPLE_AXIS, LiveProcess, Subscriber, joined, json_batches, wait_until

from greybox.data.blocks import concatenate
from greybox.data.prepare import derivative_margin

#: Each test starts a broker and a greybox process: several seconds.
pytestmark = pytest.mark.slow


@pytest.fixture
def clients(broker):
    made = []

    def subscriber(topic):
        client = Subscriber(broker.port, topic)
        made.append(client)
        return client

    yield subscriber
    for client in made:
        client.close()


def start_live(broker, model_path, tmp_path, *extra) -> LiveProcess:
    live = LiveProcess(model_path, "--source", broker.url("axis/X"), "--sink", broker.url("process/X"),
                       "--axis-config", EXAMPLE_AXIS, "--stats", tmp_path / "stats.json", "--connect-timeout", "20",
                       *extra)
    wait_until(lambda: live.said("reading mqtt://") or live.process.poll() is not None, "greybox live to connect")
    assert live.process.poll() is None, live.lines
    return live


def test_estimates_through_the_broker_equal_predict(broker, clients, model_file, offline, cut_raw, tmp_path):
    path = model_file("gmssvr")
    expected = offline(path)
    out = clients("process/X/#")
    live = start_live(broker, path, tmp_path, "--limit", "current_process_A=1e6")
    messages = json_batches(cut_raw, (10,))
    for message in messages:
        out.publish("axis/X", message)
    margin = derivative_margin(cut_raw.sample_time)
    wait_until(lambda: sum(len(json.loads(p)["time_s"]) for p in out.payloads("process/X")) >= len(cut_raw) - margin,
               "the estimates")
    assert live.stop() == 143
    received = out.payloads("process/X")
    live_table = joined(received)
    n = len(live_table["time_s"])
    assert n >= len(cut_raw) - margin - 10
    for name in expected.columns:
        np.testing.assert_allclose(live_table[name], expected[name].to_numpy()[:n], rtol=0, atol=1e-9, err_msg=name)
    assert {json.loads(p)["seq"] for p in received} <= set(range(len(messages)))
    stats = json.loads((tmp_path / "stats.json").read_text())
    assert stats["rejected"] == 0 and stats["disconnections"] == 0 and stats["samples_estimated"] == n
    assert "terminated (SIGTERM)" in live.lines[-1] or any("terminated" in line for line in live.lines)


def test_a_malformed_message_on_the_broker_is_skipped(broker, clients, model_file, tmp_path, cut_raw):
    out = clients("process/X/#")
    live = start_live(broker, model_file("coulomb"), tmp_path)
    out.publish("axis/X", "{broken")
    out.publish("axis/X", '{"time_s": 0.0, "position_mm": "far", "velocity_mm_s": 0, "current_A": 0}')
    for message in json_batches(cut_raw, (50,)):
        out.publish("axis/X", message)
    wait_until(lambda: len(out.payloads("process/X")) > 5, "estimates after the malformed messages")
    assert live.stop() == 143
    skipped = [line for line in live.lines if "skipped" in line]
    assert len(skipped) == 2 and skipped[0].startswith("message 1 on axis/X: skipped: not JSON")
    assert json.loads((tmp_path / "stats.json").read_text())["rejected"] == 2


def test_a_broker_restart_is_survived_the_gap_reported(broker, clients, model_file, offline, cut_raw, tmp_path):
    """The broker goes away between sample 499 and 600; the samples in between never arrive. After the
    reconnection the stream goes on as a new run: the estimates equal predict on the log with that gap."""
    path = model_file("gms")
    gapped = concatenate([cut_raw.select(slice(0, 500)), cut_raw.select(slice(600, None))])
    expected = offline(path, gapped, name="broker-gap", extra=["--resample", "0.002"])
    out = clients("process/X/#")
    # no idle flush while the broker is away: the test's own subscriber (QoS 0) would miss what is sent meanwhile
    live = start_live(broker, path, tmp_path, "--idle-s", "60")
    messages = json_batches(gapped, (10,))
    for message in messages[:50]:
        out.publish("axis/X", message)
    wait_until(lambda: len(out.payloads("process/X")) >= 50 - derivative_margin(0.002) // 10 - 1,
               "the estimates of the first run")
    connections = out.connections
    broker.restart()
    wait_until(lambda: live.said("broker connection back"), "greybox live to reconnect")
    wait_until(lambda: out.connections > connections, "the test's client to reconnect")
    for message in messages[50:]:
        out.publish("axis/X", message)
    wait_until(lambda: sum(len(json.loads(p)["time_s"]) for p in out.payloads("process/X"))
               >= len(gapped) - derivative_margin(0.002), "the estimates of the second run")
    assert live.stop() == 143
    live_table = joined(out.payloads("process/X"), ordered=True)
    n = len(live_table["time_s"])
    for name in expected.columns:
        np.testing.assert_allclose(live_table[name], expected[name].to_numpy()[:n], rtol=0, atol=1e-9, err_msg=name)
    stats = json.loads((tmp_path / "stats.json").read_text())
    assert stats["disconnections"] == 1 and stats["gaps"] == 1 and stats["offline_s"] > 0
    assert live.said("broker connection lost") and live.said("gap of 202 ms")


def test_the_tail_of_a_stream_comes_out_within_a_second_of_going_idle(broker, clients, model_file, offline, cut_raw,
                                                                    tmp_path):
    path = model_file("gms")
    expected = offline(path)
    out = clients("process/X/#")
    live = start_live(broker, path, tmp_path)
    messages = json_batches(cut_raw, (10,))
    for message in messages[:-1]:  # at once: a stall of the test's process must not look like an idle stream
        out.publish("axis/X", message, wait=False)
    out.publish("axis/X", messages[-1])
    idle_from = time.time()  # the last message is on the broker
    wait_until(lambda: sum(len(json.loads(p)["time_s"]) for p in out.payloads("process/X")) == len(cut_raw),
               "the tail of the stream")
    last = max(arrived for topic, _, arrived in out.messages if topic == "process/X")
    assert live.stop() == 143
    assert last - idle_from <= 1.0, f"the tail came {last - idle_from:.3f} s after the stream went idle"
    live_table = joined(out.payloads("process/X"))
    for name in expected.columns:  # the tail estimated as the end of the log, as predict does
        np.testing.assert_allclose(live_table[name], expected[name].to_numpy(), rtol=0, atol=1e-9, err_msg=name)
    assert live.said("no message for")


def test_a_deep_and_a_huge_message_on_the_broker_are_one_line_each(broker, clients, model_file, cut_raw, tmp_path):
    out = clients("process/X/#")
    live = start_live(broker, model_file("coulomb"), tmp_path)
    out.publish("axis/X", "[" * 1000 + "]" * 1000)
    out.publish("axis/X", '{"time_s": [' + "1.0, " * (50 * 2**20 // 5) + "1.0]}")
    for message in json_batches(cut_raw, (10,)):
        out.publish("axis/X", message)
    wait_until(lambda: sum(len(json.loads(p)["time_s"]) for p in out.payloads("process/X")) == len(cut_raw),
               "the stream after the two messages")
    assert live.stop() == 143
    skipped = [line for line in live.lines if "skipped" in line]
    assert len(skipped) == 2 and "nested 1000 levels deep" in skipped[0] and "bytes, more than" in skipped[1]
    assert all(len(line) <= 400 for line in live.lines)
