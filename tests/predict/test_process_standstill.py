"""Standstill of a memoryless model (issue 31, item 7): the samples where the drive holds a friction the model
cannot know are a column of their own, left out of the process-force figures, and named in the plot's legend."""

from __future__ import annotations

import numpy as np
import pytest

import greybox.cli as cli
from greybox.data.axis_config import AxisConfig
from greybox.data.io import write_log
from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.models.files import save_model
from greybox.models.friction import StribeckModel
from greybox.predict.plot import plot_process
from greybox.predict.process import ProcessTally, predict_process

HELD_A = 0.7
CUT_A = -0.3
AXIS = AxisConfig(torque_constant_Nm_per_A=1.2, screw_lead_mm=10.0, gear_ratio=1.0, efficiency_driving=0.9,
                  efficiency_backdriven=0.9)


def _stop_and_go(seed: int = 0, cut: bool = False) -> AxisLog:
    """Strokes at 20 mm/s with 0.5 s stops where the drive holds +-0.7 A (a static model predicts its offset
    there); with ``cut`` a process current of -0.3 A on every stroke."""
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
    moving = np.abs(velocity) > 0
    current = np.where(moving, 0.6 * np.tanh(velocity / 0.5) + 0.01 * velocity + (CUT_A if cut else 0.0), held)
    return AxisLog(time=time, position=position, effort=current + rng.normal(0.0, 0.01, time.size),
                   source="stop.csv")


@pytest.fixture(scope="module")
def result():
    model = StribeckModel().fit(prepare([_stop_and_go()]))
    return predict_process(model, prepare([_stop_and_go(seed=1, cut=True)]), axis_config=AXIS)


def test_the_standstill_samples_are_a_column_of_their_own(result):
    columns = result.columns()
    assert np.any(result.standstill) and not np.all(result.standstill)
    np.testing.assert_array_equal(columns["standstill"] == 1.0, result.standstill)
    # a model's own limitation, not a region the training runs left out: not outside_training (issue 40)
    assert not np.any(result.outside[result.standstill])


def test_the_process_force_figures_leave_the_standstill_out(result):
    tally = ProcessTally()
    tally.add(result)
    moving = ~result.standstill
    assert tally.n_moving == int(np.count_nonzero(moving))
    assert tally.rms("load_moving") == pytest.approx(float(np.sqrt(np.mean(result.load[moving] ** 2))))
    # the held friction is larger than the cut: counted in, it would dominate the figure
    assert tally.rms("load") > 1.2 * tally.rms("load_moving")
    cut_force = AXIS.process_load(np.array([CUT_A]), np.array([1.0]))[0]
    assert tally.rms("load_moving") == pytest.approx(abs(cut_force), rel=0.1)


def test_the_plot_names_the_standstill_in_its_legend(result):
    figure = plot_process(result)
    labels = [text.get_text() for ax in figure.axes if ax.get_legend() for text in ax.get_legend().get_texts()]
    assert any(label.startswith("standstill") for label in labels)
    assert not any(label.startswith("outside the training region") for label in labels)  # nothing else is outside


def test_predict_prints_the_force_without_the_standstill(tmp_path, capsys):
    train, cut, axis = tmp_path / "train.csv", tmp_path / "cut.csv", tmp_path / "axis.toml"
    write_log(_stop_and_go(), train)
    write_log(_stop_and_go(seed=1, cut=True), cut)
    axis.write_text("torque_constant_Nm_per_A = 1.2\nscrew_lead_mm = 10.0\nefficiency_driving = 0.9\n"
                    "efficiency_backdriven = 0.9\n", encoding="utf-8")
    save_model(StribeckModel().fit(prepare([_stop_and_go()])), tmp_path / "s.gbm")
    out = tmp_path / "p.csv"
    assert cli.main(["predict", str(tmp_path / "s.gbm"), str(cut), "--axis-config", str(axis), "--out", str(out),
                     "--quiet"]) == 0
    line = next(line for line in capsys.readouterr().out.splitlines() if line.strip().startswith("force"))
    printed = float(line.split("rms process")[1].split()[0])
    cut_force = abs(AXIS.process_load(np.array([CUT_A]), np.array([1.0]))[0])
    assert printed == pytest.approx(cut_force, rel=0.1) and "standstill left out" in line
