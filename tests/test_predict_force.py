"""Axis metadata TOML and the conversion of the process current into a force on the table."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from greybox.data.axis_config import AxisConfig, parse_axis_config, read_axis_config
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError
from greybox.evaluate.process import force_constant_N_per_A, predict_process, process_force
from greybox.friction import CoulombModel
from greybox.twin import make_dataset

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "axis_x.toml"

VALID = """
name = "Z"
torque_constant_Nm_per_A = 2.0
screw_lead_mm = 5.0
gear_ratio = 3.0
efficiency = 0.8
"""


def _write(tmp_path, text: str, name: str = "axis.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_force_constant_against_a_hand_calculation(tmp_path):
    # 2 Nm/A * 3 motor rev per screw rev * 2 pi * 0.8 / 0.005 m = 6031.857894892403 N/A
    config = read_axis_config(_write(tmp_path, VALID))
    assert force_constant_N_per_A(config) == pytest.approx(6031.857894892403, rel=1e-12)
    np.testing.assert_allclose(process_force([0.5, -1.0, 0.0], config), [3015.9289474462, -6031.857894892403, 0.0])


def test_force_from_the_power_balance():
    """F v = eta T omega with v = omega h / (2 pi i): the power reaching the table, one operating point."""
    config = AxisConfig(torque_constant_Nm_per_A=0.7, screw_lead_mm=16.0, gear_ratio=2.5, efficiency=0.85)
    current_A, omega = 3.0, 150.0  # A, rad/s of the motor
    table_speed_m_s = omega / (2 * math.pi) / config.gear_ratio * config.screw_lead_mm / 1000.0
    power_to_table_W = config.efficiency * config.torque_constant_Nm_per_A * current_A * omega
    assert process_force(current_A, config) == pytest.approx(power_to_table_W / table_speed_m_s, rel=1e-12)


def test_force_scales_as_expected():
    base = AxisConfig(torque_constant_Nm_per_A=1.0, screw_lead_mm=10.0, gear_ratio=1.0, efficiency=1.0)
    k = force_constant_N_per_A(base)
    assert k == pytest.approx(2 * math.pi * 100.0)  # 1 Nm per A over a 10 mm lead: 628.3 N/A
    for change, factor in (({"screw_lead_mm": 20.0}, 0.5), ({"gear_ratio": 4.0}, 4.0), ({"efficiency": 0.5}, 0.5),
                           ({"torque_constant_Nm_per_A": 3.0}, 3.0)):
        other = AxisConfig(**{**{"torque_constant_Nm_per_A": 1.0, "screw_lead_mm": 10.0, "gear_ratio": 1.0,
                                 "efficiency": 1.0}, **change})
        assert force_constant_N_per_A(other) == pytest.approx(factor * k)


def test_example_file_parses_and_gives_the_documented_factor():
    config = read_axis_config(EXAMPLE)
    assert config.name == "X" and config.channels == {}
    assert force_constant_N_per_A(config) == pytest.approx(1.35 * 2 * math.pi * 0.9 / 0.010)
    assert f"{force_constant_N_per_A(config):.1f}" == "763.4"


def test_channels_table(tmp_path):
    text = VALID + '\n[channels]\nposition_um = "Pos"\ncurrent_A = "Strom, Achse Z"\n'
    config = read_axis_config(_write(tmp_path, text))
    assert config.channels == {"position_um": "Pos", "current_A": "Strom, Achse Z"}


@pytest.mark.parametrize("text, message", [
    ("torque_constant_Nm_per_A = 1.0\nscrew_lead_mm = 10\ngear_ratio = 1\n", "missing efficiency"),
    ("screw_lead_mm = 10\ngear_ratio = 1\nefficiency = 0.9\n", "missing torque_constant_Nm_per_A"),
    (VALID.replace("screw_lead_mm", "screw_lead_m"),
     "'screw_lead_m': unit not accepted; give the screw lead h as 'screw_lead_mm'"),
    (VALID.replace("screw_lead_mm", "screw_lead"), "'screw_lead': no unit in the key"),
    (VALID.replace("torque_constant_Nm_per_A", "torque_constant_mNm_per_A"), "unit not accepted"),
    (VALID.replace("screw_lead_mm = 5.0", 'screw_lead_mm = "5 mm"'), "must be a number .* got the text '5 mm'"),
    (VALID.replace("efficiency = 0.8", "efficiency = 90"), "90 looks like a percentage, write 0.9"),
    (VALID.replace("efficiency = 0.8", "efficiency = 0"), "efficiency must be a positive number"),
    (VALID.replace("screw_lead_mm = 5.0", "screw_lead_mm = 0.005"), "was it written in metres"),
    (VALID.replace("gear_ratio = 3.0", "gear_ratio = -3.0"), "gear_ratio must be a positive number"),
    (VALID.replace("gear_ratio = 3.0", "gear_ratio = true"), "gear_ratio must be a number"),
    (VALID + "spindle = 3\n", "unknown key 'spindle'"),
    (VALID + '[channels]\nposition_inch = "P"\n', "'position_inch' is not a quantity with a known unit"),
    (VALID + '[channels]\nposition_mm = "P"\nposition_um = "Q"\n', "position is mapped twice"),
    (VALID + "[channels]\ncurrent_A = 3\n", "must name a column of the log as text"),
    ("torque_constant_Nm_per_A = = 1\n", "not valid TOML"),
])
def test_bad_files_give_errors_naming_the_file(tmp_path, text, message):
    path = _write(tmp_path, text)
    with pytest.raises(GreyboxError, match=message) as info:
        read_axis_config(path)
    assert str(info.value).startswith(f"{path}: ")


def test_missing_and_binary_files(tmp_path):
    with pytest.raises(GreyboxError, match="no such axis configuration file"):
        read_axis_config(tmp_path / "nothing.toml")
    binary = tmp_path / "b.toml"
    binary.write_bytes(b"\xff\xfe\x00name = 1")
    with pytest.raises(GreyboxError, match=str(binary)):
        read_axis_config(binary)
    with pytest.raises(GreyboxError, match="is a directory"):
        read_axis_config(tmp_path)


def test_parse_without_a_file_and_invalid_dataclass():
    config = parse_axis_config({"torque_constant_Nm_per_A": 1, "screw_lead_mm": 10, "gear_ratio": 1, "efficiency": 1})
    assert config.efficiency == 1.0 and isinstance(config.gear_ratio, float)
    with pytest.raises(GreyboxError, match="efficiency must be a fraction"):
        AxisConfig(torque_constant_Nm_per_A=1.0, screw_lead_mm=10.0, gear_ratio=1.0, efficiency=1.5)


def test_process_force_of_a_cutting_log_is_the_scaled_process_current():
    """force_process_N = factor * (measured - model), sample by sample."""
    train = prepare([make_dataset("X", "A", seed=5, duration_s=8)])[0]
    cut = prepare([make_dataset("X", "C", seed=6, duration_s=8, cutting=True)])[0]
    model = CoulombModel().fit(train)
    config = read_axis_config(EXAMPLE)
    result = predict_process(model, cut, axis_config=config, chunk_s=1.0)
    np.testing.assert_array_equal(result.process, cut.current - model.predict(cut))
    np.testing.assert_allclose(result.force, force_constant_N_per_A(config) * result.process, rtol=1e-15)
    assert result.force_constant_N_per_A == pytest.approx(763.4070148223198)
    columns = result.columns()
    assert list(columns)[:5] == ["time_s", "current_measured_A", "current_model_A", "current_process_A",
                                 "force_process_N"]


def test_force_logs_need_no_axis_metadata():
    train = prepare([make_dataset("X", "A", seed=5, duration_s=8)])[0]
    to_force = 763.4
    train = train.replace(effort=train.effort * to_force, effort_unit="N")
    model = CoulombModel().fit(train)
    cut = prepare([make_dataset("X", "C", seed=6, duration_s=8, cutting=True)])[0]
    cut = cut.replace(effort=cut.effort * to_force, effort_unit="N")
    result = predict_process(model, cut)
    assert list(result.columns())[1:4] == ["force_measured_N", "force_model_N", "force_process_N"]
    np.testing.assert_array_equal(result.force, result.process)
    with pytest.raises(GreyboxError, match="carries force in N already"):
        predict_process(model, cut, axis_config=read_axis_config(EXAMPLE))
