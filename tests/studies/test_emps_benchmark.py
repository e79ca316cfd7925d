"""The EMPS benchmark protocol reproduces the published IDIM-LS results on the real data.

Reference figures are the published ones (Janot, Gautier & Brunot 2019, "Data
Set and Reference Models of EMPS"), typed in here independently of the protocol.
Our preprocessing uses scipy's filters, whose edge handling differs slightly
from MATLAB's, hence the tolerances: 2 % on parameters, 0.2 percentage points
on relerr.
"""

from __future__ import annotations

import functools
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from greybox.errors import GreyboxError
from greybox.models.friction import CoulombModel
from greybox.train.candidates import choose_model
from studies import auto
from studies import emps as bench

#: A validation study's tests (runs of the study, its script, the real data sets): left out of the default
#: run (`pytest -m slow` runs them, as .ci/run does).
pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[2]
SCRIPT = REPO / "scripts" / "emps_benchmark.py"

SYMMETRIC = {"M_kg": 95.1089, "Fv_N_s_per_m": 203.5034, "Fc_N": 20.3935, "offset_N": -3.1648}
ASYMMETRIC = {"M_kg": 95.1540, "Fv_pos_N_s_per_m": 166.7061, "Fc_pos_N": 20.1440,
              "Fv_neg_N_s_per_m": 240.4236, "Fc_neg_N": 20.6277}
TRAIN_RELERR, TEST_RELERR, ASYM_TRAIN_RELERR = 4.0834, 5.9824, 3.1117
CONDITION_NUMBER = 25.9883


@pytest.fixture(scope="module")
def emps(real_data):
    """The folder of the EMPS benchmark files (skips without it)."""
    return real_data("EMPS")


@pytest.fixture(scope="module")
def logs(emps):
    return {role: bench.benchmark_log(emps / name) for role, name in
            (("train", "DATA_EMPS.mat"), ("test", "DATA_EMPS_PULSES.mat"))}


def test_idim_ls_reproduces_the_published_estimates(logs):
    fit = bench.idim_ls(logs["train"])
    for name, published in SYMMETRIC.items():
        assert fit["params"][name] == pytest.approx(published, rel=0.02), name
    assert fit["train_relerr"] == pytest.approx(TRAIN_RELERR, abs=0.2)
    assert fit["condition_number"] == pytest.approx(CONDITION_NUMBER, rel=0.01)
    test_relerr = bench.benchmark_relerr(logs["test"], fit["predict"](logs["test"]))
    assert test_relerr == pytest.approx(TEST_RELERR, abs=0.2)


def test_asymmetric_idim_ls_reproduces_the_published_estimates(logs):
    fit = bench.idim_ls(logs["train"], asymmetric=True)
    for name, published in ASYMMETRIC.items():
        assert fit["params"][name] == pytest.approx(published, rel=0.02), name
    assert fit["train_relerr"] == pytest.approx(ASYM_TRAIN_RELERR, abs=0.2)


def test_scoring_a_full_rate_prediction_equals_the_decimated_least_squares_residual(logs):
    # decimation is linear: decimating X @ theta equals the decimated columns times theta
    fit = bench.idim_ls(logs["train"])
    scored = bench.benchmark_relerr(logs["train"], fit["predict"](logs["train"]))
    assert scored == pytest.approx(fit["train_relerr"], rel=1e-9)
    assert bench.benchmark_relerr(logs["train"], logs["train"].effort) == 0.0


def test_greybox_coulomb_model_matches_the_published_estimates(logs):
    model = CoulombModel(fit_offset=True).fit(logs["train"])
    ours = {"M_kg": 1e3 * model.J_, "Fv_N_s_per_m": 1e3 * model.viscous_pos_, "Fc_N": model.coulomb_pos_,
            "offset_N": model.offset_}
    for name, published in SYMMETRIC.items():
        assert ours[name] == pytest.approx(published, rel=0.02), name
    assert bench.benchmark_relerr(logs["test"], model.predict(logs["test"])) == pytest.approx(TEST_RELERR, abs=0.2)


def test_benchmark_samples_and_the_2ms_grid(logs, emps):
    full = logs["train"]
    assert len(full) == 24841 - 49
    assert bench.decimate_benchmark(full.effort).size == 2480
    coarse = bench.benchmark_log(emps / "DATA_EMPS.mat", step_ms=2)
    assert coarse.sample_time == pytest.approx(0.002, rel=1e-4)
    assert coarse.time[0] == full.time[0]
    assert np.isin(coarse.time, full.time).all()


def test_every_friction_model_runs_symmetric_and_asymmetric():
    for name in ("stribeck", "lugre", "gms"):
        assert name in bench.MODEL_NAMES and f"{name}_asym" in bench.MODEL_NAMES
        symmetric, step, _ = bench.GREYBOX_MODELS[name]
        factory, asym_step, description = bench.GREYBOX_MODELS[f"{name}_asym"]
        assert symmetric(7).fit_offset and not symmetric(7).asymmetric
        model = factory(7)  # an asymmetric model takes no offset (it would not be identifiable)
        assert model.asymmetric and not model.fit_offset
        assert asym_step == step == 1 and "asymmetric" in description
        if name != "stribeck":
            assert model.random_state == 7  # --model-seed reaches the multi-start identification


