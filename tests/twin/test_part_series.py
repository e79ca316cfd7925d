"""A part series on the twin: the warm-up law, the tool events, the two layouts and the truth beside them."""

from __future__ import annotations

import json

import numpy as np
import pytest

from greybox.data.io import read_log
from greybox.errors import GreyboxError
from greybox.nc.blocks import Dwell, Move, Program
from greybox.twin.axes import axis_geometry
from greybox.twin.nc_run import program_trajectory
from greybox.twin.part_series import (
    BLOCK_COLUMN,
    PART_COLUMN,
    PartSeriesSpec,
    ToolEvents,
    WarmPlant,
    WarmUp,
    block_numbers,
    make_part_series,
    part_program,
    synthesize_part_series,
)
from greybox.twin.plant import default_plant_parameters

SHORT = part_program("X", (600.0,))  # one pass: a part of about 10 s


def test_warm_up_law_falls_by_its_drop_with_its_time_constant_and_recovers_in_a_pause():
    law = WarmUp(drop=0.25, time_constant_s=1800.0, cooling_time_constant_s=900.0)
    warm = float(law.running(0.0, 1800.0))
    assert float(law.level(warm)) == pytest.approx(1.0 - 0.25 * (1.0 - np.exp(-1.0)))
    assert float(law.level(law.running(0.0, 1e7))) == pytest.approx(0.75)
    cooled = law.paused(warm, 900.0)
    assert cooled == pytest.approx(warm / np.e)
    assert float(law.running(warm, 600.0)) == pytest.approx(float(law.running(0.0, 2400.0)))  # one law, no memory
    with pytest.raises(GreyboxError, match="drop"):
        WarmUp(drop=1.0)


