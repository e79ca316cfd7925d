"""``greybox info`` on model files: kind, parameters and fit, as text and as strict JSON; bad files in one line."""

from __future__ import annotations

import json
import shutil

import pytest
from svr_runs import FIXED, sweep_run

from greybox.cli import main
from greybox.data.io import write_log
from greybox.models.files import save_model
from greybox.models.svr import SVRCurrentModel


@pytest.fixture(scope="module")
def model_file(tmp_path_factory):
    model = SVRCurrentModel(**FIXED, velocity_weight=4.0).fit(sweep_run(1, n=1500))
    return model, save_model(model, tmp_path_factory.mktemp("models") / "x_svr.gbm")


def _strict(text: str):
    def refuse(constant):
        raise ValueError(f"not strict JSON: {constant}")
    return json.loads(text, parse_constant=refuse)


def test_a_model_file_prints_its_kind_parameters_and_fit_beside_a_log(model_file, tmp_path, capsys):
    model, path = model_file
    log = tmp_path / "run.csv"
    write_log(sweep_run(2, n=500), log)
    assert main(["info", str(path), str(log)]) == 0
    out = capsys.readouterr().out
    assert out.startswith("model x_svr.gbm: svr, linear axis, effort in A, step 2 ms\n")
    for row in model.parameter_table():
        assert f"  {row.name:<15} = " in out, row.name
    assert "  velocity_weight = 4\n" in out and "fit:\n  n_samples          = 1500" in out
    assert "\nrun.csv " in out  # the log's line after the model


def test_json_holds_every_parameter_with_its_unit_in_strict_json(model_file, capsys):
    model, path = model_file
    assert main(["info", "--json", str(path)]) == 0
    (line,) = capsys.readouterr().out.splitlines()
    summary = _strict(line)
    assert summary["kind"] == "svr" and summary["effort_unit"] == "A"
    assert summary["parameters"] == {row.name: {"value": float(row.value) if row.name != "n_support" else row.value,
                                                "unit": row.unit} for row in model.parameter_table()}
    assert summary["fit"]["cv_rmse_A"] is None  # NaN (nothing optimised) is null, not NaN
    assert summary["fit"]["n_train"] == model.n_train_


def test_a_model_file_under_another_name_is_recognised_by_its_content(model_file, tmp_path, capsys):
    _, path = model_file
    renamed = tmp_path / "model.bin"
    shutil.copy(path, renamed)
    assert main(["info", str(renamed)]) == 0
    assert capsys.readouterr().out.startswith("model model.bin: svr")


@pytest.mark.parametrize("content, problem", [(b"", "not a ZIP archive"), (b"PK\x03\x04junk", "not a ZIP archive"),
                                              (None, "no such model file")])
def test_a_bad_model_file_is_one_line_and_status_2(tmp_path, capsys, content, problem):
    path = tmp_path / "bad.gbm"
    if content is not None:
        path.write_bytes(content)
    assert main(["info", str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.count("\n") == 1 and "bad.gbm" in captured.err and problem in captured.err, captured.err
