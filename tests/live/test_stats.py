"""The counters file: written by a thread of its own while the stream runs, the last counters on close."""

from __future__ import annotations

import json
import threading
import time

import pytest

from greybox.live.stats import StatsFile


def test_the_file_holds_the_last_counters_after_close(tmp_path):
    path = tmp_path / "stats.json"
    stats = StatsFile(path)
    stats.write({"messages": 1})
    stats.close({"messages": 2})
    assert json.loads(path.read_text()) == {"messages": 2}
    assert stats.written == 2


def test_a_write_due_while_the_previous_one_goes_is_left_out_and_the_caller_does_not_wait(tmp_path, monkeypatch):
    path = tmp_path / "stats.json"
    stats = StatsFile(path)
    release, started = threading.Event(), threading.Event()
    write = stats._write

    def slow(text):  # a disk that takes its time to sync
        started.set()
        release.wait(10)
        write(text)

    monkeypatch.setattr(stats, "_write", slow)
    stats.write({"messages": 1})
    assert started.wait(10)
    stats.write({"messages": 2})  # returns at once: the first write is still going
    assert (stats.skipped, stats.written) == (1, 0)
    release.set()
    stats.close({"messages": 3})
    assert json.loads(path.read_text()) == {"messages": 3}
    assert stats.written == 2


def test_the_error_of_a_write_comes_out_at_the_next(tmp_path):
    stats = StatsFile(tmp_path / "gone" / "stats.json")
    stats.write({"messages": 1})
    deadline = time.monotonic() + 10
    with pytest.raises(OSError):
        while time.monotonic() < deadline:  # left out until the first write is done, which then raises
            stats.write({"messages": 2})
            time.sleep(0.01)
    with pytest.raises(OSError):
        stats.close({"messages": 3})
