"""The ageing twin (greybox.twin.ageing): drifts, day-to-day spread, daily logs."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.errors import GreyboxError
from greybox.twin.ageing import (
    DEFECT_CENTRE_OFFSET_MM,
    DEFECT_WIDTH_MM,
    MIN_LEVEL_FACTOR,
    Drift,
    aged_log,
    air_move_trajectory,
    play_operator,
)
from greybox.twin.axes import axis_geometry


def test_drift_parse_and_level_factor():
    assert Drift.parse("lubrication:10:0.02") == Drift("lubrication", 10, 0.02)
    assert Drift.parse("none") == Drift("none")
    lube, preload = Drift("lubrication", 10, 0.02), Drift("preload", 10, 0.02)
    assert lube.level_factor(10) == 1.0 and lube.level_factor(5) == 1.0
    assert lube.level_factor(20) == pytest.approx(1.2) and preload.level_factor(20) == pytest.approx(0.8)
    assert preload.level_factor(1000) == MIN_LEVEL_FACTOR
    assert Drift("none", 0, 0.5).level_factor(100) == 1.0
    for text in ("rust:1:0.1", "lubrication:1", "preload:x:0.1", "preload:1:-0.1"):
        with pytest.raises(GreyboxError):
            Drift.parse(text)


def test_air_moves_stay_in_the_window_and_go_both_ways():
    low, high = axis_geometry("X").window_mm
    trajectory = air_move_trajectory("X")
    x, v, _ = trajectory.motion.evaluate(np.arange(0.0, trajectory.duration_s, 0.002))
    assert low <= x.min() and x.max() <= high
    assert v.max() == pytest.approx(2400 / 60, rel=1e-3) and v.min() == pytest.approx(-2400 / 60, rel=1e-3)
    assert np.any((np.abs(v) > 0.5) & (np.abs(v) < 2.0))  # the slow moves near break-away


def test_aged_log_scales_the_plant_and_keeps_the_day_spread():
    plain, aged = aged_log("X", 12, 3), aged_log("X", 12, 3, [Drift("lubrication", 2, 0.01)])
    assert aged.attrs["date"] == "2026-01-13" and aged.attrs["machine"] == "twin"
    ratio = np.array(aged.attrs["plant"]["breakaway_A"]) / np.array(plain.attrs["plant"]["breakaway_A"])
    np.testing.assert_allclose(ratio, 1.1)  # 10 days at 1 %
    assert aged.attrs["plant"]["viscous_A_s_mm"] == plain.attrs["plant"]["viscous_A_s_mm"]
    other = aged_log("X", 13, 3)
    factors = [plain.attrs["drift"]["level_factor"], other.attrs["drift"]["level_factor"]]
    assert factors[0] != factors[1] and all(abs(np.log(f)) < 0.05 for f in factors)  # 1 % spread
    np.testing.assert_array_equal(aged_log("X", 12, 3).effort, plain.effort)  # seeded


def _reference_play(position, velocity, play):
    """The play operator written out with lists: the table is clipped into [x - b/2, x + b/2]."""
    table, speed, closed, y = [], [], [], position[0]
    for x, v in zip(position, velocity):
        carried = False
        if y <= x - play / 2:
            y, carried = x - play / 2, v >= 0
        elif y >= x + play / 2:
            y, carried = x + play / 2, v <= 0
        carried = carried or play <= 0
        table.append(y)
        closed.append(carried)
        speed.append(v if carried else 0.0)
    return np.array(table), np.array(speed), np.array(closed)


@pytest.mark.parametrize("play", [0.0, 0.004, 0.05])
def test_play_operator_agrees_with_its_reference(play):
    t = np.arange(0.0, 2.0, 0.001)
    x = 0.03 * np.sin(2 * np.pi * t) + 0.01 * np.sin(7 * t)
    v = np.gradient(x, t)
    compiled = play_operator(x, v, play)
    reference = _reference_play(x, v, play)
    for got, want in zip(compiled, reference):
        np.testing.assert_array_equal(got, want)
    table, _, closed = compiled
    assert np.all(np.abs(x - table) <= play / 2 + 1e-12)
    if play > 0.0:  # after each reversal the motor crosses the play while the table stands
        assert 0 < np.count_nonzero(~closed) < len(x)
    else:
        assert closed.all()


def test_backlash_and_defect_drifts():
    assert Drift.parse("backlash:5:0.001").play_mm(15) == pytest.approx(0.01)
    assert Drift("backlash", 5, 0.001).play_mm(3) == 0.0 and Drift("backlash", 5, 0.001).level_factor(50) == 1.0
    assert Drift("defect", 5, 0.02).defect_gain(15) == pytest.approx(0.2)
    assert Drift("lubrication", 5, 0.02).defect_gain(15) == 0.0 and Drift("defect", 0, 1.0).play_mm(9) == 0.0
    plain = aged_log("X", 3, 2)
    play = aged_log("X", 3, 2, [Drift("backlash", 0, 0.01)])  # 30 um
    assert play.attrs["drift"]["play_mm"] == pytest.approx(0.03)
    friction, x, v = play.extras["truth_friction_A"], plain.position, plain.velocity
    np.testing.assert_array_equal(play.position, plain.position)  # the logged position is the motor's
    starts = np.flatnonzero((v[:-1] == 0.0) & (v[1:] != 0.0)) + 1
    crossed = 0
    for start in starts[1:]:  # every start reverses: friction is 0 until the motor crossed the play
        run = np.flatnonzero(np.abs(x[start:start + 200] - x[start - 1]) < 0.03 - 1e-3)
        assert np.all(friction[start:start + len(run)][:len(run)] == 0.0)
        crossed += len(run)
    assert crossed > 20
    sliding = np.abs(v) > 20.0  # far from the reversals the friction is the plant's (the table 15 um away)
    np.testing.assert_allclose(friction[sliding], plain.extras["truth_friction_A"][sliding], atol=0.02)
    defect = aged_log("X", 3, 2, [Drift("defect", 0, 0.1)])  # 30 % at the stretch's centre
    centre = axis_geometry("X").window_centre_mm + DEFECT_CENTRE_OFFSET_MM
    ratio = defect.extras["truth_friction_A"][sliding] / plain.extras["truth_friction_A"][sliding]
    near, far = np.abs(x[sliding] - centre) < 0.3, np.abs(x[sliding] - centre) > DEFECT_WIDTH_MM / 2
    assert np.any(near) and np.any(far)
    assert np.all(ratio[far] == pytest.approx(1.0, abs=0.02)) and np.median(ratio[near]) > 1.2
