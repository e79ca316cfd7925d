"""Axis metadata TOML and the conversion of the process current into a force on the table."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from greybox.data.axis_config import AxisConfig, parse_axis_config, read_axis_config
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError
from greybox.models.friction import CoulombModel
from greybox.predict.process import predict_process
from greybox.twin import make_dataset

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "axis_x.toml"

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
    # F per A = k_t i 2 pi eta / h driving, k_t i 2 pi / (eta h) back-driven, with the file's k_t = 2 Nm/A,
    # i = 3 motor revolutions per screw revolution, eta = 0.8 and h = 0.005 m
    driving, backdriven = 2.0 * 3.0 * 2 * np.pi * 0.8 / 0.005, 2.0 * 3.0 * 2 * np.pi / (0.8 * 0.005)
    config = read_axis_config(_write(tmp_path, VALID))
    assert config.load_constants == pytest.approx((driving, backdriven), rel=1e-12)
    # driving where current and velocity share their sign, back-driven where they differ; zero current, zero force
    np.testing.assert_allclose(config.process_load([0.5, -1.0, 0.0], 1.0), [0.5 * driving, -backdriven, 0.0])
    np.testing.assert_allclose(config.process_load([0.5, -1.0], -1.0), [0.5 * backdriven, -driving])


@pytest.mark.parametrize("current_A, omega", [(3.0, 150.0), (-3.0, -150.0), (3.0, -150.0), (-3.0, 150.0)])
def test_force_from_the_power_balance_in_either_direction_of_power_flow(current_A, omega):
    """Driving: F v = eta_d T omega; back-driven (I and v of opposite signs): T omega = eta_b F v."""
    config = AxisConfig(torque_constant_Nm_per_A=0.7, screw_lead_mm=16.0, gear_ratio=2.5,
                        efficiency_driving=0.85, efficiency_backdriven=0.7)
    table_speed_m_s = omega / (2 * math.pi) / config.gear_ratio * config.screw_lead_mm / 1000.0
    motor_power_W = config.torque_constant_Nm_per_A * current_A * omega
    if motor_power_W > 0:
        table_power_W = config.efficiency_driving * motor_power_W
    else:
        table_power_W = motor_power_W / config.efficiency_backdriven
    force = config.process_load(current_A, table_speed_m_s * 1000.0)
    assert force == pytest.approx(table_power_W / table_speed_m_s, rel=1e-12)


def test_back_driven_current_is_divided_by_the_efficiency_and_rest_counts_as_driving():
    """With one efficiency eta a back-driven force read as driving would come out eta^2 too small."""
    config = AxisConfig(torque_constant_Nm_per_A=1.0, screw_lead_mm=10.0, gear_ratio=1.0, efficiency_driving=0.85)
    lossless = config.lossless_load_constant
    assert config.process_load(-1.0, 5.0) == pytest.approx(-lossless / 0.85)
    assert config.process_load(1.0, -5.0) == pytest.approx(lossless / 0.85)
    assert config.process_load(1.0, 5.0) == pytest.approx(lossless * 0.85)
    assert config.process_load(1.0, 0.0) == pytest.approx(lossless * 0.85)


def test_force_scales_as_expected():
    base = AxisConfig(torque_constant_Nm_per_A=1.0, screw_lead_mm=10.0, gear_ratio=1.0, efficiency_driving=1.0)
    k = base.lossless_load_constant
    assert k == pytest.approx(2 * math.pi * 100.0)  # 1 Nm per A over a 10 mm lead: 628.3 N/A
    assert base.load_constants == (k, k)
    for change, factors in (({"screw_lead_mm": 20.0}, (0.5, 0.5)), ({"gear_ratio": 4.0}, (4.0, 4.0)),
                            ({"efficiency_driving": 0.5}, (0.5, 2.0)),
                            ({"efficiency_driving": 0.9, "efficiency_backdriven": 0.8}, (0.9, 1.25)),
                            ({"torque_constant_Nm_per_A": 3.0}, (3.0, 3.0))):
        other = AxisConfig(**{**{"torque_constant_Nm_per_A": 1.0, "screw_lead_mm": 10.0, "gear_ratio": 1.0,
                                 "efficiency_driving": 1.0}, **change})
        assert other.load_constants == pytest.approx((factors[0] * k, factors[1] * k))


def test_example_file_parses_and_gives_the_documented_factor():
    config = read_axis_config(EXAMPLE)
    assert config.name == "X" and config.channels == {}
    driving, backdriven = config.load_constants
    assert driving == pytest.approx(1.35 * 2 * math.pi * 0.9 / 0.010)
    assert backdriven == pytest.approx(1.35 * 2 * math.pi / 0.85 / 0.010)
    assert f"{driving:.1f} {backdriven:.1f}" == "763.4 997.9"  # the figures the example file's comment states


def test_old_files_with_one_efficiency_still_load_and_mean_it_for_both_directions(tmp_path):
    config = read_axis_config(_write(tmp_path, VALID))
    assert config.efficiency_driving == config.efficiency_backdriven == 0.8
    both = VALID.replace("efficiency = 0.8", "efficiency_driving = 0.8\nefficiency_backdriven = 0.6")
    config = read_axis_config(_write(tmp_path, both, "both.toml"))
    assert (config.efficiency_driving, config.efficiency_backdriven) == (0.8, 0.6)


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
    (VALID + "efficiency_backdriven = 0.7\n", "give either 'efficiency' .* not 'efficiency' and efficiency_backdriven"),
    (VALID.replace("efficiency = 0.8", "efficiency_driving = 0.8"), "missing efficiency_backdriven"),
    (VALID.replace("efficiency = 0.8", "efficiency_driving = 0.8\nefficiency_backdriven = 85"),
     "efficiency_backdriven must be a fraction .* 85 looks like a percentage, write 0.85"),
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
    assert config.efficiency_driving == config.efficiency_backdriven == 1.0 and isinstance(config.gear_ratio, float)
    with pytest.raises(GreyboxError, match="efficiency_driving must be a fraction"):
        AxisConfig(torque_constant_Nm_per_A=1.0, screw_lead_mm=10.0, gear_ratio=1.0, efficiency_driving=1.5)


def test_process_force_of_a_cutting_log_is_the_scaled_process_current():
    """force_process_N = factor * (measured - model), sample by sample."""
    train = prepare([make_dataset("X", "A", seed=5, duration_s=8)])[0]
    cut = prepare([make_dataset("X", "C", seed=6, duration_s=8, cutting=True)])[0]
    model = CoulombModel().fit(train)
    config = read_axis_config(EXAMPLE)
    result = predict_process(model, cut, axis_config=config, chunk_s=1.0)
    np.testing.assert_array_equal(result.process, cut.current - model.predict(cut))
    driving, backdriven = config.load_constants
    back = result.process * cut.velocity < 0
    assert back.any() and (~back).any()
    np.testing.assert_allclose(result.load, np.where(back, backdriven, driving) * result.process, rtol=1e-15)
    # the axis file's data sheet: F = k_t I i 2 pi eta_d / h driving, k_t I i 2 pi / (eta_b h) back-driven (h in m)
    per_ampere = 1.35 * 1.0 * 2 * np.pi / 0.010
    assert result.load_constants == pytest.approx((per_ampere * 0.9, per_ampere / 0.85), rel=1e-12)
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
    np.testing.assert_array_equal(result.load, result.process)
    with pytest.raises(GreyboxError, match="carries force in N already"):
        predict_process(model, cut, axis_config=read_axis_config(EXAMPLE))


def test_an_axis_file_written_by_to_toml_reads_back_equal(tmp_path):
    config = AxisConfig(torque_constant_Nm_per_A=1.35, screw_lead_mm=16.0, gear_ratio=1.5, efficiency_driving=0.93,
                        efficiency_backdriven=1 - 0.0712345678901, name='Z "rear"', channels={"current_A": "I Z"})
    again = read_axis_config(_write(tmp_path, config.to_toml()))
    assert again.to_dict() == config.to_dict()
    assert again.load_constants == config.load_constants
