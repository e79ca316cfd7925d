"""Tests of ``greybox evaluate`` and ``greybox reproduce`` (through the command's main entry)."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

import greybox.cli as cli
from greybox.data.io import write_log
from greybox.data.log import AxisLog
from greybox.data.prepare import prepare, trim
from greybox.evaluate.regimes import REGIME_NAMES, TRAINING_REGION_NAMES
from greybox.evaluate.report import CSV_COLUMNS
from greybox.metrics import rmse
from greybox.models.files import save_model
from greybox.models.friction import CoulombModel, GMSModel, StribeckModel
from greybox.twin import make_dataset

#: The tests on the twin's logs take long together (model fits, end-to-end runs): left out of the default run;
#: `pytest -m slow` runs them, as .ci/run does.
slow = pytest.mark.slow


@pytest.fixture(autouse=True)
def commands(monkeypatch):
    """Make sure both sub-commands are registered, whether or not the lead has added them yet."""
    monkeypatch.setattr(cli, "COMMANDS", tuple(dict.fromkeys(cli.COMMANDS + ("evaluate", "reproduce"))))


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Two short test logs and two model files trained on a third log."""
    root = tmp_path_factory.mktemp("evaluate")
    train = prepare(make_dataset("X", "A", seed=11, duration_s=8.0))[0]
    paths = {}
    for name, model in (("stribeck", StribeckModel()), ("gms", GMSModel(n_starts=1, max_iter=60))):
        paths[name] = save_model(model.fit(train), root / f"{name}.gbm")
    for d in ("C", "D"):
        paths[d] = root / f"X_{d}.mcap"
        write_log(trim(make_dataset("X", d, seed=11, duration_s=6.0), stop_s=6.0), paths[d])
    return paths


@slow
def test_evaluate_prints_regimes_and_writes_json_and_report(files, tmp_path, capsys):
    out, records_file = tmp_path / "report", tmp_path / "metrics.json"
    status = cli.main(["evaluate", str(files["stribeck"]), str(files["gms"]), "--test", str(files["C"]),
                       str(files["D"]), "--json", str(records_file), "--out", str(out)])
    assert status == 0
    printed = capsys.readouterr().out
    for regime in REGIME_NAMES + TRAINING_REGION_NAMES:
        assert regime in printed
    assert "stribeck" in printed and "gms" in printed and "noise_floor" in printed
    records = {r["model"]: r for r in json.loads(records_file.read_text())}
    assert set(records) == {"stribeck", "gms", "noise_floor"}
    from greybox.models.files import load_model

    runs = prepare([trim(make_dataset("X", d, seed=11, duration_s=6.0), stop_s=6.0) for d in "CD"])
    measured = np.concatenate([run.effort for run in runs])
    for name in ("stribeck", "gms"):
        record = records[name]
        expected = rmse(measured, load_model(files[name]).predict(runs))
        assert record["rmse"] == pytest.approx(expected, rel=1e-3)  # logs round-trip through MCAP (1 mA)
        assert record["kind"] == name and record["logs"] == "X_C+X_D" and record["dataset"] == "test"
        assert record["regimes"]["all"]["rmse"] == pytest.approx(record["rmse"])
        low, high = record["regimes"]["low_velocity"], record["regimes"]["high_velocity"]
        assert low["n"] + high["n"] == record["n"]  # the two envelopes split the samples
        inside, outside = (record["regimes"][region] for region in TRAINING_REGION_NAMES)
        assert inside["n"] + outside["n"] == record["n"]  # so does the model's training region
        pooled = (low["n"] * low["rmse"] ** 2 + high["n"] * high["rmse"] ** 2) / record["n"]
        assert np.sqrt(pooled) == pytest.approx(record["rmse"])
    assert {p.name for p in out.iterdir()} >= {"metrics.json", "metrics.csv", "tables.md", "index.html",
                                               "error_boxplot.png", "time_comparison.png", "residual_position.png"}
    assert 'src="data:image/png;base64,' in (out / "index.html").read_text()
    machine = json.loads((out / "provenance.json").read_text())
    assert machine["cpu_count"] >= 1 and machine["libraries"]["numpy"] == np.__version__
    assert f"numpy {np.__version__}" in (out / "tables.md").read_text()


@slow
def test_evaluate_refuses_before_any_work(files, tmp_path, capsys):
    existing = tmp_path / "m.json"
    existing.write_text("{}")
    assert cli.main(["evaluate", str(files["gms"]), "--test", str(files["C"]), "--json", str(existing)]) == 2
    assert "file exists" in capsys.readouterr().err
    assert existing.read_text() == "{}"
    assert cli.main(["evaluate", str(files["gms"]), "--test", str(files["C"]), "--json", str(files["C"]),
                     "--force"]) == 2
    assert "is one of the inputs" in capsys.readouterr().err
    full = tmp_path / "full"
    full.mkdir()
    (full / "keep.txt").write_text("x")
    assert cli.main(["evaluate", str(files["gms"]), "--test", str(files["C"]), "--out", str(full)]) == 2
    assert "not empty" in capsys.readouterr().err
    missing = tmp_path / "none.gbm"
    assert cli.main(["evaluate", str(missing), "--test", str(files["C"])]) == 2
    err = capsys.readouterr().err
    assert "none.gbm" in err and "Traceback" not in err


@slow
def test_reproduce_refuses_a_non_empty_directory_and_missing_logs(files, tmp_path, capsys):
    full = tmp_path / "full"
    full.mkdir()
    (full / "keep.txt").write_text("x")
    assert cli.main(["reproduce", "--out", str(full), "--data", str(files["C"].parent)]) == 2
    assert "not empty" in capsys.readouterr().err
    assert cli.main(["reproduce", "--out", str(tmp_path / "new"), "--data", str(files["C"].parent)]) == 2
    assert "X_A" in capsys.readouterr().err  # names the missing log before any fitting
    assert not (tmp_path / "new").exists()


