"""The parts of a live stream checked against a teach-in envelope while they are cut: in memory (parts of known
content), and through ``greybox live --envelope`` with a real Mosquitto broker (twin parts at real-time pace)."""

from __future__ import annotations

import json
import time

import numpy as np
import pytest
from process_parts import good_parts, make_part

from greybox.errors import GreyboxError
from greybox.live.envelope import EnvelopeWatch, Watches, read_envelope
from greybox.live.limits import Limit, LimitWatch
from greybox.process.envelope import Envelope

BLOCK = 50


def _stream(parts, *, model: bool = False) -> dict:
    """The parts one after the other as output columns (time continuing), and each part's start [s]."""
    time_s, starts, offset = [], [], 0.0
    for part in parts:
        starts.append(offset)
        time_s.append(offset + part.time)
        offset += part.time[-1] + part.sample_time
    columns = {"time_s": np.concatenate(time_s), "velocity_mm_s": np.concatenate([p.velocity for p in parts])}
    signal = np.concatenate([p.signal for p in parts])
    if model:
        columns["current_model_A"] = np.concatenate([p.level for p in parts])
        columns["current_process_A"] = signal
        columns["current_measured_A"] = signal + columns["current_model_A"]
    else:
        columns["current_measured_A"] = signal
    return {"columns": columns, "starts": starts}


def _watched(watch, columns, block=BLOCK) -> list:
    found = []
    for start in range(0, columns["time_s"].size, block):
        found += watch.check({name: values[start:start + block] for name, values in columns.items()})
    return found


@pytest.fixture(scope="module")
def raw_envelope():
    return Envelope(false_alarm_rate=1e-3).fit(good_parts(15, seed=7), unit="A", signal={"kind": "raw"})


def test_a_breakage_is_raised_while_the_part_is_cut_and_cleared_when_the_next_part_starts(raw_envelope):
    rng = np.random.default_rng(3)
    parts = [*good_parts(3, seed=21), make_part(4, rng, wait_s=1.05, break_at_s=4.0), *good_parts(1, seed=22)]
    stream = _stream(parts)
    alarms = _watched(EnvelopeWatch(raw_envelope, kind="raw", min_rest_s=0.8), stream["columns"])
    raised = [alarm for alarm in alarms if alarm.state == "raised"]
    assert raised and all(alarm.part == 4 for alarm in raised), [alarm.line() for alarm in alarms]
    first = raised[0]
    broke = stream["starts"][3] + 4.0
    assert first.kind in ("drop", "missing cut") and first.since_s == pytest.approx(broke, abs=0.05)
    assert first.time_s <= broke + 0.05 + BLOCK * 0.002 + 1e-9  # seen while the part is cut
    cleared = [alarm for alarm in alarms if alarm.state == "cleared"]
    next_motion = stream["starts"][4] + parts[4].time[np.argmax(np.abs(parts[4].velocity) > 0.5)]
    assert len(cleared) == 1 and cleared[0].part == 4 and cleared[0].time_s == pytest.approx(next_motion)
    message = json.loads(first.message(seq=7))
    assert message["alarm"] == first.column == "envelope" and message["part"] == 4 and message["seq"] == 7


def test_a_stream_with_shorter_rests_than_the_taught_parts_is_aligned_by_the_first_motion():
    rng = np.random.default_rng(12)
    taught = [make_part(k, rng, wait_s=float(rng.uniform(3.0, 3.1))) for k in range(12)]  # cut at a loading time
    envelope = Envelope(max_shift_s=0.5).fit(taught, unit="A", signal={"kind": "raw"})
    parts = [make_part(k, rng, wait_s=1.0) for k in range(3)] + [make_part(3, rng, wait_s=1.0, break_at_s=4.0)]
    stream = _stream(parts)
    raised = [a for a in _watched(EnvelopeWatch(envelope, kind="raw", min_rest_s=0.8), stream["columns"])
              if a.state == "raised"]
    assert raised and {a.part for a in raised} == {4}  # the stream's parts 1-3 (after rests of 1.5 s) pass
    assert raised[0].since_s == pytest.approx(stream["starts"][3] + 4.0, abs=0.05)


def test_a_stream_that_starts_in_motion_waits_for_the_next_part(raw_envelope):
    rng = np.random.default_rng(5)
    parts = [make_part(1, rng, wait_s=1.05, break_at_s=4.0), *good_parts(1, seed=23)]
    stream = _stream(parts)
    late = stream["columns"]["time_s"] >= 1.2  # joined after the broken part's first motion
    alarms = _watched(EnvelopeWatch(raw_envelope, kind="raw", min_rest_s=0.8),
                      {name: values[late] for name, values in stream["columns"].items()})
    assert alarms == []


