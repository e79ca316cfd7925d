"""``greybox compensate``: tables, plots, model files and logs as inputs, refusal to overwrite."""

from __future__ import annotations

import argparse
import csv
import json

import pytest

from greybox.cli import compensate
from greybox.data.io import write_log
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError
from greybox.models.files import save_model
from greybox.models.friction import CoulombModel, GMSModel
from greybox.twin import make_dataset


def run_cli(*argv) -> int:
    parser = argparse.ArgumentParser(prog="greybox")
    compensate.add_parser(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["compensate", *map(str, argv)])
    return args.run(args)


@pytest.fixture(scope="module")
def model_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("models")
    runs = prepare([make_dataset("X", "A", seed=5, duration_s=8.0), make_dataset("X", "P", seed=5, duration_s=8.0)])
    paths = {"coulomb": folder / "coulomb.gbm", "gms": folder / "plant_gms.gbm"}
    save_model(CoulombModel().fit(runs), paths["coulomb"])
    save_model(GMSModel(n_starts=1, max_iter=60).fit(runs), paths["gms"])
    return paths


def test_twin_plant_with_fitted_models(tmp_path, capsys):
    out = tmp_path / "report"
    assert run_cli("--plant", "twin-X", "--model", "coulomb", "stribeck", "--train-duration", 8, "--duration", 4,
                   "--out", out) == 0
    printed = capsys.readouterr().out
    assert "low-stroke" in printed and "high-stroke" in printed and "kp =" in printed
    names = sorted(p.name for p in out.iterdir())
    assert names == ["compensation.csv", "compensation.json", "compensation.md",
                     "tracking_error_high-stroke.png", "tracking_error_low-stroke.png"]
    with open(out / "compensation.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [(r["reference"], r["feedforward"]) for r in rows] == [
        (ref, ff) for ref in ("low-stroke", "high-stroke") for ff in ("none", "coulomb", "stribeck")]
    assert all(float(r["rms_error_mm"]) <= float(r["peak_error_mm"]) for r in rows)
    assert [float(r["rms_vs_none"]) for r in rows if r["feedforward"] == "none"] == [1.0, 1.0]
    document = json.loads((out / "compensation.json").read_text())  # strict JSON
    assert document["settings"]["plant"]["axis"] == "X" and len(document["rows"]) == 6
    assert document["provenance"]["cpu_count"] >= 1 and "numpy" in document["provenance"]["libraries"]
    table = (out / "compensation.md").read_text()
    assert "| friction feed-forward | RMS error [um] | max error [um] |" in table


def test_existing_report_is_kept_unless_forced(tmp_path, model_files):
    out = tmp_path / "report"
    common = ["--plant", "twin-Y", "--model-file", model_files["coulomb"], "--reference", "low", "--duration", 2,
              "--out", out, "--quiet"]
    assert run_cli(*common) == 0
    before = {p.name: p.stat().st_mtime_ns for p in out.iterdir()}
    with pytest.raises(GreyboxError, match="file exists"):
        run_cli(*common)
    assert {p.name: p.stat().st_mtime_ns for p in out.iterdir()} == before
    assert run_cli(*common, "--force") == 0


def test_model_plant_and_a_log_reference(tmp_path, model_files, capsys):
    log = make_dataset("X", "A", seed=9, duration_s=3.0)
    log_path = tmp_path / "cut_17.csv"
    write_log(log, log_path)
    out = tmp_path / "report"
    assert run_cli("--plant", model_files["gms"], "--model-file", model_files["coulomb"], model_files["gms"],
                   "--reference", log_path, "--out", out, "--disturbance-std", 0.02, "--quiet") == 0
    with open(out / "compensation.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert {r["reference"] for r in rows} == {"cut_17"}
    assert [r["feedforward"] for r in rows] == ["none", "coulomb", "gms"]
    assert {r["plant"] for r in rows} == {"plant_gms"}
    errors = {r["feedforward"]: float(r["rms_error_mm"]) for r in rows}
    assert errors["gms"] < errors["none"]  # the plant's own model compensates it best
    assert (out / "tracking_error_cut_17.png").exists()


@pytest.mark.parametrize("argv, message", [
    (["--plant", "twin-Z", "--model", "coulomb"], "no such twin; the twin plants are twin-X, twin-Y"),
    (["--plant", "nope.gbm", "--model", "coulomb"], "nope.gbm: no such model file"),
    (["--plant", "twin-X"], "no feed-forward model"),
    (["--plant", "twin-X", "--model", "magic"], "unknown model kind"),
    (["--plant", "twin-X", "--train", "x.csv"], "--train needs --model"),
    (["--plant", "twin-X", "--model", "coulomb", "--reference", "medium"], "medium"),
])
def test_bad_input_is_a_one_line_error(tmp_path, argv, message):
    with pytest.raises(GreyboxError, match=message):
        run_cli(*argv, "--duration", 1, "--train-duration", 4, "--out", tmp_path / "out", "--quiet")


def test_bad_inertia_is_refused_by_the_option_parser(tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:
        run_cli("--plant", "twin-X", "--model", "coulomb", "--inertia", "heavy", "--out", tmp_path / "out")
    assert stop.value.code == 2
    assert "argument --inertia: must be plant, model or a non-negative number, got heavy" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_static_model_and_model_plant_without_training_logs_are_refused(tmp_path, model_files):
    with pytest.raises(GreyboxError, match="cannot serve as the plant"):
        run_cli("--plant", model_files["coulomb"], "--model", "coulomb", "--out", tmp_path / "a")
    with pytest.raises(GreyboxError, match="needs training logs"):
        run_cli("--plant", model_files["gms"], "--model", "coulomb", "--out", tmp_path / "b")


def test_a_damaged_plant_file_is_named_once(tmp_path):
    plant = tmp_path / "bad.gbm"
    plant.write_bytes(b"not a model")
    with pytest.raises(GreyboxError) as caught:
        run_cli("--plant", plant, "--model", "coulomb", "--out", tmp_path / "a")
    assert str(caught.value).count("bad.gbm") == 1
