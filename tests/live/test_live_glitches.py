"""Short glitches bridged as ``greybox predict --resample --max-gap`` bridges them (``greybox live --max-gap``):
a NaN or a JSON null in a batch and time stamps jittered by +-0.3 ms keep the run going, with the estimates of ``greybox
predict`` on the same log; a gap longer than ``--max-gap`` starts a new run once."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest
from live_helpers import EXAMPLE_AXIS, joined, json_batches

from greybox.live.run import run_live

#: ``greybox predict``'s bridging of the same log, and the live option.
STEP, MAX_GAP = 0.002, 5.0
PREDICT = ["--resample", str(STEP), "--max-gap", str(MAX_GAP)]
#: Largest difference allowed from ``greybox predict`` [A]: the same interpolation on the same grid, so
#: only rounding differs.
TOLERANCE_A = 1e-9


def live(model_path, messages, **options):
    out, said = io.StringIO(), []
    outcome = run_live(model_path, source="-", axis_config_path=EXAMPLE_AXIS, stdin=io.StringIO("\n".join(messages)),
                       stdout=out, say=said.append, sample_time=STEP, max_gap=MAX_GAP, **options)
    return joined(out.getvalue().splitlines()), outcome, said


def jittered(log, seed=7, jitter_s=0.3e-3):
    rng = np.random.default_rng(seed)
    return log.replace(time=log.time + rng.uniform(-jitter_s, jitter_s, len(log)))


def assert_as_predict(live_table, expected):
    assert len(live_table["time_s"]) == len(expected)
    for name in ("time_s", "current_model_A", "current_process_A", "force_process_N"):
        np.testing.assert_allclose(live_table[name], expected[name].to_numpy(), rtol=0, atol=TOLERANCE_A,
                                   err_msg=name)


@pytest.mark.parametrize("kind", ["gms", "gmssvr"])
def test_jitter_is_bridged_as_predict_resamples(kind, model_file, offline, cut_raw):
    log = jittered(cut_raw)
    steps = np.diff(log.time)
    assert steps.max() > 1.25 * STEP and steps.min() < 0.75 * STEP  # beyond the tolerance that splits runs
    path = model_file(kind)
    expected = offline(path, log, name="cut-jittered", extra=PREDICT)
    table, outcome, said = live(path, json_batches(log, (10,)))
    assert_as_predict(table, expected)
    assert outcome.stats.gaps == 0 and not outcome.stats.dropped
    assert not any(line.startswith("gap of") for line in said)


def test_without_max_gap_the_jitter_resets_the_state(model_file, cut_raw):
    out, said = io.StringIO(), []
    outcome = run_live(model_file("gms"), source="-", axis_config_path=EXAMPLE_AXIS, sample_time=STEP,
                       stdin=io.StringIO("\n".join(json_batches(jittered(cut_raw), (10,)))), stdout=out,
                       say=said.append)
    assert outcome.stats.gaps > 0


def test_a_nan_in_a_batch_is_left_out_and_bridged(model_file, offline, cut_raw):
    path = model_file("gmssvr")
    messages = json_batches(cut_raw, (10,))
    message = json.loads(messages[40])
    message["current_A"][3] = float("nan")  # sample 403
    messages[40] = json.dumps(message)
    without = cut_raw.select(np.flatnonzero(np.arange(len(cut_raw)) != 403))
    expected = offline(path, without, name="cut-without-403", extra=PREDICT)
    table, outcome, said = live(path, messages)
    assert_as_predict(table, expected)
    assert len(table["time_s"]) == len(cut_raw)  # the sample left out is interpolated back
    assert outcome.stats.gaps == 0 and outcome.stats.rejected == 0
    assert outcome.stats.dropped == {"not finite": 1}
    assert sum("NaN" in line for line in said) == 1


def test_a_gap_longer_than_max_gap_starts_a_new_run_once(model_file, offline, cut_raw):
    path = model_file("gms")
    keep = np.flatnonzero((np.arange(len(cut_raw)) < 300) | (np.arange(len(cut_raw)) >= 320))  # 42 ms away
    log = jittered(cut_raw.select(keep))
    table, outcome, said = live(path, json_batches(log, (10,)))
    assert outcome.stats.gaps == 1
    assert sum(line.startswith("gap of") for line in said) == 1
    expected = offline(path, log, name="cut-gap", extra=PREDICT)  # split into two runs there too
    assert_as_predict(table, expected)


def test_a_json_null_is_a_missing_value_bridged_as_a_nan(model_file, offline, cut_raw):
    path = model_file("gms")
    messages = json_batches(cut_raw, (10,))
    message = json.loads(messages[40])
    message["position_mm"][3] = None  # sample 403, written as null
    messages[40] = json.dumps(message)
    assert "null" in messages[40]
    without = cut_raw.select(np.flatnonzero(np.arange(len(cut_raw)) != 403))
    expected = offline(path, without, name="cut-without-403", extra=PREDICT)
    table, outcome, said = live(path, messages)
    assert_as_predict(table, expected)
    assert outcome.stats.gaps == 0 and outcome.stats.rejected == 0
    assert outcome.stats.dropped == {"not finite": 1}


def test_nulls_longer_than_max_gap_make_one_gap(model_file, offline, cut_raw):
    path = model_file("gms")
    missing = np.arange(300, 320)  # 20 samples, 42 ms between the finite ones: beyond --max-gap
    messages = [json.loads(text) for text in json_batches(cut_raw, (10,))]
    for k in missing:
        messages[k // 10]["current_A"][k % 10] = None
    table, outcome, said = live(path, [json.dumps(message) for message in messages])
    assert outcome.stats.gaps == 1 and outcome.stats.rejected == 0
    assert sum(line.startswith("gap of") for line in said) == 1
    keep = np.flatnonzero(~np.isin(np.arange(len(cut_raw)), missing))
    expected = offline(path, cut_raw.select(keep), name="cut-nulls", extra=PREDICT)
    assert_as_predict(table, expected)


def test_without_max_gap_a_null_is_refused_in_one_line(model_file, cut_raw):
    messages = json_batches(cut_raw, (10,))
    message = json.loads(messages[5])
    message["current_A"][2] = None
    messages[5] = json.dumps(message)
    out, said = io.StringIO(), []
    outcome = run_live(model_file("gms"), source="-", axis_config_path=EXAMPLE_AXIS, sample_time=STEP,
                       stdin=io.StringIO("\n".join(messages)), stdout=out, say=said.append)
    assert outcome.stats.rejected == 1
    skipped = [line for line in said if "skipped" in line]
    assert len(skipped) == 1 and "line 6: skipped: channel 'current_A' holds nan at sample 2" in skipped[0], said
