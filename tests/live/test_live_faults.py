"""Faults of a stream on stdin: malformed and out-of-range messages, time going backwards, a gap; each is
counted and said in one line, and the stream goes on with the estimates it would have given without it."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest
from live_helpers import EXAMPLE_AXIS, joined, json_batches

from greybox.data.blocks import concatenate
from greybox.errors import GreyboxError
from greybox.live.limits import Limit
from greybox.live.run import ALARM_STATUS, run_live


def run(model_path, messages, **options):
    out, said = io.StringIO(), []
    outcome = run_live(model_path, source="-", axis_config_path=EXAMPLE_AXIS, stdin=io.StringIO("\n".join(messages)),
                       stdout=out, say=said.append, **options)
    return joined(out.getvalue().splitlines()), outcome, said, out.getvalue().splitlines()


def assert_same(live, expected):
    for name in expected:
        np.testing.assert_allclose(live[name], np.asarray(expected[name]), rtol=0, atol=1e-9, err_msg=name)


def accounted(stats) -> bool:
    """Every sample received is estimated, dropped, lost or waiting."""
    return stats.samples_received == stats.samples_estimated + stats.skipped + stats.waiting


BAD = [
    "this is not JSON",
    '{"time_s": "0.1", "position_mm": 1.0, "velocity_mm_s": 0.0, "current_A": 0.1}',
    '{"time_s": [0.1, 0.2], "position_mm": [1.0], "velocity_mm_s": [0, 0], "current_A": [0, 0]}',
    '{"time_s": 0.1, "position_mm": NaN, "velocity_mm_s": 0.0, "current_A": 0.1}',
    '{"time_s": 0.1, "position_mm": 1.0, "velocity_mm_s": 0.0}',
    '{"time_s": 0.1, "position_mm": 1.0, "current_A": 0.1}',
    '{"time_s": 0.1, "position_mm": 1.0, "velocity_furlong_s": 0.0, "current_A": 0.1}',
    "[]",
    '{"time_s": 0.1, "position_mm": 1.0, "velocity_mm_s": Infinity, "current_A": 0.1}',
]


def test_malformed_and_out_of_range_messages_are_skipped(model_file, cut_raw):
    path = model_file("gms")
    clean = json_batches(cut_raw, (10,))
    expected, _, _, _ = run(path, clean)
    messages = list(clean)
    for k, bad in enumerate(BAD):
        messages.insert(3 + 5 * k, bad)
    live, outcome, said, _ = run(path, messages)
    assert_same(live, expected)
    assert outcome.stats.rejected == len(BAD)
    skipped = [line for line in said if "skipped" in line]
    assert len(skipped) == len(BAD)
    assert all(line.startswith("stdin line ") for line in skipped)  # each names the message
    assert accounted(outcome.stats) and outcome.stats.samples_estimated == len(cut_raw)


def test_time_going_backwards_or_too_soon_drops_the_sample(model_file, cut_raw):
    path = model_file("gmssvr")
    clean = json_batches(cut_raw, (10,))
    expected, _, _, _ = run(path, clean)
    back = cut_raw.select(slice(95, 96))  # a repeat of an earlier sample, sent after sample 199
    early = cut_raw.select(slice(309, 310)).replace(time=cut_raw.time[309:310] + 0.0003)  # 0.3 ms after sample 309
    messages = list(clean)
    messages.insert(20, json_batches(back, (1,))[0])
    messages.insert(32, json_batches(early, (1,))[0])
    live, outcome, said, _ = run(path, messages)
    assert_same(live, expected)
    assert outcome.stats.dropped == {"backwards": 1, "early": 1}
    assert sum(line.startswith("1 sample(s) dropped") for line in said) == 2
    assert accounted(outcome.stats)


def test_a_gap_starts_a_new_run_as_predict_splits_the_log(model_file, offline, cut_raw):
    """Samples 400-499 missing (a 202 ms gap): the state restarts there, as ``greybox predict --resample``
    splits the log at the gap; the table equals that of predict on the log with the gap."""
    path = model_file("gms")
    gapped = concatenate([cut_raw.select(slice(0, 400)), cut_raw.select(slice(500, None))])
    expected = offline(path, gapped, name="gap", extra=["--resample", "0.002"])
    live, outcome, said, _ = run(path, json_batches(gapped, (10,)))
    assert_same(live, {name: expected[name] for name in expected.columns})
    assert outcome.stats.gaps == 1
    assert [line for line in said if line.startswith("gap of")][0].startswith("gap of 202 ms")
    # without the restart the second run would be predicted from the state the first one ended in
    assert accounted(outcome.stats) and outcome.stats.samples_estimated == len(gapped)


def test_a_run_too_short_to_derive_is_counted_lost(model_file, cut_raw):
    path = model_file("coulomb")
    gapped = concatenate([cut_raw.select(slice(0, 400)), cut_raw.select(slice(500, 510)),
                          cut_raw.select(slice(600, None))])
    _, outcome, said, _ = run(path, json_batches(gapped, (10,)))
    assert outcome.stats.gaps == 2
    assert sum(outcome.stats.lost.values()) == 10
    assert any("lost" in line for line in said)
    assert accounted(outcome.stats)


def test_limits_raise_one_alarm_per_stretch_and_can_end_the_stream(model_file, cut_raw):
    path = model_file("gms")
    expected, _, _, _ = run(path, json_batches(cut_raw, (10,)))
    force = np.abs(expected["force_process_N"])
    bound = float(np.percentile(force, 97))
    live, outcome, said, lines = run(path, json_batches(cut_raw, (10,)), limits=[Limit("force_process_N", bound)],
                                     hold_s=0.004)
    # the reference: stretches of samples above the bound lasting at least 4 ms (3 samples at 2 ms)
    above = np.concatenate(([False], force > bound, [False]))
    starts, stops = np.flatnonzero(np.diff(above.astype(int)) == 1), np.flatnonzero(np.diff(above.astype(int)) == -1)
    long_stretches = int(np.sum(stops - starts >= 3))
    assert long_stretches >= 1
    assert outcome.stats.alarms == long_stretches
    alarms = [json.loads(line) for line in lines if '"alarm"' in line]
    raised = [alarm for alarm in alarms if alarm["state"] == "raised"]
    assert len(raised) == long_stretches and all(alarm["value"] > bound for alarm in raised)
    assert sum(line.startswith("ALARM:") for line in said) == long_stretches
    # each is cleared at the first sample back within the limit (the stretches ending before the log does)
    ended = (stops - starts >= 3) & (stops < len(force))
    cleared = [alarm for alarm in alarms if alarm["state"] == "cleared"]
    assert len(cleared) == outcome.stats.alarms_cleared == int(np.sum(ended))
    assert [alarm["time_s"] for alarm in cleared] == pytest.approx(list(expected["time_s"][stops[ended]]), abs=1e-12)
    # the seq of the message whose samples raised or cleared it (none for the tail finished at the end)
    assert all("wall_time" in alarm and "seq" in alarm for alarm in alarms)
    assert any(isinstance(alarm["seq"], int) for alarm in alarms)
    _, stopped, _, _ = run(path, json_batches(cut_raw, (10,)), limits=[Limit("force_process_N", bound)],
                           hold_s=0.004, exit_on_alarm=True)
    assert stopped.status == ALARM_STATUS and stopped.stats.alarms == 1
    assert stopped.stats.samples_estimated < len(cut_raw)


def test_a_limit_on_a_column_the_output_lacks_is_refused(model_file, cut_raw):
    with pytest.raises(GreyboxError, match="--limit force_N: no such output column"):
        run(model_file("coulomb"), json_batches(cut_raw, (10,)), limits=[Limit("force_N", 5.0)])


def test_recording_is_the_predict_table_in_rolling_files(model_file, offline, cut_raw, tmp_path):
    import pandas as pd
    import pyarrow.parquet as pq

    path = model_file("gmssvr")
    expected = offline(path)
    _, outcome, _, _ = run(path, json_batches(cut_raw, (10,)), record_dir=tmp_path / "rec", record_s=0.5)
    files = sorted((tmp_path / "rec").iterdir())
    assert files == sorted(outcome.recorded)
    parts = [pd.read_parquet(file) for file in files]
    spans = [part["time_s"].iloc[-1] - part["time_s"].iloc[0] for part in parts]
    assert len(files) >= 3 and all(0.5 <= span < 0.5 + 0.025 for span in spans[:-1])  # 0.5 s each, and a rest
    table = pd.concat(parts, ignore_index=True)
    assert list(table.columns) == list(expected.columns)
    np.testing.assert_allclose(table.to_numpy(), expected.to_numpy(), rtol=0, atol=1e-9)
    meta = json.loads(pq.read_schema(files[0]).metadata[b"greybox"])
    assert meta["attrs"]["model_kind"] == "gmssvr" and meta["attrs"]["live"]["file"] == 0


def test_a_deep_and_a_huge_message_give_one_short_line_each_and_the_stream_goes_on(model_file, cut_raw):
    path = model_file("gms")
    clean = json_batches(cut_raw, (10,))
    expected, _, _, _ = run(path, clean)
    deep = "[" * 1000 + "]" * 1000
    huge = '{"time_s": [' + "1.0, " * (50 * 2**20 // 5) + "1.0]}"  # 50 MB
    messages = list(clean)
    messages.insert(7, deep)
    messages.insert(30, huge)
    live, outcome, said, _ = run(path, messages)
    assert_same(live, expected)
    skipped = [line for line in said if "skipped" in line]
    assert len(skipped) == 2 and all(len(line) <= 400 for line in said)
    assert "nested 1000 levels deep" in skipped[0] and f"holds {len(huge) + 1} bytes" in skipped[1]
    assert outcome.stats.rejected == 2 and outcome.stats.samples_estimated == len(cut_raw)


def test_a_flood_of_malformed_messages_is_summed_up(model_file, cut_raw):
    path = model_file("coulomb")
    messages = json_batches(cut_raw, (10,))
    flood = [f"not JSON {k} " + "z" * 10_000 for k in range(500)]
    live, outcome, said, _ = run(path, messages[:5] + flood + messages[5:], lines_per_interval=5)
    assert outcome.stats.rejected == 500 and outcome.stats.samples_estimated == len(cut_raw)
    summary = [line for line in said if "held back" in line]
    assert len(summary) == 1 and summary[0].endswith("the last: stdin line 505: skipped: not JSON (a CSV header must "
                                                     "be the stream's first line)")
    held = int(summary[0].split()[0])
    said_skipped = sum(line.startswith("stdin line") for line in said)
    assert said_skipped <= 5 and said_skipped + held == 500  # five lines of the stream at most, the rest counted
    assert all(len(line) <= 700 for line in said)
