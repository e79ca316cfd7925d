"""Broker addresses, log-in options and client ids, without a broker: what is refused, what is kept."""

from __future__ import annotations

import re

import pytest

from greybox.errors import GreyboxError
from greybox.live import broker
from greybox.live.broker import BrokerOptions, default_client_id, parse_address, read_password, topic_matches
from greybox.live.endpoints import open_endpoints


def test_wildcards_are_part_of_the_topic_not_a_url_fragment():
    address = parse_address("mqtt://plc.local/plant/#", "--source")
    assert (address.host, address.port, address.topic, address.tls) == ("plc.local", 1883, "plant/#", False)
    assert parse_address("mqtt://h:1884/plant/+/axis/X", "--source").topic == "plant/+/axis/X"
    assert topic_matches(parse_address("mqtt://h/plant/#", "--source").topic, "plant/m1/X")


@pytest.mark.parametrize("text, words", [
    ("mqtt://h/plant/a#", "'#' the whole last level"),
    ("mqtt://h/plant/#/x", "'#' the whole last level"),
    ("mqtt://h/plant/a+", "'+' must be a whole level"),
])
def test_misplaced_wildcards_are_refused(text, words):
    with pytest.raises(GreyboxError, match=re.escape(words)):
        parse_address(text, "--source")


def test_a_sink_topic_cannot_hold_wildcards():
    with pytest.raises(GreyboxError, match="cannot hold the wildcards"):
        parse_address("mqtt://h/out/#", "--sink", wildcards=False)


def test_tls_addresses_and_the_user_name():
    address = parse_address("mqtts://greybox@broker.plant:8884/axis/X", "--source")
    assert (address.host, address.port, address.tls, address.username) == ("broker.plant", 8884, True, "greybox")
    assert parse_address("mqtts://broker/axis/X", "--source").port == 8883
    assert str(address) == "mqtts://broker.plant:8884/axis/X"  # the user name is not shown
    assert parse_address("mqtt://[::1]:1884/t", "--source").host == "::1"


def test_a_password_in_the_address_is_refused_without_showing_it():
    with pytest.raises(GreyboxError) as caught:
        parse_address("mqtt://greybox:hunter2@broker/axis/X", "--source")
    assert "hunter2" not in str(caught.value) and "--password-file" in str(caught.value)
    assert "greybox:***@broker" in str(caught.value)


def test_the_password_comes_from_a_file_or_the_environment(tmp_path):
    secret = tmp_path / "password"
    secret.write_text("s3cret with spaces\nignored\n")
    assert read_password(secret) == "s3cret with spaces"
    assert read_password(None, environ={broker.PASSWORD_ENV: "from-env"}) == "from-env"
    assert read_password(None, environ={}) is None
    (tmp_path / "empty").write_text("")
    with pytest.raises(GreyboxError, match="empty"):
        read_password(tmp_path / "empty")
    with pytest.raises(GreyboxError, match="cannot read"):
        read_password(tmp_path / "missing")
    assert "s3cret" not in repr(BrokerOptions(username="u", password="s3cret"))


def test_options_that_cannot_work_are_refused():
    with pytest.raises(GreyboxError, match="needs a user name"):
        open_endpoints("mqtt://127.0.0.1:1/in", "-", options=BrokerOptions(password="x"), stdin=None, stdout=None)
    with pytest.raises(GreyboxError, match="user names of --source, --sink and --username differ"):
        open_endpoints("mqtt://a@127.0.0.1:1/in", "mqtt://b@127.0.0.1:1/out", options=BrokerOptions(), stdin=None,
                       stdout=None)
    with pytest.raises(GreyboxError, match="--tls-key needs --tls-cert"):
        BrokerOptions(key_file="k.pem")
    with pytest.raises(GreyboxError, match="--qos 2"):
        BrokerOptions(qos=2)


def test_default_client_ids_differ_between_containers_of_the_same_pid_and_host(monkeypatch):
    monkeypatch.setattr(broker.os, "getpid", lambda: 1)
    monkeypatch.setattr(broker.socket, "gethostname", lambda: "machine-pc")
    ids = {default_client_id() for _ in range(50)}
    assert len(ids) == 50 and all(name.startswith("greybox-machine-pc-1-") for name in ids)


def test_a_sink_the_source_would_receive_is_refused_before_connecting():
    # nothing listens on port 1: the refusal must come before any connection is tried
    common = dict(options=BrokerOptions(connect_timeout=0.1), stdin=None, stdout=None)
    with pytest.raises(GreyboxError, match="receives plant/out, where the command publishes"):
        open_endpoints("mqtt://127.0.0.1:1/plant/#", "mqtt://127.0.0.1:1/plant/out", **common)
    with pytest.raises(GreyboxError, match="receives out/X/alarm/force_process_N"):
        open_endpoints("mqtt://127.0.0.1:1/out/+/alarm/#", "mqtt://127.0.0.1:1/out", axes=["X", "Y"],
                       limit_columns=["force_process_N"], **common)
    with pytest.raises(GreyboxError, match="receives plant/status"):
        open_endpoints("mqtt://127.0.0.1:1/plant/+", "-", status_topic="plant/status", **common)
    with pytest.raises(GreyboxError, match="no broker answered"):  # another broker: no loop, the connection tried
        open_endpoints("mqtt://127.0.0.1:1/plant/#", "mqtt://127.0.0.2:1/plant/out", **common)
