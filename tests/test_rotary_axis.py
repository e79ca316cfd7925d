"""Rotary axes: units (deg, rad, rev, rpm, Nm), the rotary axis file, and every command on a rotary log."""

from __future__ import annotations

import dataclasses
import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import greybox.cli as cli
from greybox.data.axis_config import parse_axis_config, read_axis_config
from greybox.data.io import read_log, write_log
from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.data.validate import check_velocity_units
from greybox.errors import GreyboxError, LogError, ParameterError
from greybox.evaluate.plots import plot_log
from greybox.models.files import check_fitted, load_model, save_model
from greybox.models.friction import StribeckModel
from greybox.predict.plot import plot_process
from greybox.predict.process import predict_process
from greybox.twin import make_dataset

EXAMPLE_C = Path(__file__).resolve().parents[1] / "examples" / "axis_c.toml"
EXAMPLE_X = Path(__file__).resolve().parents[1] / "examples" / "axis_x.toml"


def _rotary_table(n=400, step=0.002):
    time = np.arange(n) * step
    angle_rad = 0.3 * np.sin(2 * np.pi * time)
    speed_rpm = 0.3 * 2 * np.pi * np.cos(2 * np.pi * time) * 60 / (2 * np.pi)  # d(angle)/dt in rev/min
    return time, angle_rad, speed_rpm


def test_rotary_units_convert_to_deg_and_make_a_rotary_log(tmp_path):
    time, angle_rad, speed_rpm = _rotary_table()
    path = tmp_path / "c.csv"
    pd.DataFrame({"time_s": time, "position_rad": angle_rad, "velocity_rpm": speed_rpm,
                  "torque_Nm": np.ones_like(time)}).to_csv(path, index=False)
    log = read_log(path)
    assert log.motion == "rotary" and log.effort_unit == "Nm" and log.effort_column == "torque_Nm"
    np.testing.assert_allclose(log.position, np.degrees(angle_rad), rtol=1e-12)
    np.testing.assert_allclose(log.velocity, 6.0 * speed_rpm, rtol=1e-12)  # 1 rpm = 360 deg / 60 s
    assert check_velocity_units(log) == pytest.approx(1.0, rel=0.02)  # rad and rpm agree once in deg
    assert list(log.to_frame().columns[:4]) == ["time_s", "position_deg", "velocity_deg_s", "torque_Nm"]


def test_revolutions_and_mapped_rotary_columns(tmp_path):
    time = np.arange(300) * 0.002
    path = tmp_path / "c.csv"
    pd.DataFrame({"t": time, "C_turns": 0.01 * time, "iq": np.zeros_like(time)}).to_csv(path, index=False)
    log = read_log(path, columns={"time_s": "t", "position_rev": "C_turns", "current_A": "iq"})
    assert log.motion == "rotary" and log.effort_unit == "A"
    np.testing.assert_allclose(log.position, 3.6 * time)


def test_linear_and_rotary_units_together_are_refused(tmp_path):
    path = tmp_path / "mixed.csv"
    path.write_text("time_s,position_deg,velocity_mm_s,current_A\n0,0,0,0\n0.002,1,1,1\n")
    with pytest.raises(LogError, match=r"mix a linear and a rotary axis: 'position_deg' \(rotary\), "
                                       r"'velocity_mm_s' \(linear\)"):
        read_log(path)
    path.write_text("time_s,position_mm,force_N,velocity_deg_s\n0,0,0,0\n0.002,1,1,1\n")
    read_log(path)  # a rotary velocity beside a linear position is a motor's speed: an extra channel
    path.write_text("time_s,position_deg,force_N\n0,0,0\n0.002,1,1\n")
    with pytest.raises(LogError, match="mix a linear and a rotary axis"):
        read_log(path)


@pytest.mark.parametrize("factor, column", [(math.pi / 180.0, "velocity_rad_s"), (1.0 / 6.0, "velocity_rpm"),
                                            (60.0, "velocity_deg_min")])
def test_a_rotary_unit_slip_names_the_column_that_fixes_it(factor, column):
    time = np.arange(2000) * 0.002
    angle = 20.0 * np.sin(2 * np.pi * 0.5 * time)
    rate = 20.0 * 2 * np.pi * 0.5 * np.cos(2 * np.pi * 0.5 * time)
    log = AxisLog(time=time, position=angle, velocity=factor * rate, effort=np.zeros_like(time), motion="rotary")
    with pytest.raises(LogError, match=column):
        check_velocity_units(log)


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mcap"])
def test_rotary_logs_round_trip_through_every_writer(tmp_path, suffix):
    log = make_dataset("C", "A", seed=3, duration_s=4)
    path = tmp_path / f"c{suffix}"
    write_log(log, path)
    back = read_log(path)
    assert back.motion == "rotary" and back.axis == "C"
    np.testing.assert_array_equal(back.position, log.position)
    np.testing.assert_array_equal(back.velocity, log.velocity)


