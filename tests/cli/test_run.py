"""The ``greybox`` command's exit (greybox.cli.run): a command stopped by a signal does not wait for threads."""

from __future__ import annotations

import pytest

import greybox.cli as cli


@pytest.mark.parametrize("status", [143, 130])
def test_a_stopped_command_exits_without_joining_worker_threads(monkeypatch, status):
    exits = []

    def immediate_exit(code):  # os._exit ends the process at once; here it says so and stops run()
        exits.append(code)
        raise SystemExit(code)

    monkeypatch.setattr(cli, "main", lambda: status)
    monkeypatch.setattr(cli.os, "_exit", immediate_exit)
    with pytest.raises(SystemExit):
        cli.run()
    assert exits == [status]


@pytest.mark.parametrize("status", [0, 1, 2])
def test_any_other_status_exits_the_usual_way(monkeypatch, status):
    monkeypatch.setattr(cli, "main", lambda: status)
    monkeypatch.setattr(cli.os, "_exit", lambda code: pytest.fail("os._exit for an ordinary status"))
    with pytest.raises(SystemExit) as exit_:
        cli.run()
    assert exit_.value.code == status
