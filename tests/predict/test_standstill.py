"""Standstill (issue 31, item 7): where a memoryless model cannot know the friction the drive holds, the
samples are flagged like those outside the training region, in the result and in predict's outputs."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import greybox.cli as cli
from greybox.data.io import write_log
from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.models.estimator import STANDSTILL_SHARE
from greybox.models.files import save_model
from greybox.models.friction import GMSModel, StribeckModel
from greybox.predict.process import predict_process

HELD_A = 0.7


def _stop_and_go(seed: int = 0) -> AxisLog:
    """Strokes at 20 mm/s with 0.5 s stops; at every stop the drive holds +-0.7 A, the friction the last
    motion left (a static model predicts 0 A there)."""
    step = 0.002
    pieces, held = [], []
    for direction in (1.0, -1.0, 1.0, -1.0, 1.0, -1.0):
        ramp = np.sin(0.5 * np.pi * np.arange(50) / 50) ** 2
        pieces += [direction * 20.0 * np.concatenate([ramp, np.ones(400), ramp[::-1]]), np.zeros(250)]
        held += [np.zeros(500), np.full(250, direction * HELD_A)]
    velocity, held = np.concatenate(pieces), np.concatenate(held)
    time = np.arange(velocity.size) * step
    position = np.concatenate(([0.0], np.cumsum(velocity[:-1] * step)))
    rng = np.random.default_rng(seed)
    current = np.where(np.abs(velocity) > 0, 0.6 * np.tanh(velocity / 0.5) + 0.01 * velocity, held)
    return AxisLog(time=time, position=position, effort=current + rng.normal(0.0, 0.01, time.size),
                   source="stop.csv")


def test_a_static_model_flags_the_stops_and_not_the_motion():
    run = prepare([_stop_and_go()])[0]
    model = StribeckModel().fit(run)
    result = predict_process(model, run)
    at_rest = np.abs(run.velocity) < STANDSTILL_SHARE * np.abs(run.velocity).max()
    assert at_rest.mean() > 0.2
    np.testing.assert_array_equal(model.outside_training(run)["standstill"], at_rest)
    # the model's own limitation, a column of its own: not outside the training region (issue 40)
    assert not result.outside[at_rest].any() and np.array_equal(result.standstill, at_rest)
    # the phantom process current the flag marks: the held friction the model cannot know
    assert np.abs(result.process[at_rest]).mean() > 0.5 * HELD_A


def test_a_model_with_state_does_not_flag_standstill():
    run = prepare([_stop_and_go()])[0]
    model = GMSModel(n_starts=1, max_iter=40).fit(run)
    assert "standstill" not in model.outside_training(run)


@pytest.mark.parametrize("suffix", [".csv", ".mcap"])
def test_predict_writes_the_flag_and_notes_it_once(tmp_path, capsys, suffix):
    log = _stop_and_go()
    train, cut = tmp_path / "train.csv", tmp_path / f"cut{suffix}"
    write_log(log, train)
    write_log(_stop_and_go(seed=1), cut)
    model = StribeckModel().fit(prepare([log]))
    save_model(model, tmp_path / "s.gbm")
    out = tmp_path / "p.csv"
    assert cli.main(["predict", str(tmp_path / "s.gbm"), str(cut), "--out", str(out), "--quiet"]) == 0
    err = capsys.readouterr().err
    notes = [line for line in err.splitlines() if "standstill" in line]
    assert len(notes) == 1 and "left out of the process force" in notes[0]
    table = pd.read_csv(out)
    resting = np.abs(table["velocity_mm_s"].to_numpy()) < STANDSTILL_SHARE * np.abs(table["velocity_mm_s"]).max()
    assert not (table["outside_training"].to_numpy() == 1)[resting].any()  # not the training region (issue 40)
    np.testing.assert_array_equal(table["standstill"].to_numpy() == 1, resting)