def test_the_rotary_axis_file_gives_torque_by_the_direction_of_power_flow():
    config = read_axis_config(EXAMPLE_C)
    assert config.motion == "rotary" and config.screw_lead_mm is None
    k0 = 1.35 * 90.0  # k_t i [Nm/A]: a worm of ratio 90, no screw
    assert config.lossless_load_constant == pytest.approx(k0)
    assert config.load_constants == pytest.approx((0.8 * k0, k0 / 0.7))
    np.testing.assert_allclose(config.process_load([1.0, -1.0, 1.0], [5.0, 5.0, 0.0]),
                               [0.8 * k0, -k0 / 0.7, 0.8 * k0])
    assert config.units.load_column == "torque_Nm"
    assert parse_axis_config(tomllib.loads(config.to_toml())) == dataclasses.replace(config, source="")


@pytest.mark.parametrize("text, message", [
    ('motion = "rotary"\ntorque_constant_Nm_per_A = 1\nscrew_lead_mm = 5\ngear_ratio = 90\nefficiency = 0.8\n',
     "a rotary axis .* has no screw_lead_mm"),
    ('torque_constant_Nm_per_A = 1\ngear_ratio = 90\nefficiency = 0.8\n',
     'missing screw_lead_mm .*write motion = "rotary"'),
    ('motion = "angular"\ntorque_constant_Nm_per_A = 1\ngear_ratio = 90\nefficiency = 0.8\n',
     "motion must be one of 'linear', 'rotary'"),
])
def test_rotary_axis_file_errors(tmp_path, text, message):
    path = tmp_path / "axis.toml"
    path.write_text(text)
    with pytest.raises(GreyboxError, match=message):
        read_axis_config(path)


@pytest.fixture(scope="module")
def rotary(tmp_path_factory):
    """A Stribeck model of the synthetic C axis, its air-cut and cutting logs, written as files."""
    root = tmp_path_factory.mktemp("rotary")
    air = make_dataset("C", "A", seed=21, duration_s=20)
    cut = make_dataset("C", "D", seed=22, cutting=True)
    for name, log in (("air.mcap", air), ("cut.mcap", cut), ("calibration.mcap", make_dataset("C", "C", seed=23,
                                                                                                 duration_s=10))):
        write_log(log, root / name)
    model = StribeckModel().fit(prepare([air]))
    save_model(model, root / "c.gbm")
    return root, model, cut


def test_a_rotary_model_speaks_deg_and_refuses_a_linear_log(rotary):
    root, model, _ = rotary
    units = {row.name: row.unit for row in model.parameter_table()}
    assert units["viscous"] == "A s/deg" and units["v_s"] == "deg/s" and units["J"] == "A s^2/deg"
    loaded = load_model(root / "c.gbm")
    assert loaded.motion_ == "rotary"
    linear = prepare([make_dataset("X", "A", seed=1, duration_s=3)])
    with pytest.raises(LogError, match=r"log is of a linear axis \(mm\), the model was fitted on a rotary axis"):
        loaded.predict(linear)
    loaded.motion_ = "angular"
    with pytest.raises(ParameterError, match="motion_ must be one of linear, rotary"):
        check_fitted(loaded)


def test_a_linear_axis_file_is_refused_for_a_rotary_log(rotary):
    _, model, cut = rotary
    with pytest.raises(GreyboxError, match="log is of a rotary axis .* describes a linear one"):
        predict_process(model, prepare([cut]), axis_config=read_axis_config(EXAMPLE_X))


def test_predict_on_a_rotary_cut_gives_the_process_torque(rotary):
    _, model, cut = rotary
    (run,) = prepare([cut])
    config = read_axis_config(EXAMPLE_C)
    result = predict_process(model, run, axis_config=config)
    columns = result.columns()
    assert {"torque_process_Nm", "position_deg", "velocity_deg_s"} <= set(columns)
    assert not {"force_process_N", "position_mm", "velocity_mm_s"} & set(columns)
    truth = run.extras["truth_process_torque_Nm"]
    in_cut = np.abs(run.extras["truth_process_A"]) > 0
    assert in_cut.sum() > 1000
    error = abs(columns["torque_process_Nm"][in_cut].mean() - truth[in_cut].mean()) / abs(truth[in_cut].mean())
    assert error < 0.05
    assert result.attrs["axis_config"]["torque_constant_driving_Nm_per_A"] == pytest.approx(1.35 * 90 * 0.8)


