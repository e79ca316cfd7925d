"""Logs read, prepared, predicted and written block by block equal the whole-log path."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import greybox.cli as cli
from greybox.data.blocks import CannotStream, concatenate
from greybox.data.io import read_log, write_log
from greybox.data.mcap_io import McapLog
from greybox.data.prepare import derivative_margin, prepare
from greybox.data.stream import ParquetLog, median_step, open_stream, prepared_blocks
from greybox.errors import LogError
from greybox.models.files import save_model
from greybox.models.friction import GMSModel
from greybox.models.gmssvr import GMSSVRModel
from greybox.twin import make_dataset

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "axis_x.toml"


def _blocks_of(values: np.ndarray, size: int):
    return lambda: (values[k:k + size] for k in range(0, len(values), size))


@pytest.mark.parametrize("size", [1, 2, 7, 1000, 10_000])
@pytest.mark.parametrize("kind", ["uniform", "jitter", "ns", "odd"])
def test_median_step_is_numpys_median_of_the_steps(kind, size):
    rng = np.random.default_rng(len(kind) + size)
    n = {"uniform": 5000, "jitter": 5001, "ns": 4000, "odd": 3}[kind]
    if kind == "uniform":
        time = 12.5 + np.arange(n) * 0.002
    elif kind == "jitter":
        time = np.cumsum(0.002 * (1.0 + 0.2 * rng.uniform(-1, 1, n)))
    elif kind == "ns":
        time = np.cumsum(rng.integers(1_990_000, 2_010_000, n)) * 1e-9
    else:
        time = np.array([0.0, 0.5, 0.75])
    assert median_step(_blocks_of(time, size)) == np.median(np.diff(time))


@pytest.mark.parametrize("limit", [1, 10, 1 << 16])
def test_median_step_reads_a_uniform_log_once_and_an_irregular_one_twice(monkeypatch, limit):
    from greybox.data import stream

    monkeypatch.setattr(stream, "_MAX_DISTINCT_STEPS", limit)
    rng = np.random.default_rng(limit)
    for time, irregular in ((np.arange(4001) * 0.002, False),
                            (np.cumsum(0.002 * (1.0 + 0.2 * rng.uniform(-1, 1, 4000))), True)):
        passes = []

        def times(time=time, passes=passes):
            passes.append(1)
            return _blocks_of(time, 333)()

        assert median_step(times) == np.median(np.diff(time))
        distinct = np.unique(np.diff(time)).size
        assert len(passes) == (2 if distinct > limit else 1)
        assert irregular == (distinct > 100)


def test_median_step_names_the_sample_where_time_goes_back():
    time = np.arange(100) * 0.01
    time[61] = time[60]
    with pytest.raises(LogError, match="time repeats at sample 61"):
        median_step(_blocks_of(time, 7), "log.parquet")
    with pytest.raises(LogError, match="has 1 sample"):
        median_step(_blocks_of(np.array([3.0]), 5))


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    root = tmp_path_factory.mktemp("stream")
    cut = make_dataset("X", "C", seed=3, duration_s=40, cutting=True)  # logged velocity: acceleration derived
    without_velocity = cut.replace(velocity=None)  # both derived from the position
    paths = {}
    for suffix in (".parquet", ".mcap"):
        paths["cut" + suffix] = root / f"cut{suffix}"
        paths["position_only" + suffix] = root / f"position_only{suffix}"
        write_log(cut, paths["cut" + suffix])
        write_log(without_velocity, paths["position_only" + suffix])
    return paths


@pytest.mark.parametrize("suffix", [".parquet", ".mcap"])
@pytest.mark.parametrize("name", ["cut", "position_only"])
@pytest.mark.parametrize("cutoff_hz", [None, 2.0])
def test_prepared_blocks_join_into_the_prepared_whole_log(logs, name, cutoff_hz, suffix):
    path = logs[name + suffix]
    (whole,) = prepare([read_log(path)], cutoff_hz=cutoff_hz)
    stream = open_stream(path, block_samples=997)  # blocks end where the row groups (MCAP chunks) do not
    blocks = list(prepared_blocks(stream, cutoff_hz=cutoff_hz))
    margin = derivative_margin(whole.sample_time, cutoff_hz=cutoff_hz)
    assert len(blocks) == -(-len(whole) // max(997, margin))  # the margin of a low cut-off widens the blocks
    joined = concatenate(blocks)
    logged = ("time", "position", "effort") + (("velocity",) if name == "cut" else ())
    for channel in logged:
        np.testing.assert_array_equal(getattr(joined, channel), getattr(whole, channel))
    # derived channels: the filter's rounding differs with where it starts (a low cut-off amplifies it),
    # its result does not; without the margins the difference is 1e-3 of the scale (the test below)
    for channel in ("velocity", "acceleration"):
        scale = np.max(np.abs(getattr(whole, channel)))
        assert np.max(np.abs(getattr(joined, channel) - getattr(whole, channel))) <= 1e-9 * scale
    assert joined.extras.keys() == whole.extras.keys()
    assert joined.attrs["derivative_filter"] == whole.attrs["derivative_filter"]


def test_a_block_too_short_for_the_filter_margin_would_differ(logs):
    """The margin matters: without it the blocks' derivatives differ from the whole log's near the seams."""
    (whole,) = prepare([read_log(logs["cut.parquet"])])
    from greybox.data.prepare import derive

    stream = ParquetLog(logs["cut.parquet"], block_samples=997)
    naive = concatenate([derive(block, sample_time=whole.sample_time) for block in stream.blocks()])
    assert np.max(np.abs(naive.acceleration - whole.acceleration)) > 1e-3 * np.max(np.abs(whole.acceleration))


def test_a_last_piece_of_one_sample_joins_the_block_before(tmp_path):
    log = make_dataset("X", "A", seed=4, duration_s=6)
    path = tmp_path / "odd.parquet"
    write_log(log.select(slice(0, 2001)), path)
    sizes = [len(block) for block in ParquetLog(path, block_samples=1000).blocks()]
    assert sizes == [1000, 1001]


@pytest.mark.parametrize(("damage", "message"), [
    ("gap", "gap of"), ("nan", r"holds nan at t = .* \(sample 1500; 1 non-finite value in samples 1000 to 1999"),
    ("backwards", "time goes backwards at sample 1000"),
])
def test_errors_name_the_sample_of_the_whole_log(tmp_path, damage, message):
    log = make_dataset("X", "A", seed=5, duration_s=10)
    time, effort = log.time.copy(), log.effort.copy()
    if damage == "gap":
        time[1500:] += 0.5
    elif damage == "nan":
        effort[1500] = np.nan
    else:
        time[1000] = time[998]
    path = tmp_path / "damaged.parquet"
    write_log(log.replace(time=time, effort=effort), path)
    with pytest.raises(LogError, match=message):
        list(prepared_blocks(ParquetLog(path, block_samples=1000)))


# ------------------------------------------------------------------ greybox predict, streamed


@pytest.fixture(autouse=True)
def predict_registered(monkeypatch):
    if "predict" not in cli.COMMANDS:
        monkeypatch.setattr(cli, "COMMANDS", tuple(cli.COMMANDS) + ("predict",))


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    root = tmp_path_factory.mktemp("stream_models")
    train = prepare([make_dataset("X", "A", seed=11, duration_s=30)])
    gms = GMSModel(n_starts=1, max_iter=80).fit(train)
    # the GMS+SVR freezes that GMS: the stage its own fit on these runs would identify (tests/models/test_contract.py)
    gmssvr = GMSSVRModel(gms=GMSModel(n_starts=1, max_iter=80), optimize=False, C=0.5, epsilon=0.02, gamma=3.0,
                         n_subset=400).fit_staged(train, first_stage=gms)
    paths = {"gms": root / "gms.gbm", "gmssvr": root / "gmssvr.gbm"}
    save_model(gms, paths["gms"])
    save_model(gmssvr, paths["gmssvr"])
    return paths


@pytest.fixture(scope="module")
def whole_and_calibration(tmp_path_factory, logs):
    """The cutting log as CSV (read whole) and an air-cut calibration log, written once (read only)."""
    root = tmp_path_factory.mktemp("stream_inputs")
    whole_log, calibration = root / "cut.csv", root / "air.mcap"
    write_log(read_log(logs["cut.parquet"]), whole_log)
    write_log(make_dataset("X", "C", seed=21, duration_s=20), calibration)
    return whole_log, calibration


def _table(path: Path):
    if path.suffix == ".csv":
        return pd.read_csv(path), json.loads(Path(str(path) + ".json").read_text())
    return pd.read_parquet(path), json.loads(pq.read_schema(path).metadata[b"greybox"])


@pytest.mark.parametrize("kind", ["gms", "gmssvr"])
@pytest.mark.parametrize(("log_suffix", "suffix"), [(".parquet", ".parquet"), (".parquet", ".csv"),
                                                     (".mcap", ".parquet")])
def test_streamed_predict_writes_what_the_whole_log_gives(tmp_path, capsys, logs, whole_and_calibration, models, kind,
                                                         log_suffix, suffix):
    """The same cutting log as Parquet or MCAP (streamed) and as CSV (read whole): equal tables and metadata."""
    whole_log, calibration = whole_and_calibration
    outputs = {}
    for name, log in (("streamed", logs["cut" + log_suffix]), ("whole", whole_log)):
        out = tmp_path / f"{name}{suffix}"
        status = cli.main(["predict", str(models[kind]), str(log), "--out", str(out), "--axis-config", str(EXAMPLE),
                           "--calibration", str(calibration), "--chunk-s", "7", "--quiet"])
        printed = capsys.readouterr().out
        assert status == 0
        assert ("read and written block by block" in printed) == (name == "streamed")
        outputs[name] = (_table(out), printed)
    (streamed, streamed_meta), streamed_text = outputs["streamed"]
    (whole, whole_meta), whole_text = outputs["whole"]
    assert list(streamed.columns) == list(whole.columns)
    assert "force_process_upper_N" in streamed.columns and "outside_training" in streamed.columns
    for column in whole.columns:
        np.testing.assert_allclose(streamed[column], whole[column], rtol=0, atol=1e-9)
    for meta in (streamed_meta, whole_meta):
        meta["attrs"].pop("log_file")
    assert streamed_meta == whole_meta
    assert streamed_meta["dataset"] == "C" and streamed_meta["axis"] == "X"
    figures = [line for line in whole_text.splitlines() if line.startswith("  ")]
    assert figures and figures == [line for line in streamed_text.splitlines() if line.startswith("  ")]


@pytest.mark.parametrize("suffix", [".mcap", ".parquet"])
@pytest.mark.parametrize("problem, message", [("missing", "no such file"), ("empty", "empty file"),
                                              ("directory", "no log file")])
def test_a_log_that_is_not_a_file_is_one_line_as_when_read_whole(tmp_path, capsys, models, suffix, problem,
                                                                  message):
    log = tmp_path / f"log{suffix}"
    if problem == "empty":
        log.write_bytes(b"")
    elif problem == "directory":
        log.mkdir()
    out = tmp_path / "out.parquet"
    assert cli.main(["predict", str(models["gms"]), str(log), "--out", str(out), "--quiet"]) == 2
    error = capsys.readouterr().err.strip()
    assert message in error and str(log) in error and len(error.splitlines()) == 1
    assert not out.exists()


def test_streamed_predict_leaves_no_output_on_a_damaged_log(tmp_path, capsys, models):
    log = make_dataset("X", "C", seed=6, duration_s=30, cutting=True)
    effort = log.effort.copy()
    effort[-10] = np.inf  # found in the last block, after earlier blocks were written
    path = tmp_path / "late_damage.parquet"
    write_log(log.replace(effort=effort), path)
    out = tmp_path / "out.parquet"
    out.write_text("an older output")
    status = cli.main(["predict", str(models["gms"]), str(path), "--out", str(out), "--force", "--quiet"])
    captured = capsys.readouterr()
    assert status == 2
    assert "late_damage.parquet" in captured.err and "inf" in captured.err and "Traceback" not in captured.err
    assert out.read_text() == "an older output"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["late_damage.parquet", "out.parquet"]


def test_mcap_messages_out_of_time_order_are_read_whole(tmp_path, capsys, models):
    """A logger may store chunks out of time order: the stream says so and predict reads the log whole."""
    from mcap.writer import Writer

    log = make_dataset("X", "C", seed=8, duration_s=12, cutting=True)
    path = tmp_path / "shuffled.mcap"
    with open(path, "wb") as stream:
        writer = Writer(stream)
        writer.start()
        schema = writer.register_schema("greybox.AxisSample", "jsonschema", b"{}")
        channel = writer.register_channel("/axis/X", "json", schema, {"axis": "X"})
        order = np.concatenate([np.arange(3000, len(log)), np.arange(3000)])  # the first seconds come last
        for k in order:
            stamp = int(round(log.time[k] * 1e9))
            message = json.dumps({"position_mm": log.position[k], "velocity_mm_s": log.velocity[k],
                                  "current_A": log.effort[k]}).encode()
            writer.add_message(channel, stamp, message, stamp)
        writer.finish()
    with pytest.raises(CannotStream, match="time order"):
        median_step(McapLog(path, block_samples=1000).times)
    out = tmp_path / "out.parquet"
    assert cli.main(["predict", str(models["gms"]), str(path), "--out", str(out), "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert "block by block" not in printed
    np.testing.assert_array_equal(pd.read_parquet(out)["time_s"], prepare([read_log(path)])[0].time)


@pytest.mark.parametrize("repeat_channels", [True, False])
def test_mcap_channels_come_from_the_summary_or_from_the_records(tmp_path, repeat_channels):
    """Without channels in the summary section, the data section's channel records choose the channel."""
    from mcap.writer import Writer

    x, y = (make_dataset(axis, "A", seed=9, duration_s=6) for axis in ("X", "Y"))
    path = tmp_path / "two.mcap"
    with open(path, "wb") as stream:
        writer = Writer(stream, repeat_channels=repeat_channels)
        writer.start()
        schema = writer.register_schema("greybox.AxisSample", "jsonschema", b"{}")
        channels = {log.axis: writer.register_channel(f"/axis/{log.axis}", "json", schema, {"axis": log.axis})
                    for log in (x, y)}
        n = min(len(x), len(y))
        for k in range(n):
            for log in (x, y):
                stamp = int(round(log.time[k] * 1e9))
                message = {"position_mm": log.position[k], "current_A": log.effort[k]}
                writer.add_message(channels[log.axis], stamp, json.dumps(message).encode(), stamp)
        writer.finish()
    streamed = concatenate(McapLog(path, axis="Y", block_samples=500).blocks())
    whole = read_log(path, axis="Y")
    assert streamed.axis == whole.axis == "Y"
    np.testing.assert_array_equal(streamed.position, whole.position)
    np.testing.assert_array_equal(streamed.position, y.position[:n])
    with pytest.raises(LogError, match="several channels"):
        McapLog(path, block_samples=500)


