"""``greybox live`` as a plant runs it, against a real Mosquitto with users, an ACL and TLS certificates made by
the test: logging in, refusals named, the status topic and its will, two instances side by side, a broker
restart with a persistent session."""

from __future__ import annotations

import json
import signal

import pytest
from live_helpers import EXAMPLE_AXIS, LiveProcess, Subscriber, json_batches, run_cli, wait_until

#: Each test starts brokers and greybox processes: several seconds.
pytestmark = pytest.mark.slow

USERS = {"greybox": "gr3ybox pass", "plc": "plc-pass"}
ACL = ["user greybox", "topic read axis/#", "topic write process/#",
       "user plc", "topic write axis/#", "topic read process/#"]


def estimated(client, topic) -> int:
    return sum(len(json.loads(payload)["time_s"]) for payload in client.payloads(topic))


def distinct(client, topic) -> int:
    """Samples estimated, each counted once: QoS 1 is at least once, a message may come again after a reconnection."""
    return len({time for payload in client.payloads(topic) for time in json.loads(payload)["time_s"]})


def secrets_file(tmp_path, text):
    path = tmp_path / f"password-{len(list(tmp_path.glob('password-*')))}"
    path.write_text(text + "\n")
    return path


def test_a_plant_broker_with_users_an_acl_and_tls(make_broker, certificates, model_file, cut_raw, tmp_path):
    server = make_broker(users=USERS, acl=ACL, tls=certificates)
    plc = Subscriber(server.port, "process/#", user=("plc", USERS["plc"]), tls=certificates)
    try:
        live = LiveProcess(model_file("coulomb"), "--source", server.url("axis/#", user="greybox"),
                           "--sink", server.url("process/X"),
                           "--password-file", secrets_file(tmp_path, USERS["greybox"]),
                           "--tls-ca", certificates.ca, "--tls-cert", certificates.client_cert,
                           "--tls-key", certificates.client_key, "--axis-config", EXAMPLE_AXIS,
                           "--connect-timeout", "20")
        wait_until(lambda: live.said("reading mqtts://") or live.process.poll() is not None, "greybox live to log in")
        assert live.process.poll() is None, live.lines
        wait_until(lambda: "process/X/status" in plc.retained, "the status")
        assert json.loads(plc.retained["process/X/status"])["state"] == "online"
        for message in json_batches(cut_raw, (10,)):
            plc.publish("axis/X/cut", message)  # the filter axis/# takes every topic below axis/
        wait_until(lambda: estimated(plc, "process/X") >= len(cut_raw) - 200, "estimates through the TLS broker")
        assert live.stop() == 143
        status = json.loads(plc.retained["process/X/status"])
        assert status["state"] == "offline" and status["counters"]["samples_received"] == len(cut_raw)
        assert not any(USERS["greybox"] in line for line in live.lines)
    finally:
        plc.close()


