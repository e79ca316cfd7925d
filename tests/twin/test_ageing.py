"""The ageing twin (greybox.twin.ageing): drifts, day-to-day spread, daily logs."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.errors import GreyboxError
from greybox.twin.ageing import MIN_LEVEL_FACTOR, Drift, aged_log, air_move_trajectory
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
