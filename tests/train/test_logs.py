"""Training as a library (issue 43, item 3): ``train_logs`` fits, records and returns the model, and a model
trained from Python or by the fleet carries the same training record as one of ``greybox train``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from export_logs import write_export_logs

from greybox.cli import main
from greybox.data.io import read_log
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError
from greybox.fleet.train import train_jobs, train_model
from greybox.models.files import load_model, save_model
from greybox.models.friction import CoulombModel
from greybox.train import train_logs


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    """Two export-like air cuts in one folder (one machine to the fleet)."""
    files = write_export_logs(tmp_path_factory.mktemp("mill"))
    return [files["aircut_1"], files["aircut_2"]]


def _info(capsys, path) -> tuple[list[str], dict]:
    """What ``greybox info`` prints of a model file from its training record on, and its JSON records."""
    assert main(["info", str(path)]) == 0
    text = capsys.readouterr().out.splitlines()
    assert main(["info", "--json", str(path)]) == 0
    summary = json.loads(capsys.readouterr().out)
    return text[text.index("training:"):], summary["records"]


def test_python_and_fleet_models_show_the_command_lines_training_record(logs, tmp_path, capsys):
    cli_file = tmp_path / "cli.gbm"
    assert main(["train", "--model", "coulomb", "--train", *map(str, logs), "--out", str(cli_file), "--quiet"]) == 0
    capsys.readouterr()
    cli_model = load_model(cli_file)
    params = cli_model.get_params(deep=False)  # the command line's default: an offset fitted

    python_file = save_model(train_logs("coulomb", logs, params=params), tmp_path / "python.gbm")
    jobs = train_jobs(logs, CoulombModel(**params), str(tmp_path / "fleet"))
    assert len(jobs) == 1
    entry = train_model(jobs[0])
    assert entry["status"] == "ok", entry
    fleet_file = tmp_path / "fleet" / entry["output"]

    cli_lines, cli_records = _info(capsys, cli_file)
    assert any(line.startswith("  files") and logs[0].name in line for line in cli_lines)
    for path in (python_file, fleet_file):
        lines, records = _info(capsys, path)
        assert lines == cli_lines
        assert records == cli_records
        assert load_model(path).training_record_ == cli_model.training_record_


def test_the_record_is_the_models_own_and_measures_its_fit(logs):
    runs = prepare([read_log(path) for path in logs])
    model = train_logs(CoulombModel(), runs, intervals="none")
    record = model.training_record_
    residual = np.concatenate([run.effort - model.predict(run) for run in runs])
    assert record["training_error"]["rmse"] == pytest.approx(np.sqrt(np.mean(residual ** 2)), rel=1e-12)
    assert [entry["name"] for entry in record["runs"]] == [path.name for path in logs]
    assert [entry["name"] for entry in record["files"]] == [path.name for path in logs]  # the runs' sources
    assert "parameter_intervals_" not in vars(model)


def test_the_given_model_is_left_unfitted_and_saving_writes_the_checked_file(logs, tmp_path):
    given = CoulombModel()
    out = tmp_path / "m.gbm"
    model = train_logs(given, logs, out=out)
    assert model is not given and not hasattr(given, "training_record_")
    loaded = load_model(out)
    assert loaded.training_record_ == model.training_record_ and loaded.parameter_intervals_
    with pytest.raises(GreyboxError, match="file exists"):
        train_logs(given, logs, out=out)  # nothing read, nothing overwritten
    with pytest.raises(GreyboxError, match="one of the training logs"):
        train_logs(given, logs, out=logs[0], overwrite=True)


def test_a_second_stage_applies_to_two_stage_models_only(logs):
    with pytest.raises(GreyboxError, match="--stage2 does not apply to the coulomb model"):
        train_logs("coulomb", logs[:1], stage2=logs[1:])
