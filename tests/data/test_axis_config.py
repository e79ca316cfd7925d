"""An implausibly low efficiency in an axis file gets one note (issue 31, item 8); a plausible one none."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from greybox.cli import main
from greybox.data.axis_config import MIN_PLAUSIBLE_EFFICIENCY, parse_axis_config
from greybox.data.io import write_log
from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError
from greybox.models.files import save_model
from greybox.models.friction import CoulombModel

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


LINEAR = {"torque_constant_Nm_per_A": 1.35, "screw_lead_mm": 10.0, "gear_ratio": 2.0, "efficiency": 0.9}


def test_the_inertia_at_the_motor_shaft_becomes_a_models_inertia():
    config = parse_axis_config({**LINEAR, "inertia_kg_m2": 0.004})
    # a motor turn (2 pi rad) per 5 mm of table travel: 1 mm/s^2 is 2 pi / 5 rad/s^2 at the motor
    per_ampere = 0.004 * (2 * math.pi / 5.0) / 1.35
    assert config.model_inertia("A") == pytest.approx(per_ampere, rel=1e-12)
    reflected_mass_kg = 0.004 * (2 * math.pi / 5e-3) ** 2  # m = J_m (2 pi i / h)^2, h in m
    assert config.model_inertia("N") == pytest.approx(reflected_mass_kg / 1000.0, rel=1e-12)  # N s^2/mm
    rotary = parse_axis_config({"motion": "rotary", "torque_constant_Nm_per_A": 2.0, "gear_ratio": 90.0,
                                "efficiency": 0.8, "inertia_kg_m2": 0.01})
    assert rotary.model_inertia("A") == pytest.approx(0.01 * 90.0 * math.pi / 180.0 / 2.0, rel=1e-12)
    assert rotary.model_inertia("Nm") == pytest.approx(0.01 * 90.0**2 * math.pi / 180.0, rel=1e-12)


def test_without_the_entry_there_is_no_inertia_and_the_file_round_trips():
    assert parse_axis_config(LINEAR).model_inertia("A") is None
    config = parse_axis_config({**LINEAR, "inertia_kg_m2": 0.004})
    import tomllib

    assert parse_axis_config(tomllib.loads(config.to_toml())).inertia_kg_m2 == 0.004
    assert config.to_dict()["inertia_kg_m2"] == 0.004
    assert "inertia_kg_m2" not in parse_axis_config(LINEAR).to_dict()


@pytest.mark.parametrize("entry, message", [
    ({"inertia_kg_m2": -1.0}, "inertia_kg_m2 must be a positive number"),
    ({"inertia_kg_m2": "0.004 kg m^2"}, "inertia_kg_m2 must be a number"),
    ({"inertia_g_cm2": 40.0}, "'inertia_g_cm2': unit not accepted; give the moment of inertia"),
    ({"inertia": 0.004}, "'inertia': no unit in the key"),
])
def test_a_bad_inertia_entry_is_one_clear_error(entry, message):
    with pytest.raises(GreyboxError, match=message):
        parse_axis_config({**LINEAR, **entry}, source="x.toml")


def test_an_effort_unit_the_axis_does_not_carry_is_refused():
    with pytest.raises(GreyboxError, match="no effort in 'Nm'"):
        parse_axis_config({**LINEAR, "inertia_kg_m2": 0.004}).model_inertia("Nm")
