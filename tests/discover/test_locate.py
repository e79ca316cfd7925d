"""Where the residual lives: motion states, regime tables, profiles, structure columns."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.discover.locate import MOTION_STATES, motion_states, residual_by_regime, residual_profiles, structure_basis
from greybox.twin import make_dataset


def test_motion_states_and_time_since_the_last_change():
    v = np.array([0.0, 0.0, 2.0, 3.0, 0.0, 0.0, -1.0, -2.0, 0.0, 4.0])
    t = np.arange(v.size) * 0.01
    run = AxisLog(time=t, position=np.zeros(v.size), effort=np.zeros(v.size), velocity=v,
                  acceleration=np.zeros(v.size))
    state, since = motion_states(run, standstill_mm_s=0.5)
    names = [MOTION_STATES[s] for s in state]
    assert names == ["rest_after_positive", "rest_after_positive", "positive", "positive", "rest_after_positive",
                     "rest_after_positive", "negative", "negative", "rest_after_negative", "positive"]
    np.testing.assert_allclose(since, [0.0, 0.01, 0.0, 0.01, 0.0, 0.01, 0.0, 0.01, 0.0, 0.0])


@pytest.fixture(scope="module")
def runs():
    return prepare([make_dataset("X", "A", seed=3, duration_s=10.0), make_dataset("X", "B", seed=3)])


def test_every_structure_family_partitions_the_samples(runs):
    families = structure_basis(runs)
    n = sum(len(run) for run in runs)
    assert set(families) == {"velocity", "position_direction", "time", "acceleration", "after_change"}
    for matrix in families.values():
        assert matrix.shape[0] == n
        np.testing.assert_array_equal(np.asarray(matrix.sum(axis=1)).ravel(), np.ones(n))
        assert np.all(np.asarray(matrix.sum(axis=0)).ravel() > 0)  # no empty column


def test_regime_table_shares_and_means(runs):
    rng = np.random.default_rng(0)
    residual = rng.normal(size=sum(len(run) for run in runs))
    table = residual_by_regime(runs, residual)
    assert table["all"]["n"] == residual.size and table["all"]["share_of_squares"] == pytest.approx(1.0)
    directions = sum(table[name]["share_of_squares"] for name in ("positive", "negative", "standstill"))
    assert directions == pytest.approx(1.0)
    positions = [row for name, row in table.items() if name.startswith("position ")]
    times = [row for name, row in table.items() if name.startswith("time ")]
    assert sum(row["n"] for row in positions) == residual.size == sum(row["n"] for row in times)
    assert table["all"]["mean"] == pytest.approx(residual.mean())


def test_profiles_show_a_residual_that_depends_on_the_position(runs):
    x = np.concatenate([run.position for run in runs])
    residual = 0.01 * (x - x.mean())
    profile = residual_profiles(runs, residual)["position_positive"]
    keep = profile["n"] > 0
    slope = np.polyfit(profile["centre"][keep], profile["mean"][keep], 1)[0]
    assert slope == pytest.approx(0.01, rel=1e-3)  # bin means at the bin centres