def test_script_writes_json_markdown_and_plot(tmp_path, emps):
    out, md, png = tmp_path / "emps.json", tmp_path / "emps.md", tmp_path / "emps.png"
    result = subprocess.run(
        [sys.executable, str(SCRIPT), "--data", str(emps), "--json", str(out), "--markdown", str(md),
         "--plot", str(png), "--models", "coulomb_idim_ls", "coulomb", "stribeck", "stribeck_asym", "--quiet"],
        capture_output=True, text=True, cwd=tmp_path, timeout=300,
    )
    assert result.returncode == 0, result.stderr
    models = json.loads(out.read_text())["models"]
    assert list(models) == ["coulomb_idim_ls", "coulomb", "stribeck", "stribeck_asym"]
    for entry in models.values():
        assert 0 < entry["train_relerr"] < 10 and 0 < entry["test_relerr"] < 10
        assert entry["params"]
    assert models["coulomb_idim_ls"]["params"]["M_kg"] == pytest.approx(SYMMETRIC["M_kg"], rel=0.02)
    # the greybox models' parameters are their parameter tables: every value with its unit
    assert set(models["stribeck"]["units"]) == set(models["stribeck"]["params"])
    assert models["stribeck"]["units"]["v_s"] == "mm/s" and models["coulomb"]["units"]["offset"] == "N"
    # the asymmetric model: a sliding curve and a viscous coefficient per direction, no offset
    asym = models["stribeck_asym"]
    assert asym["units"]["viscous_neg"] == "N s/mm" and "v_s_neg" in asym["params"] and asym["params"]["offset"] == 0.0
    assert asym["n_params"] > models["stribeck"]["n_params"]
    assert "| `stribeck` |" in md.read_text() and "| `stribeck_asym` | asymmetric" in md.read_text()
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary files left


def test_record_prints_the_results_as_json_last_and_writes_nothing(tmp_path, emps):
    result = subprocess.run([sys.executable, str(SCRIPT), "--record", "--quiet", "--data", str(emps), "--models",
                             "coulomb_idim_ls", "coulomb"], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert result.returncode == 0, result.stderr
    printed = json.loads(result.stdout)  # the whole output is one JSON object: the record's figures
    assert list(printed["models"]) == ["coulomb_idim_ls", "coulomb"]
    assert printed["models"]["coulomb_idim_ls"]["train_relerr"] == pytest.approx(TRAIN_RELERR, abs=0.2)
    assert printed["published"]["coulomb_idim_ls"]["test_relerr"] == TEST_RELERR
    assert list(tmp_path.iterdir()) == []


def test_record_refuses_the_file_options(tmp_path):
    result = subprocess.run([sys.executable, str(SCRIPT), "--record", "--markdown", str(tmp_path / "emps.md")],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 2 and "--record writes no file" in result.stderr
    assert result.stdout == "" and not (tmp_path / "emps.md").exists()

def test_missing_data_folder_is_reported(tmp_path):
    with pytest.raises(GreyboxError, match="nowhere"):
        bench.emps_benchmark(tmp_path / "nowhere", tmp_path / "x.json")
    result = subprocess.run([sys.executable, str(SCRIPT), "--json", str(tmp_path / "x.json"),
                             "--data", str(tmp_path / "nowhere")], capture_output=True, text=True, timeout=300)
    assert result.returncode == 2
    assert "nowhere" in result.stderr and "Traceback" not in result.stderr
    assert not (tmp_path / "x.json").exists()


def test_an_unknown_model_name_is_refused_before_any_file_is_read(tmp_path):
    with pytest.raises(GreyboxError, match="unknown model.*stribek.*known: "):
        bench.run_benchmark(tmp_path / "nowhere", names=["coulomb", "stribek"])


def test_outputs_never_replace_the_data_nor_an_existing_file_without_force(tmp_path):
    data = tmp_path / "EMPS"
    data.mkdir()
    for name in (bench.TRAIN_FILE, bench.TEST_FILE):
        (data / name).write_bytes(b"not the real data")  # never read: the refusal comes first
    with pytest.raises(GreyboxError, match="EMPS data files"):
        bench.emps_benchmark(data, data / bench.TRAIN_FILE, force=True)
    existing = tmp_path / "emps.json"
    existing.write_text("{}")
    with pytest.raises(GreyboxError, match="exists"):
        bench.emps_benchmark(data, existing)
    assert (data / bench.TRAIN_FILE).read_bytes() == b"not the real data" and existing.read_text() == "{}"


def test_the_script_finds_the_data_through_greybox_real_data(tmp_path):
    env = {**os.environ, "GREYBOX_REAL_DATA": str(tmp_path / "elsewhere")}
    result = subprocess.run([sys.executable, str(SCRIPT), "--json", str(tmp_path / "x.json")], env=env,
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 2 and str(tmp_path / "elsewhere" / "EMPS") in result.stderr


def test_auto_runs_the_choice_on_three_stretches_of_the_training_file(emps, monkeypatch):
    candidates = ["coulomb:offset", "coulomb:asymmetric"]
    monkeypatch.setattr(auto, "choose_model", functools.partial(choose_model, candidates=candidates))
    results, _ = bench.run_benchmark(emps, ["auto"])
    entry = results["models"]["auto"]
    assert entry["selection"]["chosen"] in candidates
    assert [fold.split(": ")[-1] for fold in entry["selection"]["folds"]] == [
        "stretch 1 of 3", "stretch 2 of 3", "stretch 3 of 3"]
    assert 0 < entry["test_relerr"] < 100 and entry["n_params"] in (4, 5)
    assert f": {entry['selection']['chosen']} |" in bench.markdown_table(results)