def test_refusals_are_named(make_broker, certificates, model_file, tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("GREYBOX_MQTT_PASSWORD", raising=False)
    plain = make_broker(users=USERS, acl=ACL)
    path = model_file("coulomb")
    cases = [
        (["--source", plain.url("axis/X", user="greybox"), "--password-file", secrets_file(tmp_path, "wrong")],
         "the broker refused the connection: Not authorized"),
        (["--source", plain.url("axis/X"), "--sink", plain.url("process/X")], "refused the connection: Not authorized"),
    ]
    secured = make_broker(users=USERS, acl=ACL, tls=certificates)
    cases.append((["--source", secured.url("axis/X", user="greybox"), "--password-file",
                   secrets_file(tmp_path, USERS["greybox"]), "--tls-ca", certificates.other_ca],
                  "TLS handshake failed"))
    cases.append((["--source", secured.url("axis/X", user="greybox"), "--tls-ca", certificates.ca, "--tls-key",
                   certificates.client_key], "--tls-key needs --tls-cert"))
    for argv, words in cases:
        assert run_cli(["live", path, *argv, "--connect-timeout", "5"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and words in err[0], (argv, err)
        assert "gr3ybox" not in err[0] and "wrong" not in err[0]


def test_two_instances_on_one_host_do_not_knock_each_other_off(broker, model_file, cut_raw, tmp_path):
    client = Subscriber(broker.port, "process/#")
    lives = [LiveProcess(model_file("coulomb"), "--source", broker.url("axis/X"), "--sink", broker.url(f"process/{k}"),
                         "--stats", tmp_path / f"stats{k}.json", "--connect-timeout", "20") for k in range(2)]
    try:
        for live in lives:
            wait_until(lambda live=live: live.said("reading mqtt://") or live.process.poll() is not None, "start")
        messages = json_batches(cut_raw, (10,))
        for message in messages:
            client.publish("axis/X", message)
        for k in range(2):
            wait_until(lambda k=k: estimated(client, f"process/{k}") >= len(cut_raw) - 200, f"instance {k}")
        assert [live.stop() for live in lives] == [143, 143]
        for k in range(2):
            stats = json.loads((tmp_path / f"stats{k}.json").read_text())
            assert stats["disconnections"] == 0 and stats["gaps"] == 0 and stats["samples_received"] == len(cut_raw)
    finally:
        client.close()
        for live in lives:
            if live.process.poll() is None:
                live.process.kill()


def test_the_broker_publishes_offline_when_the_process_dies(broker, model_file):
    client = Subscriber(broker.port, "process/X/status")
    try:
        live = LiveProcess(model_file("coulomb"), "--source", broker.url("axis/X"), "--sink", broker.url("process/X"),
                           "--connect-timeout", "20")
        wait_until(lambda: "process/X/status" in client.retained, "the status")
        assert json.loads(client.retained["process/X/status"])["state"] == "online"
        live.process.send_signal(signal.SIGKILL)
        live.process.wait(timeout=10)
        wait_until(lambda: json.loads(client.retained["process/X/status"])["state"] == "offline", "the will")
        assert json.loads(client.retained["process/X/status"])["reason"] == "connection lost"
    finally:
        client.close()


def test_a_broker_restart_with_a_persistent_session_loses_no_sample(make_broker, model_file, cut_raw, tmp_path):
    """QoS 1 from the publisher (its session persistent) to greybox (its session persistent) and back: the
    broker stops between two halves of the stream, the second half is published while it is away; every sample
    arrives, no gap, and every estimate reaches the subscriber."""
    server = make_broker(persistence=True)
    client = Subscriber(server.port, "process/X", qos=1)
    live = LiveProcess(model_file("coulomb"), "--source", server.url("axis/X"), "--sink", server.url("process/X"),
                       "--client-id", "plant-line-1", "--stats", tmp_path / "stats.json", "--idle-s", "0.5",
                       "--connect-timeout", "20")
    try:
        wait_until(lambda: live.said("reading mqtt://") or live.process.poll() is not None, "start")
        messages = json_batches(cut_raw, (10,))
        for message in messages[:60]:
            client.publish("axis/X", message)
        wait_until(lambda: estimated(client, "process/X") > 0, "the first estimates")
        server.stop()
        for message in messages[60:]:
            client.publish("axis/X", message, wait=False)  # queued by the publisher while the broker is away
        server.start()
        try:
            wait_until(lambda: distinct(client, "process/X") == len(cut_raw), "every estimate", timeout_s=30)
        finally:
            assert live.stop() == 143, live.lines
            print("\n".join(live.lines), distinct(client, "process/X"))
        stats = json.loads((tmp_path / "stats.json").read_text())
        assert stats["samples_estimated"] == len(cut_raw)
        # QoS 1 is at least once: a message the broker delivers again after its restart repeats time stamps
        # already estimated, and exactly those samples are dropped as not after their predecessors
        assert stats["samples_received"] - len(cut_raw) == stats["dropped"].get("backwards", 0)
        assert not stats["lost"] and set(stats["dropped"]) <= {"backwards"}
        assert stats["gaps"] == 0 and stats["disconnections"] == 1 and stats["outputs_lost"] == 0
    finally:
        client.close()
        if live.process.poll() is None:
            live.process.kill()
