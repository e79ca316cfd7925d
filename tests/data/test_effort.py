"""The effort's quantity travels with the log and the model (issue 31, item 4): a motor torque of a servo trace
is shown in Nm, training logs of a current and of a torque are refused together, and a log of the other
quantity is converted through the axis file's torque constant (or refused without one)."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from export_logs import AXIS, write_export_logs

from greybox.cli import main
from greybox.data.effort import check_one_effort, convert_effort, effort_quantity, shown_unit
from greybox.data.io import read_log
from greybox.data.log import AxisLog
from greybox.data.units import MOTOR_TORQUE
from greybox.errors import GreyboxError

K_T = AXIS["torque_constant_Nm_per_A"]


@pytest.fixture(scope="module")
def exports(tmp_path_factory):
    return write_export_logs(tmp_path_factory.mktemp("exports"))


def _log(source: str, torque: bool) -> AxisLog:
    time = np.arange(50) * 0.002
    return AxisLog(time=time, position=np.sin(time), effort=np.cos(time), source=source,
                   attrs={MOTOR_TORQUE: "torque_Nm"} if torque else {})


def test_the_quantity_of_a_log_is_told_by_its_torque_column(exports):
    assert effort_quantity(read_log(exports["torque_aircut"])) == "motor torque"
    assert effort_quantity(read_log(exports["aircut_1"])) == "current"


def test_units_written_in_ampere_are_shown_in_nm_for_a_motor_torque():
    assert shown_unit("A s^2/mm", "motor torque") == "Nm s^2/mm"
    assert shown_unit("N/A", "motor torque") == "N/Nm"
    assert shown_unit("A s/mm", "current") == "A s/mm"
    assert shown_unit("mm/s", "motor torque") == "mm/s"


def test_mixed_quantities_are_refused_naming_the_files():
    with pytest.raises(GreyboxError) as caught:
        check_one_effort([_log("/d/a.csv", False), _log("/d/b.csv", True), _log("/d/a.csv", False)])
    message = str(caught.value)
    assert "a.csv" in message and "b.csv" in message and "current [A]" in message and "motor torque [Nm]" in message
    assert check_one_effort([_log("a.csv", True), _log("b.csv", True)]) == "motor torque"


def test_conversion_goes_through_the_torque_constant_and_back():
    current = _log("a.csv", False)
    torque = convert_effort([current], "motor torque", K_T)[0]
    assert effort_quantity(torque) == "motor torque"
    np.testing.assert_allclose(torque.effort, K_T * current.effort)
    back = convert_effort([torque], "current", K_T)[0]
    assert effort_quantity(back) == "current"
    np.testing.assert_allclose(back.effort, current.effort)


def test_train_refuses_a_current_log_and_a_torque_log_in_one_line(exports, tmp_path, capsys):
    status = main(["train", "--model", "coulomb", "--train", str(exports["aircut_1"]), str(exports["torque_aircut"]),
                   "--out", str(tmp_path / "m.gbm"), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1
    assert "aircut_1.csv" in err[0] and "torque_aircut.csv" in err[0]
    assert not (tmp_path / "m.gbm").exists()


@pytest.fixture(scope="module")
def torque_model(exports, tmp_path_factory):
    path = tmp_path_factory.mktemp("models") / "t.gbm"
    assert main(["train", "--model", "stribeck", "--train", str(exports["torque_aircut"]), "--out", str(path),
                 "--quiet"]) == 0
    return path


def test_a_torque_model_shows_nm_in_info_and_records_its_quantity(torque_model, capsys):
    capsys.readouterr()
    assert main(["info", str(torque_model)]) == 0
    out = capsys.readouterr().out
    assert "effort in Nm (motor torque)" in out.splitlines()[0]
    coulomb = next(line for line in out.splitlines() if line.strip().startswith("coulomb "))
    assert coulomb.split()[3] == "Nm"
    assert "effort         = motor torque [Nm]" in out and "RMSE" in out and " A," not in out
    assert main(["info", "--json", str(torque_model)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["effort"] == {"quantity": "motor torque", "unit": "Nm"}
    assert summary["records"]["training"]["training_error"]["quantity"] == "motor torque"


def test_predicting_a_torque_log_writes_nm_and_the_force_constant_per_nm(exports, torque_model, tmp_path, capsys):
    out = tmp_path / "p.csv"
    assert main(["predict", str(torque_model), str(exports["torque_cut"]), "--axis-config", str(exports["axis"]),
                 "--out", str(out), "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert "rms measured" in printed and " Nm," in printed and " A," not in printed and "N/Nm" in printed
    columns = list(pd.read_csv(out, nrows=1).columns)
    assert "motor_torque_process_Nm" in columns and not any(name.endswith("_A") for name in columns)
    attrs = json.loads((tmp_path / "p.csv.json").read_text())["attrs"]
    lossless = 2.0 * math.pi / (AXIS["screw_lead_mm"] * 1e-3)  # N per Nm: the torque constant is in the log
    assert attrs["effort"] == {"quantity": "motor torque", "unit": "Nm"}
    assert attrs["axis_config"]["force_constant_driving_N_per_Nm"] == pytest.approx(
        AXIS["efficiency_driving"] * lossless)


def test_a_current_log_on_a_torque_model_is_refused_without_an_axis_file(exports, torque_model, tmp_path, capsys):
    status = main(["predict", str(torque_model), str(exports["cut"]), "--out", str(tmp_path / "p.csv"), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "cut.csv" in err[0] and "--axis-config" in err[0]


def test_a_current_log_on_a_torque_model_is_converted_with_a_note(exports, torque_model, tmp_path, capsys):
    converted, same = tmp_path / "c.csv", tmp_path / "t.csv"
    assert main(["predict", str(torque_model), str(exports["cut"]), "--axis-config", str(exports["axis"]),
                 "--out", str(converted), "--quiet"]) == 0
    notes = [line for line in capsys.readouterr().err.splitlines() if "converted" in line]
    assert len(notes) == 1 and "torque constant 1.2 Nm/A" in notes[0]
    # the same model on the torque trace of the same motion: the process force agrees with the converted one
    assert main(["predict", str(torque_model), str(exports["torque_cut"]), "--axis-config", str(exports["axis"]),
                 "--out", str(same), "--quiet"]) == 0

    def cut_force(path, log):
        force = pd.read_csv(path)["force_process_N"].to_numpy()
        truth = pd.read_csv(log, sep=";", decimal=",")["truth_force [N]"].to_numpy()
        return force[np.abs(truth) > 1.0].mean(), truth[np.abs(truth) > 1.0].mean()

    estimated, injected = cut_force(converted, exports["cut"])
    assert estimated == pytest.approx(injected, rel=0.01)  # without the conversion it is k_t times too small
    on_torque, injected_there = cut_force(same, exports["torque_cut"])
    assert on_torque == pytest.approx(injected_there, rel=0.01)


def test_evaluate_refuses_a_model_of_another_quantity(exports, torque_model, capsys):
    status = main(["evaluate", str(torque_model), "--test", str(exports["aircut_1"])])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "motor torque" in err[0] and "current" in err[0]


def test_evaluate_refuses_test_logs_of_a_current_and_a_torque(exports, torque_model, capsys):
    status = main(["evaluate", str(torque_model), "--test", str(exports["torque_aircut"]), str(exports["aircut_1"])])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "torque_aircut.csv" in err[0] and "aircut_1.csv" in err[0]
    assert "evaluate them apart" in err[0]
