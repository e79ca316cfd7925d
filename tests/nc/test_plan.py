"""The air-cut plan: G-code written and read back, the planner's limits, the twin running a program, the loop."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

import greybox.cli as cli
from greybox.data.io import read_log
from greybox.errors import GreyboxError
from greybox.nc import AirCutPlan, Dwell, Move, Program, parse_program, plan_air_cuts, write_program
from greybox.twin.axes import axis_geometry
from greybox.twin.nc_run import program_trajectory

X_PLAN = AirCutPlan("X", (-510.0, 0.0), (-275.0, -225.0), (100.0, 2000.0), duration_a_s=40.0)


@pytest.mark.parametrize("dialect", ["sinumerik", "fanuc"])
def test_written_programs_read_back_block_for_block(dialect):
    program = plan_air_cuts(X_PLAN, seed=3)
    text = write_program(program, dialect=dialect, header=["a (test) header"])
    assert ("G4 F" in text) == (dialect == "sinumerik") and ("G04 X" in text) == (dialect == "fanuc")
    back = parse_program(text)
    assert back.axis == "X" and len(back.blocks) == len(program.blocks)
    for written, read in zip(program.blocks, back.blocks):
        assert type(written) is type(read)
        if isinstance(written, Move):
            assert read.target == pytest.approx(written.target, abs=1e-4)
            assert read.feed == (None if written.feed is None else pytest.approx(written.feed, abs=1e-4))
        else:
            assert read.seconds == pytest.approx(written.seconds, abs=1e-4)


def test_the_reader_understands_iso_and_sinumerik_forms():
    text = """%
    (air cut) ; a comment
    N10 G90 G21 G94
    N20 G0 C10
    N30 G1 C20 F360 (feed per minute)
    N40 G04 P250
    N50 G91 C-5
    N60 C-5 F720
    N70 G4 F1.5
    N80 M30
    N90 G1 C100
    """
    program = parse_program(text)
    assert program.axis == "C" and program.motion == "rotary"
    assert program.blocks == (Move(10.0, None, 4), Move(20.0, 360.0, 5), Dwell(0.25, 6), Move(15.0, 360.0, 7),
                              Move(10.0, 720.0, 8), Dwell(1.5, 9))


@pytest.mark.parametrize("text, message", [
    ("G0 X0\nG1 Y5 F100\n", "line 2: moves Y after X; the program must move one axis only"),
    ("G20\nG0 X0\n", "line 1: G20: inch units"),
    ("G95 G0 X0\n", "line 1: G95: feed per revolution"),
    ("G0 X0\nS1000 M3\n", "line 2: M3"),
    ("G0 X0\nG1 X5\n", "line 2: a feed move without a feed"),
    ("G91 G0 X5\n", "line 1: an incremental move"),
    ("G0 X0\nG1 X5 F100 T1\n", "line 2: word T1 is not run"),
    ("G0 X0\nG4\n", "line 2: a dwell G4 needs its time"),
    ("(only a comment)\n", "no move of an axis"),
    ("G0 X0\nG1 X1 F1OO\n", "line 2: cannot read 'O"),
])
def test_the_reader_refuses_what_the_twin_does_not_run(text, message):
    with pytest.raises(GreyboxError, match=message):
        parse_program(text, source="p.mpf")


def test_the_plan_keeps_to_its_travel_window_and_feeds():
    program = plan_air_cuts(X_PLAN, seed=5)
    titles = [title.split(":")[0] for _, title in program.sections]
    assert titles == ["warm-up", "dataset A", "dataset B"]
    start_a, start_b = program.sections[1][0], program.sections[2][0]
    a_moves = [block for block in program.blocks[start_a:start_b] if isinstance(block, Move)]
    assert all(-275.0 <= move.target <= -225.0 for move in a_moves)
    assert all(100.0 <= move.feed <= 2000.0 for move in a_moves)
    assert max(move.feed for move in a_moves) > 1000.0 and min(move.feed for move in a_moves) < 300.0
    reversals = np.sum(np.diff(np.sign(np.diff([move.target for move in a_moves]))) != 0)
    assert reversals >= 10
    b_moves = [block for block in program.blocks[start_b:] if isinstance(block, Move)]
    assert {move.target for move in b_moves} == {-510.0, 0.0} and {move.feed for move in b_moves} == {600.0, 1800.0}
    assert plan_air_cuts(X_PLAN, seed=5) == program and plan_air_cuts(X_PLAN, seed=6) != program


@pytest.mark.parametrize("changes, message", [
    ({"window": (-600.0, -225.0)}, "--window -600:-225: the window must lie inside the travel"),
    ({"feed": (100.0, 20000.0)}, r"--feed: feed 20000 mm/min is outside \(0, 10000\]"),
    ({"window": (-275.0, -274.0)}, "too short to reach 2000 mm/min and stop again"),
    ({"sweep_feeds": (600.0, -1.0)}, "--sweep-feeds: feed -1"),
    ({"axis": "C", "travel": (-180.0, 180.0), "window": (-25.0, 25.0), "feed": (100.0, 9900.0)},
     "needs .* deg"),
])
def test_plans_the_axis_cannot_run_are_refused(changes, message):
    plan = AirCutPlan(**{**X_PLAN.__dict__, **changes})
    with pytest.raises(GreyboxError, match=message):
        plan_air_cuts(plan)


def test_the_twin_runs_a_program_at_its_feeds_and_stops_at_its_reversals():
    program = Program("X", (Move(-250.0, None), Move(-100.0, 600.0), Move(-10.0, 1800.0), Dwell(1.0),
                            Move(-400.0, 1200.0)))
    trajectory = program_trajectory(program, axis_geometry("X"))
    time = np.arange(0.0, trajectory.duration_s, 0.001)
    position, velocity, _ = trajectory.motion.evaluate(time)
    assert position[0] == -250.0 and position[-1] == pytest.approx(-400.0, abs=1e-9)
    assert position.max() == pytest.approx(-10.0, abs=1e-9)  # the reversal target, reached at rest
    speeds = np.round(np.abs(velocity[np.abs(np.gradient(velocity, time)) < 1e-6]) * 60.0, 6)
    assert {600.0, 1800.0, 1200.0} <= set(speeds)  # cruising at the programmed feeds [mm/min]
    assert not np.any(np.abs(velocity) * 60.0 > 1800.0 + 1e-6)
    at_rest = np.abs(velocity) < 1e-12
    assert np.any(at_rest & (np.abs(position + 10.0) < 1e-9))  # the dwell at the reversal
    with pytest.raises(GreyboxError, match="line 0: X-600 lies outside the twin's travel"):
        program_trajectory(Program("X", (Move(-250.0, None), Move(-600.0, 100.0))), axis_geometry("X"))
    with pytest.raises(GreyboxError, match="the program moves Y, the twin axis is X"):
        program_trajectory(Program("Y", (Move(-250.0, None),)), axis_geometry("X"))


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_plan_to_log_to_model_to_process_force(tmp_path, capsys):
    program = tmp_path / "aircuts.mpf"
    assert cli.main(["plan", "--axis", "X", "--travel", "-510:0", "--window", "-275:-225", "--feed", "100:2000",
                     "--duration-a", "30", "--warmup", "1", "--sweep-feeds", "1200", "--out", str(program)]) == 0
    assert "sections: warm-up; dataset A; dataset B" in capsys.readouterr().out
    assert program.read_text().splitlines()[0].startswith("; greybox")
    assert cli.main(["synth", "--plan", str(program), "--seed", "4", "--out", str(tmp_path / "run")]) == 0
    log = read_log(tmp_path / "run" / "X_aircuts.mcap")
    assert log.position.min() == pytest.approx(-510.0, abs=0.01) and log.position.max() == pytest.approx(0.0, abs=0.01)
    assert cli.main(["synth", "--axis", "X", "--datasets", "D", "--cutting", "--seed", "9",
                     "--out", str(tmp_path / "cut")]) == 0
    assert cli.main(["train", "--model", "stribeck", "--train", str(tmp_path / "run" / "X_aircuts.mcap"),
                     "--out", str(tmp_path / "x.gbm"), "--quiet"]) == 0
    out = tmp_path / "process.csv"
    assert cli.main(["predict", str(tmp_path / "x.gbm"), str(tmp_path / "cut" / "X_D.mcap"), "--axis-config",
                     str(cli_example("axis_x.toml")), "--out", str(out), "--quiet"]) == 0
    printed = capsys.readouterr().out  # stribeck: inside the air cuts' region, its stops flagged apart
    assert re.search(r"\(position 0\.0 %, velocity 0\.0 %, .*standstill (?!0\.0 %)[0-9.]+ %", printed)
    cut = read_log(tmp_path / "cut" / "X_D.mcap")
    in_cut = np.abs(cut.extras["truth_process_A"]) > 0
    estimated = pd.read_csv(out)["force_process_N"].to_numpy()[in_cut].mean()
    truth = cut.extras["truth_process_force_N"][in_cut].mean()
    assert abs(estimated - truth) < 0.15 * abs(truth)


def test_plan_options_are_checked(tmp_path, capsys):
    status = cli.main(["plan", "--axis", "X", "--travel", "-510:0", "--window", "-275:-225", "--feed", "100:2000",
                       "--max-acceleration", "10", "--out", str(tmp_path / "p.mpf")])
    assert status == 2 and "too short to reach 2000 mm/min" in capsys.readouterr().err
    assert not (tmp_path / "p.mpf").exists()
    (tmp_path / "p.mpf").write_text("G0 X0\n")
    status = cli.main(["plan", "--axis", "X", "--travel", "-510:0", "--window", "-275:-225", "--feed", "100:2000",
                       "--out", str(tmp_path / "p.mpf")])
    assert status == 2 and "exists" in capsys.readouterr().err
    assert (tmp_path / "p.mpf").read_text() == "G0 X0\n"
    status = cli.main(["synth", "--plan", str(tmp_path / "p.mpf"), "--axis", "X", "--seed", "1", "--out",
                       str(tmp_path / "o")])
    assert status == 2 and "--axis does not apply" in capsys.readouterr().err


def cli_example(name: str):
    from pathlib import Path

    return Path(__file__).resolve().parents[2] / "examples" / name


def test_fanuc_numbers_carry_a_point_and_rotary_programs_turn_by_increments():
    plan = AirCutPlan("C", (-180.0, 180.0), (-25.0, 25.0), (100.0, 2000.0), duration_a_s=20.0, warmup_strokes=1)
    program = plan_air_cuts(plan, seed=2)
    text = write_program(program, dialect="fanuc")
    lines = text.splitlines()
    assert lines[:2] == ["%", "O1000 (GREYBOX AIR CUT)"] and lines[-1] == "%"
    assert "N40 G1 C-180. F1000." in lines  # from 0 to the travel's end, incrementally
    assert "N50 G1 C360." in lines  # a whole turn, not "to 180", which a modulo table already is at
    assert all(" C" in line for line in lines if " G1 " in line) and "G04 X0.2" in text  # X: the dwell time
    back = parse_program(text)
    np.testing.assert_allclose(back.positions, program.positions, atol=1e-9)
    with pytest.raises(GreyboxError, match="--duration-a 5: dataset A needs at least 10 s"):
        plan_air_cuts(AirCutPlan(**{**X_PLAN.__dict__, "duration_a_s": 5.0}))
    short = plan_air_cuts(AirCutPlan(**{**X_PLAN.__dict__, "duration_a_s": 10.0}), seed=1)
    a_moves = short.blocks[short.sections[1][0]:short.sections[2][0]]
    assert len([block for block in a_moves if isinstance(block, Move)]) > 24  # random moves and a whole sine
