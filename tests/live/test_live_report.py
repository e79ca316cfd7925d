"""The lines of a stream: each cut short, at most a burst per interval, the rest summed up in one line."""

from __future__ import annotations

import pytest

from greybox.live.report import LineLimiter, clip


class Clock:
    def __init__(self):
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_a_long_line_is_cut_and_says_how_much():
    line = "x" * 5_000_000
    cut = clip(line, 100)
    assert cut.startswith("x" * 100) and cut.endswith("(4999900 more characters)") and len(cut) < 150
    assert clip("a\nb", 10) == "a b"  # one line stays one line
    assert clip("short", 10) == "short"


def test_lines_beyond_the_burst_are_counted_and_summed_up_once_per_interval():
    said, clock = [], Clock()
    limiter = LineLimiter(said.append, burst=3, interval_s=10.0, max_chars=50, clock=clock)
    for k in range(1000):
        limiter(f"message {k}: skipped " + "y" * 1000)
    assert len(said) == 3 and all(len(line) < 100 for line in said)
    clock.now = 9.9
    limiter.tick()
    assert len(said) == 3
    clock.now = 10.0
    limiter.tick()
    assert len(said) == 4 and said[3].startswith("997 more line(s) held back in the last 10 s; the last: message 999")
    assert len(said[3]) < 150 and limiter.held_back == 997
    limiter("after")  # a new interval: lines go out again
    assert said[4] == "after"
    limiter.flush()
    assert len(said) == 5  # nothing held back: no summary


def test_the_summary_of_the_last_interval_comes_at_the_end():
    said, clock = [], Clock()
    limiter = LineLimiter(said.append, burst=1, clock=clock)
    limiter("one")
    limiter("two")
    limiter.flush()
    assert said == ["one", "1 more line(s) held back in the last 10 s; the last: two"]


def test_limits_out_of_range_are_refused():
    with pytest.raises(ValueError, match="burst"):
        LineLimiter(print, burst=0)
