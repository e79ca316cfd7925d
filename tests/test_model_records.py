"""A model file remembers how it was made (issue 31, item 6): the training record, info, and the warning of
predict and evaluate when a log is prepared otherwise."""

from __future__ import annotations

import hashlib
import json
import zipfile

import numpy as np
import pytest
from export_logs import write_export_logs
from model_files import write_members

from greybox.cli import main
from greybox.data.io import read_log
from greybox.data.prepare import prepare
from greybox.errors import ModelFileError
from greybox.models.files import load_model, save_model
from greybox.models.friction import CoulombModel
from greybox.provenance import check_training_record, preparation_differences


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    directory = tmp_path_factory.mktemp("records")
    files = write_export_logs(directory)
    model = directory / "c.gbm"
    assert main(["train", "--model", "coulomb", "--train", str(files["aircut_1"]), str(files["aircut_2"]),
                 "--out", str(model), "--quiet"]) == 0
    return files, model


def test_the_model_file_records_files_preparation_errors_and_ranges(trained):
    files, path = trained
    model, records = load_model(path, records=True)
    record = records["training"]
    for entry, name in zip(record["files"], ("aircut_1", "aircut_2")):
        content = files[name].read_bytes()
        assert entry == {"name": files[name].name, "bytes": len(content), "sha256": hashlib.sha256(content).hexdigest()}
    assert record["preparation"]["cutoff_hz"] == 50.0 and record["preparation"]["resample_s"] is None
    assert record["preparation"]["sample_time_s"] == pytest.approx(0.002)
    assert record["preparation"]["derived"] == ["acceleration", "velocity"]  # aircut_2 logs a velocity
    runs = prepare([read_log(files["aircut_1"]), read_log(files["aircut_2"])])
    residual = np.concatenate([run.effort - model.predict(run) for run in runs])
    assert record["training_error"]["rmse"] == pytest.approx(np.sqrt(np.mean(residual ** 2)), rel=1e-9)
    assert record["training_error"]["samples"] == residual.size == sum(run["samples"] for run in record["runs"])
    assert record["ranges"]["position"] == pytest.approx([min(r.position.min() for r in runs),
                                                           max(r.position.max() for r in runs)])
    assert record["operating"]["cells"]  # the region of the motion the runs showed (greybox.data.operating)


