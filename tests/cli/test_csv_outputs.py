"""Every CSV file greybox writes is plain: default ``pandas.read_csv`` reads its header and its values.

The commands that write CSV are run on small inputs (``predict --out x.csv``, ``evaluate --out DIR``,
``compensate --out DIR``, and the library's ``write_log``); then every ``*.csv`` found in the output
folder is read with ``pandas.read_csv(path)`` and no options, and its columns and values are compared
with what the command computed (the JSON files it wrote beside, or the log and model themselves).
The metadata of a log or process table go to the sidecar ``x.csv.json``, from which greybox reads
them back.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

import greybox.cli as cli
from greybox.control.report import REPORT_FILES
from greybox.data.file_metadata import sidecar_path
from greybox.data.io import read_log, write_log
from greybox.data.prepare import prepare, trim
from greybox.evaluate.report import CSV_COLUMNS
from greybox.models.files import load_model, save_model
from greybox.models.friction import CoulombModel, GMSModel
from greybox.twin import make_dataset

PROCESS_COLUMNS = ["time_s", "current_measured_A", "current_model_A", "current_process_A", "position_mm",
                   "velocity_mm_s", "outside_training"]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Two small model files trained on a short air cut, and a short cutting log (MCAP).

    The air cut moves both ways (8 s of dataset A; its first 6 s go one way only): on motion in one
    direction the GMS fit is degenerate (its inertia comes out 0), and the GMS model must serve as a plant.
    """
    root = tmp_path_factory.mktemp("csv_outputs")
    train = prepare([make_dataset("X", "A", seed=3, duration_s=8.0)])[0]
    assert train.velocity.min() < -1.0 and train.velocity.max() > 1.0
    paths = {"coulomb": save_model(CoulombModel().fit(train), root / "coulomb.gbm"),
             "gms": save_model(GMSModel(n_starts=1, max_iter=40).fit(train), root / "gms.gbm")}
    paths["log"] = root / "X_C.mcap"
    write_log(trim(make_dataset("X", "C", seed=4, duration_s=4.0, cutting=True), stop_s=4.0), paths["log"])
    return paths