def test_a_warm_machine_passes_with_the_previous_parts_relevelling_and_not_without():
    teach = good_parts(10, seed=2, with_level=True)
    relevel = Envelope(relevel=True).fit(teach, unit="A", signal={"kind": "current"})
    plain = Envelope().fit(teach, unit="A", signal={"kind": "current"})
    warm = _stream(good_parts(4, seed=31, with_level=True, friction=0.8), model=True)["columns"]
    assert _watched(EnvelopeWatch(relevel, kind="current", min_rest_s=0.8), warm) == []
    assert any(alarm.state == "raised" for alarm in _watched(EnvelopeWatch(plain, kind="current", min_rest_s=0.8),
                                                             warm))
    rng = np.random.default_rng(8)
    broken = [*good_parts(2, seed=32, with_level=True, friction=0.8),
              make_part(3, rng, wait_s=1.05, break_at_s=4.0, friction=0.8, with_level=True)]
    stream = _stream(broken, model=True)
    raised = [a for a in _watched(EnvelopeWatch(relevel, kind="current", min_rest_s=0.8), stream["columns"])
              if a.state == "raised"]
    assert raised and raised[0].part == 3 and raised[0].since_s == pytest.approx(stream["starts"][2] + 4.0, abs=0.05)


def test_the_first_part_of_a_relevelled_stream_is_checked_whole_at_its_end():
    teach = good_parts(10, seed=2, with_level=True)
    relevel = Envelope(relevel=True).fit(teach, unit="A", signal={"kind": "current"})
    rng = np.random.default_rng(9)
    parts = [make_part(1, rng, wait_s=1.05, break_at_s=4.0, with_level=True), *good_parts(1, seed=33, with_level=True)]
    stream = _stream(parts, model=True)
    alarms = _watched(EnvelopeWatch(relevel, kind="current", min_rest_s=0.8), stream["columns"])
    raised = [alarm for alarm in alarms if alarm.state == "raised"]
    assert raised and raised[0].part == 1 and raised[0].since_s == pytest.approx(4.0, abs=0.05)
    assert raised[0].time_s >= parts[0].time[-1] - 0.6  # at the part's end (the next part's start), not while cut


def test_a_gap_ends_the_part_and_a_limit_watches_beside_the_envelope(raw_envelope):
    rng = np.random.default_rng(4)
    parts = [*good_parts(1, seed=24), make_part(2, rng, wait_s=1.05, break_at_s=4.0)]
    columns = _stream(parts)["columns"]
    both = Watches([LimitWatch([Limit("current_measured_A", 1e6)]), EnvelopeWatch(raw_envelope, kind="raw",
                                                                                  min_rest_s=0.8)])
    both.check_columns(list(columns))
    raised = [alarm for alarm in _watched(both, columns) if alarm.state == "raised"]
    assert raised and {alarm.column for alarm in raised} == {"envelope"}
    ended = both.rearm(float(columns["time_s"][-1]))  # the broken part checked whole, its alarm cleared
    assert [(alarm.state, alarm.whole_part) for alarm in ended] == [("raised", True), ("cleared", False)]
    assert both.rearm() == []


def test_the_last_part_is_checked_whole_when_the_stream_ends_and_its_alarm_stays_raised(raw_envelope):
    rng = np.random.default_rng(6)
    parts = [*good_parts(1, seed=25), make_part(2, rng, wait_s=1.05, break_at_s=4.0)]
    columns = _stream(parts)["columns"]
    both = Watches([LimitWatch([Limit("current_measured_A", 1e6)]), EnvelopeWatch(raw_envelope, kind="raw",
                                                                                  min_rest_s=0.8)])
    both.check_columns(list(columns))
    _watched(both, columns)
    last = float(columns["time_s"][-1])
    ended = both.end_run(last)  # the end of the input: the broken part's mean deviation, raised and kept
    assert [(alarm.part, alarm.state, alarm.whole_part, alarm.kind) for alarm in ended] == [(2, "raised", True,
                                                                                           "drop")]
    assert both.end_run(last) == []  # once
    cleared = both.rearm(last + 5.0)  # the next run: the part's alarm cleared
    assert [(alarm.part, alarm.state) for alarm in cleared] == [(2, "cleared")]
    assert both.rearm() == []


@pytest.mark.slow
def test_live_checks_the_streams_last_part_whole_at_the_end_of_its_input(twin_parts):
    import io

    from live_helpers import EXAMPLE_AXIS, json_batches

    from greybox.live.run import run_live

    out, said = io.StringIO(), []
    run_live(twin_parts["model"], source="-", axis_config_path=EXAMPLE_AXIS, envelope_path=twin_parts["envelope"],
             stdin=io.StringIO("\n".join(json_batches(twin_parts["log"], (250,)))), stdout=out, say=said.append)
    alarms = [json.loads(line) for line in out.getvalue().splitlines() if '"alarm"' in line]
    whole = [alarm for alarm in alarms if alarm.get("whole_part")]
    assert [(alarm["part"], alarm["state"], alarm["kind"]) for alarm in whole] == [(3, "raised", "drop")]
    assert whole[0]["time_s"] == pytest.approx(float(twin_parts["log"].time[-1]))
    assert not [alarm for alarm in alarms if alarm["part"] == 3 and alarm["state"] == "cleared"]


