"""Several axes in one log: axis-prefixed columns, MCAP channels and TDMS groups; machine files; machine models
trained, predicted and refused on the command line (the machine model file itself: tests/models/test_machine.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import greybox.cli as cli
from greybox.data.io import read_log, write_log
from greybox.data.machine_config import parse_machine_config, read_machine_config
from greybox.data.prepare import prepare
from greybox.data.units import axes_in_columns
from greybox.errors import GreyboxError, LogError
from greybox.models.files import load_model
from greybox.models.friction import StribeckModel
from greybox.models.machine import MachineModel, save_machine
from greybox.predict.process import predict_process
from greybox.twin import make_dataset

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "machine.toml"


def _machine_logs(dataset="A", seed=0, duration_s=4.0, **options):
    logs = [make_dataset(axis, dataset, seed + k, duration_s=duration_s, **options) for k, axis in enumerate("XYC")]
    shortest = min(len(log) for log in logs)
    return [log.select(slice(0, shortest)) for log in logs]


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mcap"])
def test_several_axes_round_trip_through_one_file(tmp_path, suffix):
    logs = _machine_logs()
    path = tmp_path / f"machine{suffix}"
    write_log(logs, path)
    for log in logs:
        back = read_log(path, axis=log.axis)
        assert back.axis == log.axis and back.motion == log.motion
        np.testing.assert_array_equal(back.position, log.position)
        np.testing.assert_array_equal(back.effort, log.effort)
        assert sorted(back.extras) == sorted(log.extras)  # its own truth channels, none of the other axes
        assert back.attrs["seed"] == log.attrs["seed"]


def test_a_table_of_several_axes_names_them(tmp_path):
    logs = _machine_logs()
    path = tmp_path / "machine.csv"
    write_log(logs, path)
    columns = pd.read_csv(path, nrows=1).columns
    assert columns[0] == "time_s" and {"X_position_mm", "Y_current_A", "C_position_deg"} <= set(columns)
    assert axes_in_columns(columns) == ["X", "Y", "C"]
    with pytest.raises(LogError, match=r"holds several axes \(X, Y, C\); choose one with axis='X'"):
        read_log(path)
    with pytest.raises(LogError, match="no columns of axis 'Z' .* the axes in the file: X, Y, C"):
        read_log(path, axis="Z")


def test_axes_with_different_time_stamps_do_not_share_a_table(tmp_path):
    x, y = make_dataset("X", "A", 1, duration_s=3), make_dataset("Y", "A", 2, duration_s=3)
    y = y.replace(time=y.time + 0.001)
    with pytest.raises(LogError, match="different time stamps"):
        write_log([x.select(slice(0, 1000)), y.select(slice(0, 1000))], tmp_path / "xy.csv")


def test_tdms_axes_by_channel_prefix_and_by_group(tmp_path):
    from nptdms import ChannelObject, TdmsWriter

    logs = _machine_logs()
    with TdmsWriter(tmp_path / "prefixed.tdms") as writer:
        channels = [ChannelObject("Log", "time_s", logs[0].time)]
        channels += [ChannelObject("Log", f"{log.axis}_{name}", values) for log in logs
                     for name, values in log.named_channels()]
        writer.write_segment(channels)
    with TdmsWriter(tmp_path / "groups.tdms") as writer:
        writer.write_segment([ChannelObject(log.axis, name, values) for log in logs
                              for name, values in log.named_channels(time=True)])
    for name in ("prefixed.tdms", "groups.tdms"):
        back = read_log(tmp_path / name, axis="C")
        assert back.motion == "rotary"
        np.testing.assert_array_equal(back.position, logs[2].position)


def test_the_example_machine_file():
    machine = read_machine_config(EXAMPLE)
    assert list(machine.axes) == ["X", "Y", "C"]
    assert machine.axis("C").motion == "rotary" and machine.axis("C").config.load_constants[0] == pytest.approx(97.2)
    assert machine.axis("X").config.load_constants[0] == pytest.approx(1.35 * 2 * np.pi * 0.9 / 0.010)
    with pytest.raises(GreyboxError, match="no axis 'Z'; the machine has X, Y, C"):
        machine.axis("Z")


@pytest.mark.parametrize("document, message", [
    ({"name": "m"}, "no axes"),
    ({"axes": {"X1-a": {}}}, "axis name 'X1-a' must be letters and digits"),
    ({"axes": {"X": {"channels": {"position_mm": "P"}, "lead": 5}}}, r"\[axes.X\]: unknown key 'lead'"),
    ({"axes": {"C": {"motion": "rotary", "torque_constant_Nm_per_A": 1, "screw_lead_mm": 5, "gear_ratio": 9,
                     "efficiency": 0.8}}}, r"\[axes.C\]: a rotary axis .* has no screw_lead_mm"),
    ({"axes": {"X": {}}, "spindle": 1}, "unknown key 'spindle'"),
])
def test_machine_file_errors(document, message):
    with pytest.raises(GreyboxError, match=message):
        parse_machine_config(document, source="m.toml")


def test_an_axis_with_channels_only_and_shared_channels():
    machine = parse_machine_config({"channels": {"time_s": "Time"},
                                    "axes": {"X": {"channels": {"position_mm": "X1_Pos", "current_A": "X1_I"}}}})
    axis = machine.axis("X")
    assert axis.config is None and axis.motion == "linear"
    assert axis.channels == {"time_s": "Time", "position_mm": "X1_Pos", "current_A": "X1_I"}


@pytest.fixture(scope="module")
def fitted():
    runs = {log.axis: prepare([log])[0] for log in _machine_logs(duration_s=10)}
    return {axis: StribeckModel().fit(run) for axis, run in runs.items()}


@pytest.fixture(scope="module")
def three_axis_csvs(tmp_path_factory):
    root = tmp_path_factory.mktemp("machine")
    for name, logs in (("air_A.csv", _machine_logs("A", seed=10, duration_s=15)),
                       ("air_C.csv", _machine_logs("C", seed=20, duration_s=8)),
                       ("cut_D.csv", _machine_logs("D", seed=30, cutting=True))):
        write_log(logs, root / name)
    return root


def test_a_three_axis_csv_trains_evaluates_and_predicts(three_axis_csvs, tmp_path, capsys):
    root = three_axis_csvs
    machine_dir = tmp_path / "machine"
    assert cli.main(["train", "--model", "stribeck", "--train", str(root / "air_A.csv"), "--axes", "X,Y,C",
                     "--out", str(machine_dir), "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert "trained stribeck for axis C" in printed and "A s/deg" in printed and "A s/mm" in printed
    assert cli.main(["evaluate", str(machine_dir / "Y.gbm"), "--test", str(root / "air_C.csv"), "--axis", "Y"]) == 0
    assert "samples" in capsys.readouterr().out
    out = tmp_path / "process.parquet"
    assert cli.main(["predict", str(machine_dir), str(root / "cut_D.csv"), "--machine", str(EXAMPLE),
                     "--out", str(out), "--calibration", str(root / "air_C.csv"), "--plot",
                     str(tmp_path / "process.png"), "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert "axis C:" in printed and "resultant process force of axes X, Y" in printed
    table = pd.read_parquet(out)
    assert {"X_force_process_N", "Y_force_process_lower_N", "C_torque_process_Nm", "C_position_deg",
            "force_process_resultant_N"} <= set(table.columns)
    np.testing.assert_allclose(table["force_process_resultant_N"],
                               np.hypot(table["X_force_process_N"], table["Y_force_process_N"]), rtol=1e-12)
    # each axis's columns are what the axis's own model file gives on that axis alone
    (x_run,) = prepare([read_log(root / "cut_D.csv", axis="X")])
    alone = predict_process(load_model(machine_dir / "X.gbm"), x_run,
                            axis_config=read_machine_config(EXAMPLE).axis("X").config)
    np.testing.assert_array_equal(table["X_force_process_N"], alone.load)
    assert (tmp_path / "process.png").stat().st_size > 10_000


def test_machine_options_are_checked(three_axis_csvs, tmp_path, capsys, fitted):
    root = three_axis_csvs
    machine_dir = tmp_path / "machine"
    save_machine(MachineModel(models=fitted), machine_dir)
    for extra, message in ((["--axis-config", str(EXAMPLE)], "--axis-config does not apply to a machine model"),
                           (["--axis", "X"], "--axis does not apply to a machine model")):
        status = cli.main(["predict", str(machine_dir), str(root / "cut_D.csv"), "--out", str(tmp_path / "p.csv"),
                           *extra])
        assert status == 2 and message in capsys.readouterr().err
    status = cli.main(["train", "--model", "stribeck", "--train", str(root / "air_A.csv"), "--axes", "X,X",
                       "--out", str(tmp_path / "m2")])
    assert status == 2 and "names an axis twice" in capsys.readouterr().err
    status = cli.main(["train", "--model", "stribeck", "--train", str(root / "air_A.csv"), "--axes", "X",
                       "--out", str(machine_dir)])
    assert status == 2 and "file exists" in capsys.readouterr().err


def test_missing_axes_are_named_as_such(tmp_path, fitted, capsys):
    single = make_dataset("C", "A", 1, duration_s=3)
    assert axes_in_columns(dict(single.named_channels(time=True))) == []  # truth_* columns are no axis "truth"
    logs = _machine_logs()
    write_log([logs[0], logs[2]], tmp_path / "xc.mcap")  # no Y
    with pytest.raises(LogError, match=r"no channel of axis 'Y' \(/axis/Y\); the channels in the file: /axis/C, "
                                       r"/axis/X"):
        read_log(tmp_path / "xc.mcap", axis="Y")
    write_log([logs[0], logs[2]], tmp_path / "xc.csv")
    status = cli.main(["train", "--model", "stribeck", "--train", str(tmp_path / "xc.csv"), "--axes", "X", "Y",
                       "--out", str(tmp_path / "m"), "--quiet"])
    captured = capsys.readouterr()
    assert status == 2 and "no columns of axis 'Y'" in captured.err and "trained" not in captured.out
    assert not (tmp_path / "m").exists()


def test_the_command_line_names_its_options_not_python_keywords(tmp_path, capsys):
    logs = _machine_logs()
    write_log(logs, tmp_path / "m.csv")
    write_log(logs, tmp_path / "m.mcap")
    for path, option in ((tmp_path / "m.csv", "--axis X"), (tmp_path / "m.mcap", "--topic TOPIC")):
        assert cli.main(["info", str(path)]) == 2
        error = capsys.readouterr().err
        assert option in error and "axis=" not in error and "topic=" not in error
