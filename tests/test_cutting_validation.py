"""The cutting validation script, run small: its tables, figures and the strength sweep hold together."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]
SCRIPT = REPO / "scripts" / "cutting_validation.py"


def _load_script():
    spec = importlib.util.spec_from_file_location("cutting_validation", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("validation")
    script = _load_script()
    status = script.main(["--models", "coulomb,stribeck", "--strengths", "0.5,2", "--strength", "0.5",
                          "--json", str(out / "v.json"), "--markdown", str(out / "v.md"),
                          "--plot-dir", str(out / "figures")])
    return status, out, json.loads((out / "v.json").read_text())


def test_script_writes_every_output(run):
    status, out, result = run
    assert status == 0
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
            assert (item["correlation"] >= row["target"]) == (item["strength_A"] >= needed)
        if np.isfinite(needed):
            assert row["mean_cut_force_for_target_N"] == pytest.approx(
                abs(weak["mean_cut_force_true_N"]) * needed / 0.5, rel=1e-9)


def test_strength_of_the_table_must_be_swept():
    script = _load_script()
    with pytest.raises(SystemExit):
        script.main(["--models", "coulomb", "--strengths", "0.5,2", "--strength", "1"])