def _main(capsys, *argv) -> tuple[int, str, str]:
    status = cli.main([str(arg) for arg in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def _csv_files(folder) -> list:
    return sorted(path for path in folder.rglob("*.csv"))


def _same(read: pd.Series, expected) -> None:
    """Values of a column read by pandas equal ``expected`` (None and NaN read as NaN; text as text)."""
    for got, want in zip(read.tolist(), expected):
        if want is None or (isinstance(want, float) and math.isnan(want)):
            assert isinstance(got, float) and math.isnan(got)
        elif isinstance(want, str):
            assert str(got) == want
        else:
            assert got == want, (read.name, got, want)
    assert len(read) == len(expected)


def test_predict_csv_is_plain_and_its_metadata_sit_beside_it(files, tmp_path, capsys):
    out = tmp_path / "process.csv"
    status, stdout, stderr = _main(capsys, "predict", files["gms"], files["log"], "--out", out)
    assert status == 0, stderr
    assert _csv_files(tmp_path) == [out]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["process.csv", "process.csv.json"]
    assert f"wrote {out}\n" in stdout and f"wrote {out}.json\n" in stdout
    assert out.read_text().splitlines()[0] == ",".join(PROCESS_COLUMNS)  # no comment line before the header

    table = pd.read_csv(out)
    assert list(table.columns) == PROCESS_COLUMNS
    assert all(dtype == np.float64 for dtype in table.dtypes)
    log = prepare([read_log(files["log"])])[0]
    model = load_model(files["gms"])
    np.testing.assert_array_equal(table["current_measured_A"], log.current)
    np.testing.assert_array_equal(table["position_mm"], log.position)
    np.testing.assert_array_equal(table["velocity_mm_s"], log.velocity)
    np.testing.assert_allclose(table["current_model_A"], model.predict(log), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(table["current_process_A"], table["current_measured_A"] - table["current_model_A"])

    metadata = json.loads(sidecar_path(out).read_text())
    assert metadata["axis"] == "X" and metadata["effort_unit"] == "A"
    assert metadata["attrs"]["model_kind"] == "gms" and metadata["attrs"]["log_file"] == str(files["log"])
    # the package reads its own output back, metadata from the sidecar
    back = read_log(out, columns={"current_A": "current_process_A"})
    assert (back.axis, back.effort_unit, back.attrs) == ("X", "A", metadata["attrs"])
    np.testing.assert_array_equal(back.current, table["current_process_A"])


def test_predict_keeps_an_existing_sidecar_unless_force(files, tmp_path, capsys):
    out = tmp_path / "process.csv"
    side = sidecar_path(out)
    side.write_text("keep me\n")
    status, _, stderr = _main(capsys, "predict", files["gms"], files["log"], "--out", out)
    assert status == 2 and f"{side}: file exists; use --force" in stderr and len(stderr.splitlines()) == 1
    assert side.read_text() == "keep me\n" and not out.exists()
    status, _, stderr = _main(capsys, "predict", files["gms"], files["log"], "--out", out, "--force")
    assert status == 0, stderr
    assert json.loads(side.read_text())["attrs"]["model_kind"] == "gms"
    # a sidecar that is not JSON is named when the CSV is read
    side.write_text("{not json")
    status, _, stderr = _main(capsys, "info", out, "--columns", "current_A=current_process_A")
    assert status == 2 and f"{side}: metadata file is not valid JSON" in stderr


def test_evaluate_report_csv_matches_its_json(files, tmp_path, capsys):
    out = tmp_path / "report"
    status, _, stderr = _main(capsys, "evaluate", files["coulomb"], files["gms"], "--test", files["log"],
                              "--out", out)
    assert status == 0, stderr
    assert _csv_files(tmp_path) == [out / "metrics.csv"]
    table = pd.read_csv(out / "metrics.csv")
    assert list(table.columns) == list(CSV_COLUMNS)
    records = json.loads((out / "metrics.json").read_text())
    assert len(table) == len(records) and {r["model"] for r in records} >= {"coulomb", "gms"}
    for column in CSV_COLUMNS:
        _same(table[column], [record.get(column) for record in records])


def test_compensate_report_csv_matches_its_json(files, tmp_path, capsys):
    out = tmp_path / "report"
    status, _, stderr = _main(capsys, "compensate", "--plant", files["gms"], "--model-file", files["coulomb"],
                              "--reference", "low", "--duration", 1, "--out", out, "--quiet")
    assert status == 0, stderr
    assert _csv_files(tmp_path) == [out / REPORT_FILES[1]]
    table = pd.read_csv(out / "compensation.csv")
    rows = json.loads((out / "compensation.json").read_text())["rows"]
    assert list(table.columns) == list(rows[0]) and "rms_error_mm" in table.columns
    assert list(table["feedforward"]) == ["none", "coulomb"]
    for column in table.columns:
        _same(table[column], [row[column] for row in rows])


def test_written_log_reads_with_default_pandas_and_back_with_its_metadata(tmp_path):
    log = make_dataset("Y", "B", seed=8, duration_s=2.0)
    log.attrs["note"] = "written by the test"
    path = tmp_path / "Y_B.csv"
    write_log(log, path)
    assert _csv_files(tmp_path) == [path]
    frame = log.to_frame()
    table = pd.read_csv(path)
    assert list(table.columns) == list(frame.columns) and list(table.columns)[:2] == ["time_s", "position_mm"]
    for column in frame.columns:
        np.testing.assert_array_equal(table[column], frame[column], err_msg=column)
    metadata = json.loads(sidecar_path(path).read_text())
    assert metadata == json.loads(json.dumps({"axis": "Y", "dataset": "B", "effort_unit": "A",
                                              "attrs": log.attrs}))
    back = read_log(path)
    assert (back.axis, back.dataset, back.effort_unit, back.attrs["note"]) == ("Y", "B", "A", "written by the test")
    # the sidecar is where the metadata come from: edit it, and the log read says so
    sidecar_path(path).write_text(json.dumps({**metadata, "axis": "Z"}))
    assert read_log(path).axis == "Z"


def test_metadata_comment_of_earlier_versions_is_still_read(tmp_path):
    path = tmp_path / "old.csv"
    path.write_text('# greybox {"axis": "X", "dataset": "A", "effort_unit": "N", "attrs": {"seed": 1}}\n'
                    "time_s,position_mm,force_N\n0.0,1.0,2.0\n0.002,1.5,2.5\n")
    log = read_log(path)
    assert (log.axis, log.dataset, log.effort_unit, log.attrs) == ("X", "A", "N", {"seed": 1})
    np.testing.assert_array_equal(log.effort, [2.0, 2.5])
