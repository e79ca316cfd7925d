"""Fed the samples of a log, the live estimates equal the table ``greybox predict`` writes for it (1e-9 A),
for every kind a model file may hold, whatever the batching of the messages."""

from __future__ import annotations

import io

import numpy as np
import pytest
from live_helpers import EXAMPLE_AXIS, QUICK, joined, json_batches

from greybox.data.prepare import derivative_margin
from greybox.live.run import run_live
from greybox.models import registry

#: Message sizes in turn: single samples, controller batches of 10, odd sizes.
SIZES = (1, 10, 7, 1, 25, 3)


def test_every_kind_a_model_file_may_hold_is_covered():
    assert set(QUICK) == set(registry.MODEL_CLASSES) | set(registry.DERIVED_MODEL_CLASSES)


def live_table(model_path, messages, **options) -> tuple[dict, object]:
    out, said = io.StringIO(), []
    outcome = run_live(model_path, source="-", axis_config_path=EXAMPLE_AXIS, stdin=io.StringIO("\n".join(messages)),
                       stdout=out, say=said.append, **options)
    return joined(out.getvalue().splitlines()), outcome


@pytest.mark.parametrize("kind", sorted(QUICK))
def test_live_equals_predict(kind, model_file, offline, cut_raw):
    path = model_file(kind)
    expected = offline(path)
    live, outcome = live_table(path, json_batches(cut_raw, SIZES))
    assert list(live) == list(expected.columns)
    for name in expected.columns:
        np.testing.assert_allclose(live[name], expected[name].to_numpy(), rtol=0, atol=1e-9, err_msg=name)
    assert outcome.stats.samples_estimated == outcome.stats.samples_received == len(cut_raw)


def test_the_lookahead_is_what_makes_it_exact(model_file, offline, cut_raw):
    """Deriving each message's samples without the samples after them (as a causal filter must) differs."""
    from greybox.data.prepare import derive

    path = model_file("gms")
    expected = offline(path)["current_model_A"].to_numpy()
    margin = derivative_margin(cut_raw.sample_time)
    head = derive(cut_raw.select(slice(0, 3 * margin)))  # the first stretch derived alone, without what follows
    whole = derive(cut_raw)
    assert np.max(np.abs(head.acceleration[-10:] - whole.acceleration[3 * margin - 10:3 * margin])) > 1.0
    assert expected.size == len(cut_raw)


def test_messages_with_velocity_and_acceleration_need_no_lookahead(model_file, offline, cut_raw, live_root):
    from greybox.data.prepare import prepare

    prepared = prepare([cut_raw])[0]  # velocity and acceleration present: the messages carry both
    path = model_file("gmssvr")
    expected = offline(path, prepared, name="cut-prepared")
    out, said = io.StringIO(), []
    stdin = io.StringIO("\n".join(json_batches(prepared, (10,))))
    run_live(path, source="-", axis_config_path=EXAMPLE_AXIS, stdin=stdin, stdout=out, say=said.append,
             sample_time=0.002)
    lines = out.getvalue().splitlines()
    # with the step given, each message's estimates come with the message itself
    assert '"seq":0' in lines[0] and len(lines) == -(-len(prepared) // 10)
    live = joined(lines)
    np.testing.assert_allclose(live["current_model_A"], expected["current_model_A"].to_numpy(), rtol=0, atol=1e-9)
    assert not any("look-ahead" in line for line in said)


def test_csv_lines_equal_json_messages(model_file, cut_raw):
    path = model_file("lugre")
    header = "time_s,position_mm,velocity_mm_s,current_A"
    rows = [f"{t!r},{p!r},{v!r},{c!r}" for t, p, v, c in
            zip(cut_raw.time.tolist(), cut_raw.position.tolist(), cut_raw.velocity.tolist(), cut_raw.effort.tolist())]
    from_csv, _ = live_table(path, [header, *rows])
    from_json, _ = live_table(path, json_batches(cut_raw, (1,)))
    for name in from_json:
        np.testing.assert_array_equal(from_csv[name], from_json[name])