def test_figures_label_rotary_units(rotary):
    _, model, cut = rotary
    (run,) = prepare([cut])
    figure = plot_process(predict_process(model, run, axis_config=read_axis_config(EXAMPLE_C)))
    labels = [ax.get_ylabel() for ax in figure.axes]
    assert "velocity [deg/s]" in labels and "process torque [Nm]" in labels
    assert not any("mm" in label or "[N]" in label for label in labels)
    figure = plot_log(run)
    labels = [ax.get_ylabel() for ax in figure.axes] + [ax.get_xlabel() for ax in figure.axes]
    assert "position [deg]" in labels and "velocity [deg/s]" in labels and not any("mm" in t for t in labels)


def test_every_command_runs_on_a_rotary_log(rotary, tmp_path, capsys):
    root, _, _ = rotary
    assert cli.main(["info", str(root / "air.mcap"), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["motion"] == "rotary" and "position_min_deg" in summary and "speed_max_deg_min" in summary
    assert cli.main(["info", str(root / "air.mcap")]) == 0
    assert "position deg" in capsys.readouterr().out
    assert cli.main(["train", "--model", "stribeck", "--train", str(root / "air.mcap"),
                     "--out", str(tmp_path / "s.gbm")]) == 0
    assert "A s/deg" in capsys.readouterr().out
    assert cli.main(["evaluate", str(tmp_path / "s.gbm"), "--test", str(root / "calibration.mcap"),
                     "--out", str(tmp_path / "report")]) == 0
    assert (tmp_path / "report" / "index.html").exists()
    out = tmp_path / "cut.csv"
    assert cli.main(["predict", str(tmp_path / "s.gbm"), str(root / "cut.mcap"), "--out", str(out),
                     "--axis-config", str(EXAMPLE_C), "--calibration", str(root / "calibration.mcap"),
                     "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert "torque   rms process" in printed and "Nm/A driving" in printed
    table = pd.read_csv(out)
    assert {"torque_process_Nm", "torque_process_lower_Nm", "torque_process_upper_Nm",
            "position_deg", "velocity_deg_s"} <= set(table.columns)
    metadata = json.loads(Path(f"{out}.json").read_text())
    assert "low_velocity_deg_s" in metadata["attrs"]["interval"]["thresholds"]
    assert "_mm" not in json.dumps(metadata["attrs"]["interval"]) + json.dumps(metadata["attrs"]["axis_config"])
    assert cli.main(["plot", str(root / "cut.mcap"), "--out", str(tmp_path / "cut.png")]) == 0
    assert (tmp_path / "cut.png").stat().st_size > 10_000


def test_discover_names_effect_parameters_in_deg(rotary, tmp_path, capsys):
    root, _, _ = rotary
    document = tmp_path / "discovery.json"
    assert cli.main(["discover", "--model", "stribeck", "--train", str(root / "air.mcap"),
                     "--test", str(root / "calibration.mcap"), "--json", str(document), "--quiet",
                     "--effects", "position_periodic_friction", "position_trend", "--null-replicates", "20"]) == 0
    printed = capsys.readouterr().out
    effects = [line for line in printed.splitlines() if line.startswith("  1. ")]
    assert effects and "_deg" in effects[0] and "_mm" not in effects[0]
    assert json.loads(document.read_text())["length_unit"] == "deg"


def test_compensate_on_the_rotary_twin_reports_in_mdeg_and_refuses_a_mixed_study(rotary, tmp_path, capsys):
    root, _, _ = rotary
    out = tmp_path / "loop"
    assert cli.main(["compensate", "--plant", "twin-C", "--model-file", str(root / "c.gbm"), "--out", str(out),
                     "--duration", "4", "--quiet"]) == 0
    assert "RMS mdeg" in capsys.readouterr().out
    assert "RMS error [mdeg]" in (out / "compensation.md").read_text()
    assert "rms_error_deg" in pd.read_csv(out / "compensation.csv").columns
    status = cli.main(["compensate", "--plant", "twin-X", "--model-file", str(root / "c.gbm"),
                       "--out", str(tmp_path / "mixed")])
    error = capsys.readouterr().err.strip()
    assert status == 2 and "c.gbm: a rotary axis, the plant twin-X is a linear one" in error and "\n" not in error


def test_a_modulo_axis_is_unwrapped_with_a_note(tmp_path):
    time = np.arange(10000) * 0.002
    path = tmp_path / "modulo.csv"
    pd.DataFrame({"time_s": time, "position_deg": (60.0 * time) % 360.0, "velocity_deg_s": np.full_like(time, 60.0),
                  "current_A": np.zeros_like(time)}).to_csv(path, index=False)
    with pytest.warns(UserWarning, match="wraps around a turn 3 time"):
        log = read_log(path)
    np.testing.assert_allclose(log.position, 60.0 * time, atol=1e-9)
    assert check_velocity_units(log) == pytest.approx(1.0, rel=1e-3)
