"""An implausibly low efficiency in an axis file gets one note (issue 31, item 8); a plausible one none."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from greybox.cli import main
from greybox.data.axis_config import MIN_PLAUSIBLE_EFFICIENCY, parse_axis_config
from greybox.data.io import write_log
from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.friction import CoulombModel
from greybox.persistence import save_model

BASE = {"torque_constant_Nm_per_A": 1.2, "screw_lead_mm": 10.0, "efficiency_backdriven": 0.85}


def test_an_efficiency_of_a_percent_divided_twice_is_noted():
    with pytest.warns(UserWarning) as caught:
        config = parse_axis_config({**BASE, "efficiency_driving": 0.009}, "axis.toml")
    assert config.efficiency_driving == 0.009  # taken as written: a warning, not an error
    assert len(caught) == 1
    message = str(caught[0].message)
    assert "axis.toml" in message and "efficiency_driving = 0.009" in message and "0.9" in message


@pytest.mark.parametrize("efficiency", [MIN_PLAUSIBLE_EFFICIENCY, 0.5, 0.9, 1.0])
def test_plausible_efficiencies_pass_without_a_note(efficiency):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        parse_axis_config({**BASE, "efficiency_driving": efficiency}, "axis.toml")


def test_predict_notes_it_in_one_line(tmp_path, capsys):
    axis = tmp_path / "axis.toml"
    axis.write_text("torque_constant_Nm_per_A = 1.2\nscrew_lead_mm = 10.0\nefficiency = 0.009\n", encoding="utf-8")
    time = np.arange(2000) * 0.002
    velocity = 20.0 * np.sin(2 * np.pi * time)
    log = AxisLog(time=time, position=np.cumsum(velocity) * 0.002, velocity=velocity,
                  effort=0.5 * np.tanh(velocity) + 0.01 * velocity, source="log.csv")
    write_log(log, tmp_path / "log.csv")
    save_model(CoulombModel().fit(prepare([log])), tmp_path / "c.gbm")
    assert main(["predict", str(tmp_path / "c.gbm"), str(tmp_path / "log.csv"), "--axis-config", str(axis),
                 "--out", str(tmp_path / "p.csv"), "--quiet"]) == 0
    notes = [line for line in capsys.readouterr().err.splitlines() if "efficiency" in line]
    assert len(notes) == 1 and notes[0].startswith("note: ") and "axis.toml" in notes[0]