def test_info_shows_the_record(trained, capsys):
    files, path = trained
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "training:" in out and files["aircut_1"].name in out and "cut-off 50 Hz" in out
    assert "position range" in out and "training error = RMSE" in out
    assert main(["info", "--json", str(path)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["records"]["training"]["files"][1]["name"] == files["aircut_2"].name


def test_predict_and_evaluate_warn_in_one_line_when_prepared_otherwise(trained, tmp_path, capsys):
    files, path = trained
    out = tmp_path / "p.csv"
    assert main(["predict", str(path), str(files["cut"]), "--out", str(out), "--quiet"]) == 0
    assert "warning" not in capsys.readouterr().err
    assert main(["predict", str(path), str(files["cut"]), "--out", str(out), "--quiet", "--force",
                 "--cutoff-hz", "20"]) == 0
    err = [line for line in capsys.readouterr().err.splitlines() if line.startswith("warning")]
    assert len(err) == 1 and "cut-off 20 Hz (training 50 Hz; --cutoff-hz 50)" in err[0]
    assert main(["evaluate", str(path), "--test", str(files["aircut_1"]), "--cutoff-hz", "20"]) == 0
    err = [line for line in capsys.readouterr().err.splitlines() if line.startswith("warning")]
    assert len(err) == 1 and files["aircut_1"].name in err[0] and "--cutoff-hz 50" in err[0]


def test_resampling_and_a_logged_velocity_are_differences():
    trained = {"sample_time_s": 0.002, "cutoff_hz": 50.0, "resample_s": None, "max_gap_steps": 5.0,
               "time_tolerance": 0.25, "derived": ["acceleration", "velocity"]}
    assert preparation_differences(trained, dict(trained)) == []
    assert "sample time 1 ms (training 2 ms; --resample 0.002)" in \
        preparation_differences(trained, {**trained, "sample_time_s": 0.001})[0]
    assert "--resample 0.002 (training no --resample)" in \
        preparation_differences(trained, {**trained, "resample_s": 0.002})[0]
    assert "derived acceleration" in preparation_differences(trained, {**trained, "derived": ["acceleration"]})[0]


def test_files_without_records_still_load(tmp_path):
    model = CoulombModel().fit(prepare([_log()]))
    path = save_model(model, tmp_path / "old.gbm")
    with zipfile.ZipFile(path) as archive:
        assert "records" not in json.loads(archive.read("model.json"))
    loaded, records = load_model(path, records=True)
    assert records == {} and np.array_equal(loaded.predict(prepare([_log()])[0]), model.predict(prepare([_log()])[0]))


def test_info_shows_the_region_of_a_file_without_a_record(tmp_path, capsys):
    run = prepare([_log()])[0]
    save_model(CoulombModel().fit(run), tmp_path / "old.gbm")
    assert main(["info", str(tmp_path / "old.gbm")]) == 0
    out = capsys.readouterr().out
    assert "training region:" in out and "training:" not in out
    assert f"position range [mm] = {run.position.min():.6g} .. {run.position.max():.6g}" in out


def _log():
    from greybox.data.log import AxisLog

    time = np.arange(2000) * 0.002
    position = 20.0 * np.sin(np.pi * time)
    return AxisLog(time=time, position=position, effort=0.5 * np.tanh(np.gradient(position, time)))


def _rewrite(path, target, change) -> None:
    with zipfile.ZipFile(path) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    document = json.loads(members["model.json"])
    change(document)
    members["model.json"] = json.dumps(document).encode()
    write_members(target, members)


@pytest.mark.parametrize("change, message", [
    (lambda d: d["records"]["training"]["files"][0].update(sha256="../../etc/passwd"), "sha256 must be 64 hex"),
    (lambda d: d["records"]["training"].update(runs="all"), "runs must be a list"),
    (lambda d: d["records"]["training"]["ranges"].update(position=[5.0, 1.0]), "low 5.0 above high 1.0"),
    (lambda d: d["records"]["training"]["preparation"].update(cutoff_hz="50"), "cutoff_hz must be a finite"),
    (lambda d: d.update(records=[1, 2]), "records must be an object"),
    (lambda d: d["records"]["training"]["operating"]["cells"].append([0, 10 ** 9]), "within the grid"),
    (lambda d: d["records"]["training"]["operating"].update(window_s=float("inf")), "window_s"),
])
def test_a_hostile_record_is_refused_in_one_line(trained, tmp_path, capsys, change, message):
    _, path = trained
    target = tmp_path / "hostile.gbm"
    _rewrite(path, target, change)
    with pytest.raises(ModelFileError, match=message):
        load_model(target)
    assert main(["info", str(target)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "hostile.gbm" in err


def test_unknown_records_are_skipped_on_loading_and_refused_on_saving(trained, tmp_path):
    _, path = trained
    target = tmp_path / "newer.gbm"
    _rewrite(path, target, lambda d: d["records"].update(model_selection={"table": []}))
    assert set(load_model(target, records=True)[1]) == {"training"}
    with pytest.raises(ModelFileError, match="unknown record 'model_selection'"):
        save_model(load_model(target), tmp_path / "x.gbm", records={"model_selection": {}})


def test_the_record_check_refuses_missing_keys():
    with pytest.raises(ValueError, match="exactly"):
        check_training_record({"version": 1})


def test_each_axis_of_a_machine_model_records_its_training(tmp_path, capsys):
    from greybox.data.io import write_log
    from greybox.data.log import AxisLog

    logs = []
    for axis, scale in (("X", 1.0), ("Y", 2.0)):
        log = _log()
        logs.append(AxisLog(time=log.time, position=scale * log.position, effort=scale * log.effort, axis=axis))
    write_log(logs, tmp_path / "xy.csv")
    assert main(["train", "--model", "coulomb", "--axes", "X,Y", "--train", str(tmp_path / "xy.csv"), "--out",
                 str(tmp_path / "m"), "--quiet"]) == 0
    for axis, scale in (("X", 1.0), ("Y", 2.0)):
        _, records = load_model(tmp_path / "m" / f"{axis}.gbm", records=True)
        assert records["training"]["files"][0]["name"] == "xy.csv"
        assert records["training"]["ranges"]["position"][1] == pytest.approx(20.0 * scale, rel=0.01)
    assert main(["predict", str(tmp_path / "m"), str(tmp_path / "xy.csv"), "--out", str(tmp_path / "p.csv"),
                 "--quiet", "--cutoff-hz", "20"]) == 0
    warnings = [line for line in capsys.readouterr().err.splitlines() if line.startswith("warning")]
    assert [("axis X" in line, "axis Y" in line) for line in warnings] == [(True, False), (False, True)]