def _indexed_mcap(path: Path, log, *, index: bool = True) -> Path:
    """The log on /axis/X with the mcap package's writer, with message-index records (its default) or without."""
    from mcap.writer import IndexType, Writer

    with open(path, "wb") as stream:
        writer = Writer(stream, chunk_size=64 * 1024,
                        index_types=IndexType.ALL if index else IndexType.CHUNK)
        writer.start()
        schema = writer.register_schema("greybox.AxisSample", "jsonschema", b"{}")
        other = writer.register_channel("/temperature", "json", schema, {})  # a second channel in the chunks
        channel = writer.register_channel("/axis/X", "json", schema, {"axis": "X"})
        for k in range(len(log)):
            stamp = int(round(log.time[k] * 1e9))
            message = {"position_mm": log.position[k], "current_A": log.effort[k]}
            writer.add_message(channel, stamp, json.dumps(message).encode(), stamp)
            if k % 100 == 0:
                writer.add_message(other, stamp, b'{"temperature_C": 21.5}', stamp)
        writer.finish()
    return path


def test_mcap_times_come_from_the_message_index_without_opening_the_chunks(tmp_path, monkeypatch):
    from greybox.data import mcap_io

    log = make_dataset("X", "A", seed=9, duration_s=20)
    indexed = McapLog(_indexed_mcap(tmp_path / "indexed.mcap", log), axis="X", block_samples=700)
    plain = McapLog(_indexed_mcap(tmp_path / "plain.mcap", log, index=False), axis="X", block_samples=700)
    from_chunks = np.concatenate(list(plain.times()))
    monkeypatch.setattr(mcap_io, "_decompress", lambda *args: pytest.fail("a chunk was decompressed"))
    from_index = np.concatenate(list(indexed.times()))
    monkeypatch.undo()
    np.testing.assert_array_equal(from_index, from_chunks)
    np.testing.assert_array_equal(from_index, np.round(log.time * 1e9) * 1e-9)
    assert indexed.n_samples == len(log) and indexed.time_span() == plain.time_span()
    np.testing.assert_array_equal(concatenate(indexed.blocks()).position, log.position)


def test_a_message_index_that_disagrees_with_the_messages_is_a_corrupt_file(tmp_path, capsys, models):
    from greybox.data.mcap_io import scan_records

    log = make_dataset("X", "A", seed=9, duration_s=20)
    path = _indexed_mcap(tmp_path / "x.mcap", log)
    data = bytearray(path.read_bytes())
    buf = np.frombuffer(bytes(data), np.uint8)
    opcodes, offsets, _, _ = scan_records(buf, 8, len(data) - 8)
    index = offsets[np.flatnonzero(opcodes == 0x07)]
    channel = [offset for offset in index if data[offset] == 2][3]  # /axis/X's index of the fourth chunk
    stamp = int.from_bytes(data[channel + 6:channel + 14], "little")
    data[channel + 6:channel + 14] = (stamp + 1).to_bytes(8, "little")  # 1 ns off: still in time order
    path.write_bytes(bytes(data))
    out = tmp_path / "out.parquet"
    assert cli.main(["predict", str(models["gms"]), str(path), "--out", str(out), "--axis", "X", "--quiet"]) == 2
    error = capsys.readouterr().err.strip()
    assert "corrupt MCAP file: the message index" in error and len(error.splitlines()) == 1
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["x.mcap"]
