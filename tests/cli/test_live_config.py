"""``greybox live --config``: every option as a TOML key, checked as on the command line, named when wrong."""

from __future__ import annotations

import pytest

from greybox.cli import build_parser
from greybox.cli._live_config import read_config
from greybox.errors import GreyboxError


@pytest.fixture(scope="module")
def actions():
    parser = build_parser(["live"])
    live = next(action for action in parser._actions if hasattr(action, "choices") and action.choices
                and "live" in action.choices).choices["live"]
    return {action.dest: action for action in live._actions if action.option_strings}


def write(tmp_path, text):
    path = tmp_path / "live.toml"
    path.write_text(text)
    return path


def test_keys_are_the_options_read_by_their_types(tmp_path, actions):
    path = write(tmp_path, 'source = "mqtts://greybox@broker/plant/#"\nrecord-s = 30\n'
                           'limit = ["force_process_N=1500"]\nexit_on_alarm = true\nqos = 0\n'
                           'tls_ca = "/etc/greybox/ca.pem"\nidle_s = 0.25\n')
    values = read_config(path, actions)
    assert values == {"source": "mqtts://greybox@broker/plant/#", "record_s": 30.0, "limit": ["force_process_N=1500"],
                      "exit_on_alarm": True, "qos": 0, "tls_ca": "/etc/greybox/ca.pem", "idle_s": 0.25}


@pytest.mark.parametrize("text, words", [
    ("record_s = -1", "record_s: "),
    ("qos = 2", "qos: "),
    ("exit_on_alarm = 1", "exit_on_alarm: give true or false"),
    ('colour = "red"', "colour: no such option"),
    ('password = "x"', "password: the password is not kept in the configuration; give password_file"),
    ("source = [1, 2]", "source: give a number or a string"),
    ("source = ", "not TOML"),
])
def test_wrong_keys_and_values_are_named(tmp_path, actions, text, words):
    with pytest.raises(GreyboxError, match=words) as caught:
        read_config(write(tmp_path, text + "\n"), actions)
    assert str(caught.value).startswith(f"--config {tmp_path / 'live.toml'}")
