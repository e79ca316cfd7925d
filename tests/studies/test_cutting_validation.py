"""The cutting validation, run small: its tables, figures and the strength sweep hold together."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from greybox.errors import GreyboxError
from studies.cutting import cutting_validation, detail_table, sweep_table

#: A validation study's tests (runs of the study, its script, the real data sets): left out of the default
#: run (`pytest -m slow` runs them, as .ci/run does).
pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[2]
SCRIPT = REPO / "scripts" / "cutting_validation.py"
DATA = REPO / "data"
AXIS_CONFIG = REPO / "examples" / "axis_x.toml"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("validation")
    validation = cutting_validation(DATA, AXIS_CONFIG, kinds=("coulomb", "stribeck"), strengths=(0.5, 2.0),
                                    strength=0.5, json_path=out / "v.json", markdown_path=out / "v.md",
                                    plot_dir=out / "figures")
    return validation, out, json.loads((out / "v.json").read_text())


def test_every_output_is_written(run):
    validation, out, result = run
    assert validation.figure == out / "figures" / "correlation_vs_cut_force.png"
    assert (out / "figures" / "correlation_vs_cut_force.png").read_bytes()[:4] == b"\x89PNG"
    assert (out / "figures" / "predict_coulomb_X_D.png").exists()
    table = (out / "v.md").read_text()
    assert "Correlation by cut strength" in table and "perfect model (noise only)" in table
    assert [(row["model"], row["test"]) for row in result["rows"]] == [
        ("coulomb", "X_C seed 7"), ("coulomb", "X_D seed 7"), ("stribeck", "X_C seed 7"), ("stribeck", "X_D seed 7")]


def test_process_error_is_the_air_cut_error_at_every_strength(run):
    _, _, result = run
    for row in result["rows"]:
        assert row["air_identity_A"] <= 1e-3 + 1e-9
        rmses = [item["process_rmse_A"] for item in row["by_strength"].values()]
        assert max(rmses) - min(rmses) <= 1e-3
        assert row["process_rmse_A"] == pytest.approx(row["air_same_trajectory_rmse_A"], abs=1e-3)


def test_correlation_rises_with_strength_and_the_threshold_sits_between(run):
    _, _, result = run
    for row in result["rows"]:
        weak, strong = row["by_strength"]["0.5"], row["by_strength"]["2"]
        assert strong["correlation"] > weak["correlation"]
        assert strong["mean_cut_force_true_N"] == pytest.approx(4 * weak["mean_cut_force_true_N"])
        needed = row["strength_for_target_A"]
        # The threshold is consistent with the swept logs: below it r < target, above it r >= target.
        for item in (weak, strong):
            assert (item["correlation"] >= row["target"]) == (needed is not None and item["strength_A"] >= needed)
        if needed is not None:
            assert row["mean_cut_force_for_target_N"] == pytest.approx(
                abs(weak["mean_cut_force_true_N"]) * needed / 0.5, rel=1e-9)


def test_strength_of_the_table_must_be_swept_and_kinds_registered():
    with pytest.raises(GreyboxError, match="not one of the swept strengths"):
        cutting_validation(DATA, AXIS_CONFIG, kinds=("coulomb",), strengths=(0.5, 2.0), strength=1.0)
    with pytest.raises(GreyboxError, match="unknown model kind"):
        cutting_validation(DATA, AXIS_CONFIG, kinds=("coulombb",), strengths=(0.5,), strength=0.5)


def test_the_script_runs_as_a_user_runs_it(tmp_path):
    result = subprocess.run([sys.executable, str(SCRIPT), "--model", "coulomb", "--strengths", "0.5", "2",
                             "--strength", "0.5", "--json", str(tmp_path / "v.json"), "--record"],
                            capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert result.returncode == 0, result.stderr
    assert "Correlation by cut strength" in result.stdout and "noise floor rms(truth_noise_A)" in result.stdout
    assert [row["model"] for row in json.loads((tmp_path / "v.json").read_text())["rows"]] == ["coulomb"] * 2
    # --record: the figures last, from which the printed tables render again (the page's view of the record)
    record = json.loads(result.stdout[result.stdout.rindex("\n{") + 1:])
    assert detail_table(record["rows"]) in result.stdout
    assert sweep_table(record["rows"], record["cases"], record["target"]) in result.stdout
    assert [case["name"] for case in record["cases"]] == ["X_C seed 7", "X_D seed 7"]
    refused = subprocess.run([sys.executable, str(SCRIPT), "--model", "coulomb", "--strengths", "0.5", "2",
                              "--strength", "1"], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert refused.returncode == 2 and "not one of the swept strengths" in refused.stderr
    assert "Traceback" not in refused.stderr


def test_existing_outputs_are_kept_without_force(tmp_path):
    existing = tmp_path / "v.md"
    existing.write_text("mine")
    with pytest.raises(GreyboxError, match="exists"):
        cutting_validation(DATA, AXIS_CONFIG, kinds=("coulomb",), strengths=(0.5,), strength=0.5,
                           markdown_path=existing)
    (tmp_path / "figures").mkdir()
    (tmp_path / "figures" / "mine.png").write_bytes(b"x")
    with pytest.raises(GreyboxError, match="not empty"):
        cutting_validation(DATA, AXIS_CONFIG, kinds=("coulomb",), strengths=(0.5,), strength=0.5,
                           plot_dir=tmp_path / "figures")
    assert existing.read_text() == "mine"


def test_a_detail_strength_outside_the_case_is_refused_before_any_prediction():
    from types import SimpleNamespace

    from studies.cutting import evaluate_model

    case = SimpleNamespace(strengths=(0.25, 0.5, 1.0))  # nothing else is read before the check
    with pytest.raises(ValueError, match=r"detail_strength 0.75 A is not one of the case's cut strengths \(0.25"):
        evaluate_model("gms", None, case, None, 0.75, 0.95, 60.0)