def test_warm_plant_is_the_cold_plant_with_its_friction_scaled_sample_by_sample():
    plant = default_plant_parameters("X")
    trajectory = program_trajectory(SHORT, axis_geometry("X"))
    n = int(trajectory.duration_s / 0.002)
    law = WarmUp(drop=0.3, time_constant_s=5.0)
    cold = plant.simulate(trajectory.motion, n, 0.002)
    warm = WarmPlant(plant, law, 0.5).simulate(trajectory.motion, n, 0.002)
    factor = 1.0 - 0.3 * (1.0 - 0.5 * np.exp(-np.arange(n) * 0.002 / 5.0))
    np.testing.assert_allclose(warm.friction_A, cold.friction_A * factor, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(warm.inertia_A, cold.inertia_A)


def test_series_follows_the_warm_up_and_the_tool_events_and_writes_their_truth():
    events = ToolEvents(wear_pct_per_part=10.0, wear_start_part=1, breakage_part=4, breakage_time_s=4.0,
                        missing_blank=(2,), oversized_blank=(3,), oversize_factor=1.5)
    spec = PartSeriesSpec(parts=5, program=SHORT, events=events, warm_up=WarmUp(time_constant_s=30.0), loading_s=1.0,
                          jitter_s=0.3, pauses=((5, 600.0),))
    logs, truth = make_part_series(spec, 4)
    parts = truth["parts"]
    assert [p["part"] for p in parts] == [1, 2, 3, 4, 5]
    # warm-up: friction factor falls part by part, the pause before part 5 brings part of it back
    starts = [p["friction_factor_start"] for p in parts]
    assert starts[0] == 1.0 and starts[1] < starts[0] and starts[3] < starts[2]
    assert starts[4] > parts[3]["friction_factor_end"]
    # events: missing blank cuts nothing; oversized 1.5 x (1 + 2 * 10 %); breakage at 4 s in part 4, nothing after
    cut = [np.abs(log.extras["truth_process_A"]) for log in logs]
    assert cut[1].max() == 0.0 and parts[1]["mean_cut_current_A"] == 0.0
    assert parts[2]["mean_cut_current_A"] / parts[0]["mean_cut_current_A"] == pytest.approx(1.5 * 1.2, rel=0.02)
    broken = logs[3].time >= 4.0
    assert cut[3][~broken].max() > 0.1 and cut[3][broken].max() == 0.0 and cut[4].max() == 0.0
    assert {e["kind"] for e in truth["events"]} == {"breakage", "missing blank", "oversized blank", "pause"}
    assert parts[3]["mean_cut_force"] < 0.9 * 1.3 * parts[0]["mean_cut_force"]  # worn 30 %, broken part-way
    # the waits differ from part to part within the jitter
    waits = np.array([p["wait_s"] for p in parts])
    assert np.all((waits >= 1.0) & (waits <= 1.3)) and np.ptp(waits) > 0.01
    assert all(np.all(log.extras[PART_COLUMN] == k + 1) for k, log in enumerate(logs))


def test_events_refuse_parts_not_counted_from_one():
    with pytest.raises(GreyboxError, match="counted from 1"):
        ToolEvents(missing_blank=(0,))
    with pytest.raises(GreyboxError, match="both"):
        ToolEvents(breakage_part=2)
    assert ToolEvents(wear_pct_per_part=3.0, wear_start_part=10).worn_part(15.0) == 15


def test_both_layouts_hold_the_same_samples_and_nothing_is_overwritten(tmp_path):
    spec = PartSeriesSpec(parts=3, program=SHORT, loading_s=0.5)
    written = synthesize_part_series(spec, 2, tmp_path)
    names = sorted(path.name for path in written)
    assert names == ["X_part.mpf", "X_part001.mcap", "X_part002.mcap", "X_part003.mcap", "X_parts.json",
                     "X_series.mcap"]
    series = read_log(tmp_path / "X_series.mcap")
    parts = [read_log(tmp_path / f"X_part00{k}.mcap") for k in (1, 2, 3)]
    assert len(series) == sum(len(p) for p in parts)
    assert np.all(np.diff(series.time) > 0)
    np.testing.assert_array_equal(series.effort, np.concatenate([p.effort for p in parts]))
    np.testing.assert_array_equal(series.extras[PART_COLUMN], np.repeat([1.0, 2.0, 3.0], [len(p) for p in parts]))
    np.testing.assert_array_equal(series.extras[BLOCK_COLUMN], np.concatenate([p.extras[BLOCK_COLUMN] for p in parts]))
    truth = json.loads((tmp_path / "X_parts.json").read_text())
    assert [p["file"] for p in truth["parts"]] == ["X_part001.mcap", "X_part002.mcap", "X_part003.mcap"]
    before = (tmp_path / "X_series.mcap").read_bytes()
    with pytest.raises(GreyboxError, match="file exists"):
        synthesize_part_series(spec, 3, tmp_path)
    assert (tmp_path / "X_series.mcap").read_bytes() == before


def test_a_parquet_series_holds_the_samples_of_the_mcap_one(tmp_path):
    spec = PartSeriesSpec(parts=2, program=SHORT, loading_s=0.5)
    synthesize_part_series(spec, 2, tmp_path / "m", layout="series")
    written = synthesize_part_series(spec, 2, tmp_path / "p", layout="series", suffix="parquet")
    assert sorted(path.name for path in written) == ["X_part.mpf", "X_parts.json", "X_series.parquet"]
    mcap, parquet = read_log(tmp_path / "m" / "X_series.mcap"), read_log(tmp_path / "p" / "X_series.parquet")
    np.testing.assert_array_equal(parquet.effort, mcap.effort)
    np.testing.assert_array_equal(parquet.extras[PART_COLUMN], mcap.extras[PART_COLUMN])
    with pytest.raises(GreyboxError, match="mcap or parquet"):
        synthesize_part_series(spec, 2, tmp_path / "c", suffix="csv")


def test_block_numbers_follow_the_program_lines_where_each_block_runs():
    program = Program("X", (Move(-226.0, None, 1), Move(-250.0, 600.0, 2), Move(-260.0, 300.0, 3), Dwell(0.7, 4),
                            Move(-226.0, 2000.0, 5)), source="test")
    trajectory = program_trajectory(program, axis_geometry("X"))
    time = np.arange(int(trajectory.duration_s / 0.002) + 1) * 0.002
    position, velocity, _ = trajectory.motion.evaluate(time)
    blocks = block_numbers(program, position, velocity)
    runs = [int(b) for k, b in enumerate(blocks) if k == 0 or b != blocks[k - 1]]
    assert runs == [2, 3, 4, 5]  # the rest before the first move already waits for it; the last block stays
    # lines 2 and 3 form one stroke: the block changes where the position passes -250 mm, at the cut's feed
    change = int(np.argmax(blocks == 3))
    assert position[change - 1] > -250.0 >= position[change] - 1e-3 and abs(velocity[change]) > 4.0
    # the dwell holds at rest at -260 mm from the end of line 3's move until line 5 moves
    dwell = blocks == 4
    assert np.all(velocity[dwell] == 0.0) and np.allclose(position[dwell], -260.0)
    assert 0.7 <= dwell.sum() * 0.002 <= 0.7 + 0.01
    # a log of the series carries the column: the program's lines in order after the loading wait (line 0)
    logs, _ = make_part_series(PartSeriesSpec(parts=1, program=SHORT, loading_s=0.5), 3)
    column = logs[0].extras[BLOCK_COLUMN]
    assert [int(b) for k, b in enumerate(column) if k == 0 or b != column[k - 1]] == [0, 2, 3]
