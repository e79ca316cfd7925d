"""The run of a stream: its network threads get the GIL within the short switch interval while it runs."""

from __future__ import annotations

import io
import sys

from live_helpers import json_batches

from greybox.live.run import SWITCH_INTERVAL_S, responsive_threads, run_live


def test_the_switch_interval_is_short_while_the_stream_runs_and_set_back_after(model_file, cut_raw):
    before = sys.getswitchinterval()
    assert SWITCH_INTERVAL_S < before  # CPython's default (5 ms) is longer
    seen = []
    messages = json_batches(cut_raw.select(slice(0, 400)), [10] * 40)
    run_live(model_file("coulomb"), source="-", stdin=io.StringIO("\n".join(messages)), stdout=io.StringIO(),
             say=lambda line: seen.append(sys.getswitchinterval()), sample_time=cut_raw.sample_time)
    assert seen and seen[1] == SWITCH_INTERVAL_S  # the lines said while the stream runs (after the start line)
    assert sys.getswitchinterval() == before


def test_the_switch_interval_is_set_back_after_an_error():
    before = sys.getswitchinterval()
    try:
        with responsive_threads(0.001):
            assert sys.getswitchinterval() == 0.001
            raise KeyboardInterrupt
    except KeyboardInterrupt:
        pass
    assert sys.getswitchinterval() == before