@pytest.mark.slow  # end to end: synthetic logs, greybox reproduce --quick, report: 3.5-14 s on 2 cores
def test_reproduce_quick_writes_the_report(tmp_path, capsys):
    data = tmp_path / "data"
    data.mkdir()
    for d in "ABCD":
        write_log(trim(make_dataset("Y", d, seed=2, duration_s=5.0), stop_s=5.0), data / f"Y_{d}.mcap")
    out = tmp_path / "out"
    assert cli.main(["reproduce", "--out", str(out), "--data", str(data), "--axis", "Y", "--quick",
                     "--jobs", "1", "--no-models"]) == 0
    captured = capsys.readouterr()
    assert "axis Y, experiment 2: gmssvr (GMS on A, SVR on B)" in captured.err  # progress display
    # one axis: the one per-axis check of the paper's pattern, flagged as a quick run; the sole SVR's three
    # figures beside the paper's without a pass/fail
    pattern = [line for line in captured.out.splitlines() if line.startswith("  met ") or "not met" in line]
    assert len(pattern) == 1 and "checks met (--quick: small search budgets" in captured.out
    assert "the sole SVR beside the paper (shown, not checked" in captured.out
    assert sum("sole SVR" in line and "(paper " in line for line in captured.out.splitlines()) == 3
    assert "The paper's pattern on the synthetic axes" in (out / "tables.md").read_text()
    records = json.loads((out / "metrics.json").read_text())
    assert {(r["experiment"], r["model"]) for r in records} == {
        (1, m) for m in ("coulomb", "stribeck", "lugre", "gms", "svr", "gmssvr", "noise_floor")} | {
        (2, m) for m in ("stribeck", "gms", "svr", "gmssvr", "gmssvr_eq8", "noise_floor")}
    assert "Table 3" in (out / "tables.md").read_text() and not (out / "models").exists()
    table = pd.read_csv(out / "metrics.csv")  # plain CSV: default settings read it
    assert list(table.columns) == list(CSV_COLUMNS) and len(table) == len(records)
    assert list(table["model"]) == [r["model"] for r in records] and list(table["n"]) == [r["n"] for r in records]
    assert cli.main(["reproduce", "--out", str(out), "--data", str(data), "--axis", "Y"]) == 2  # not empty now


def _sine_log(amplitude_mm: float, offset_mm: float = 0.0, seed: int = 3) -> AxisLog:
    """A 1.5 s sine of ``amplitude_mm`` about ``offset_mm`` at 2 ms, the current of Coulomb + viscous friction."""
    time = np.arange(750) * 0.002
    position = offset_mm + amplitude_mm * np.sin(2.0 * np.pi * time)
    velocity = np.gradient(position, time)
    effort = 0.4 * np.tanh(velocity / 0.5) + 0.01 * velocity + np.random.default_rng(seed).normal(0, 0.02, time.size)
    return AxisLog(time=time, position=position, effort=effort)


@pytest.fixture(scope="module")
def windows(tmp_path_factory):
    """A Coulomb model trained on a 10 mm window, the same model saved without the record of its window, and logs
    inside and beyond it."""
    root = tmp_path_factory.mktemp("windows")
    model = CoulombModel().fit(prepare([_sine_log(5.0)]))
    paths = {"c": save_model(model, root / "c.gbm")}
    del model.position_range_mm_, model.velocity_range_mm_s_, model.effort_range_  # as a file written before
    paths["old"] = save_model(model, root / "old.gbm")
    for name, offset in (("same", 0.0), ("shifted", 3.0)):
        paths[name] = root / f"{name}.csv"
        write_log(_sine_log(5.0, offset, seed=4), paths[name])
    return paths


def test_evaluate_says_where_a_model_leaves_its_training_region(windows, tmp_path, capsys):
    out = tmp_path / "m.json"
    status = cli.main(["evaluate", str(windows["c"]), "--test", str(windows["same"]), str(windows["shifted"]),
                       "--json", str(out)])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    record = json.loads(out.read_text())[0]
    inside, outside = (record["regimes"][name] for name in TRAINING_REGION_NAMES)
    for name, row in zip(TRAINING_REGION_NAMES, (inside, outside)):
        assert any(line.split()[:2] == [name, str(row["n"])] for line in captured.out.splitlines())
    assert inside["n"] + outside["n"] == record["n"] and outside["n"] > 0
    notes = [line for line in captured.err.splitlines() if line.startswith("note:")]
    shifted = record["training_region"]["per_log"]["shifted"]
    assert len(notes) == 1  # none on the log inside the window
    assert notes[0].startswith(f"note: shifted.csv: {100 * shifted['share']:.1f} % of the samples lie outside what "
                               f"model c was trained on (positions {100 * shifted['by']['position']:.1f} %, ")
    assert f"standstill {100 * shifted['by']['standstill']:.1f} %)" in notes[0]
    assert notes[0].endswith(f"RMSE there {shifted['outside']['rmse']:.3g} A against {shifted['inside']['rmse']:.3g} "
                             "A inside")


def test_evaluate_of_a_model_file_without_its_training_region_says_so_once(windows, capsys):
    status = cli.main(["evaluate", str(windows["old"]), "--test", str(windows["same"]), str(windows["shifted"])])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    notes = [line for line in captured.err.splitlines() if line.startswith("note:")]
    assert len(notes) == 1 and notes[0].startswith("note: old: the model file has no record of its training region")
    assert "inside_training" not in captured.out and "outside_training" not in captured.out
