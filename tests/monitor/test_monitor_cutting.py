"""Stretches without process load found from the current alone (no spindle-load column)."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.prepare import prepare
from greybox.errors import ParameterError
from greybox.monitor.cutting import uncut_samples
from greybox.twin.ageing import SPINDLE_COLUMN, aged_log
from greybox.twin.cutting import CuttingSpec


def _mask(run, **options):
    return uncut_samples(run.velocity, run.acceleration, run.effort, **options)


def test_a_twin_production_day_loses_its_cut_and_keeps_its_air_moves():
    for seed in (4, 5):
        runs = prepare(aged_log("X", 3, seed, cutting=CuttingSpec()))
        for run in runs:
            keep = _mask(run)
            process = np.abs(run.extras["truth_process_A"])
            assert np.count_nonzero(process) > 500  # there was a cut
            assert np.max(process[keep]) < 0.05  # and none of it is kept
            returns = (process == 0.0) & (run.velocity >= 10.0)  # the air strokes (the cuts are negative)
            assert np.count_nonzero(keep & returns) > 0.8 * np.count_nonzero(returns)


def test_it_agrees_with_the_spindle_load_where_there_is_one():
    from greybox.monitor.fingerprint import spindle_idle_samples

    run = prepare(aged_log("X", 5, 9, cutting=CuttingSpec()))[0]
    found = _mask(run)
    idle = spindle_idle_samples(run.extras[SPINDLE_COLUMN])
    moving = run.velocity != 0.0
    assert np.count_nonzero(found & ~idle & moving) < 0.02 * np.count_nonzero(moving)


def test_an_air_cut_is_kept_nearly_whole():
    run = prepare(aged_log("X", 0, 1))[0]
    fast = np.abs(run.velocity) >= 10.0
    assert np.count_nonzero(_mask(run) & fast) > 0.9 * np.count_nonzero(fast)


def test_a_load_of_either_sign_is_found():
    run = prepare(aged_log("X", 0, 1))[0]
    stretch = np.flatnonzero(np.abs(run.velocity) >= 10.0)[200:700]
    for sign in (1.0, -1.0):  # against the feed (current up) or pulled along (current down)
        effort = run.effort.copy()
        effort[stretch] += sign * 0.3 * np.sign(run.velocity[stretch])
        keep = uncut_samples(run.velocity, run.acceleration, effort)
        assert not keep[stretch[20:-20]].any()


def test_one_direction_only_keeps_everything_and_bad_options_are_refused():
    v = np.full(500, 20.0)
    assert uncut_samples(v, np.zeros(500), np.ones(500)).all()
    run = prepare(aged_log("X", 0, 1))[0]
    for options in ({"share": 0.0}, {"tolerance": -1.0}, {"iterations": 0}, {"window": 0}, {"pad": -1}):
        with pytest.raises(ParameterError, match="uncut_samples"):
            _mask(run, **options)
