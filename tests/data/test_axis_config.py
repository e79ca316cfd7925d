"""The axis file's optional inertia: read, checked, converted to a model's units and written back."""

from __future__ import annotations

import math

import pytest

from greybox.data.axis_config import parse_axis_config
from greybox.errors import GreyboxError

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