def test_an_envelope_of_a_signal_the_output_lacks_is_refused_in_one_line(tmp_path):
    force = Envelope().fit(good_parts(5, seed=1), unit="N", signal={"kind": "force"})
    watch = EnvelopeWatch(force, kind="force", name="env.json")
    with pytest.raises(GreyboxError, match="env.json: taught on the force signal.*--axis-config"):
        watch.check_columns(["time_s", "current_measured_A", "current_model_A", "current_process_A",
                             "velocity_mm_s"])
    path = tmp_path / "env.json"
    Envelope().fit(good_parts(5, seed=1), unit="A", signal={"kind": "current", "model_sha256": "0" * 64}).save(path)
    model = tmp_path / "model.gbm"
    model.write_bytes(b"another model")
    with pytest.raises(GreyboxError, match="taught with another model file than model.gbm"):
        read_envelope(path, model_path=model)
    (tmp_path / "bad.json").write_text("{\"format\": 1}")
    with pytest.raises(GreyboxError, match="bad.json: not a valid envelope file"):
        read_envelope(tmp_path / "bad.json", model_path=model)


@pytest.fixture
def twin_parts(tmp_path, model_file):
    """A re-levelled force envelope taught on ten twin parts of a one-pass program through a fast warm-up, the
    model it was taught with, and parts 10-12 (12 breaks 4.5 s after its log start) as one log."""
    from live_helpers import EXAMPLE_AXIS

    from greybox.data.io import write_log
    from greybox.process.run import teach_logs
    from greybox.twin.part_series import PartSeriesSpec, ToolEvents, WarmUp, make_part_series, part_program

    spec = PartSeriesSpec(parts=12, program=part_program("X", (600.0,)), loading_s=2.5, jitter_s=0.1,
                          events=ToolEvents(breakage_part=12, breakage_time_s=4.5),
                          warm_up=WarmUp(drop=0.25, time_constant_s=300.0))
    logs, truth = make_part_series(spec, seed=5)
    paths = []
    for log in logs[:10]:
        paths.append(tmp_path / f"part{len(paths) + 1:02d}.csv")
        write_log(log.replace(extras={}), paths[-1])
    model = model_file("gms")
    teach_logs(paths, tmp_path / "force.json", model=str(model), axis_config=str(EXAMPLE_AXIS), relevel=True)
    streamed = logs[9:12]
    starts = [part["series_start_s"] for part in truth["parts"][9:12]]
    time_s = np.concatenate([start + log.time for start, log in zip(starts, streamed)])
    log = streamed[0].replace(time=time_s, position=np.concatenate([log.position for log in streamed]),
                              effort=np.concatenate([log.effort for log in streamed]),
                              velocity=np.concatenate([log.velocity for log in streamed]), extras={})
    return {"model": model, "envelope": tmp_path / "force.json", "log": log, "starts": starts,
            "breakage_s": starts[2] + 4.5}


@pytest.mark.slow
def test_live_flags_a_breakage_on_the_broker_while_the_part_is_cut(broker, twin_parts, tmp_path):
    """Parts 10-12 at real-time pace (0.1 s a message): part 10 is the stream's first (checked whole at its end),
    the good part 11 raises nothing, the breakage of part 12 is raised before the part's motion ends."""
    from live_helpers import EXAMPLE_AXIS, LiveProcess, Subscriber, json_batches, wait_until

    out = Subscriber(broker.port, "process/X/alarm/#")
    live = LiveProcess(twin_parts["model"], "--source", broker.url("axis/X"), "--sink", broker.url("process/X"),
                       "--axis-config", EXAMPLE_AXIS, "--envelope", twin_parts["envelope"], "--connect-timeout", "20")
    try:
        wait_until(lambda: live.said("reading mqtt://") or live.process.poll() is not None, "greybox live to connect")
        assert live.process.poll() is None, live.lines
        log = twin_parts["log"]
        messages = json_batches(log, (50,))
        step = 50 * log.sample_time
        last_motion = float(log.time[np.flatnonzero(np.abs(log.velocity) > 0.5)[-1]])  # part 12's
        published_at, began = {}, time.monotonic()
        for k, message in enumerate(messages):
            time.sleep(max(0.0, began + k * step - time.monotonic()))
            out.publish("axis/X", message, wait=False)
            published_at[k] = float(log.time[min((k + 1) * 50, len(log)) - 1])  # the last sample published
            if out.payloads("process/X/alarm/envelope") and "alarm_seen_s" not in twin_parts:
                twin_parts["alarm_seen_s"] = published_at[k]
        wait_until(lambda: live.said("ENVELOPE ALARM CLEARED") or len(out.payloads("process/X/alarm/envelope")) > 0,
                   "the alarm", timeout_s=10)
    finally:
        status = live.stop()
        out.close()
    alarms = [json.loads(payload) for payload in out.payloads("process/X/alarm/envelope")]
    raised = [alarm for alarm in alarms if alarm["state"] == "raised"]
    assert status == 143 and raised, live.lines
    assert {alarm["part"] for alarm in raised} == {3}, alarms  # parts 10 and 11 pass
    first = raised[0]
    assert first["kind"] in ("drop", "missing cut") and not first["whole_part"]
    assert first["since_s"] == pytest.approx(twin_parts["breakage_s"], abs=0.2)
    assert twin_parts["alarm_seen_s"] < last_motion  # on the broker while the part is still cut
