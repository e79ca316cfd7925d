"""``greybox discover`` on log files: JSON, report, model file, refusals."""

from __future__ import annotations

import argparse
import json
import re
import time

import numpy as np
import pytest

from greybox.cli import build_parser
from greybox.cli import discover as discover_cli
from greybox.data.io import write_log
from greybox.errors import GreyboxError
from greybox.models import registry
from greybox.models.augmented import AugmentedModel
from greybox.models.files import load_model
from studies.discovery import StudyCase, case_logs


def run_cli(argv):
    parser = argparse.ArgumentParser(prog="greybox")
    discover_cli.add_parser(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["discover", *argv])
    return args.run(args)


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    directory = tmp_path_factory.mktemp("logs")
    train, test, _ = case_logs(StudyCase("position_periodic_friction", 1.5, 3, "coulomb", 15.0))
    paths = []
    for name, log in (("train.csv", train), ("test.csv", test)):
        raw = log.replace(acceleration=None, extras={}, attrs={})  # as logged: position, velocity, current
        write_log(raw, directory / name)
        paths.append(str(directory / name))
    return paths


@pytest.mark.slow  # a discovery run, > 5 s
def test_discover_writes_findings_report_and_model(logs, tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(registry.MODEL_CLASSES, "augmented", AugmentedModel)
    out, model = tmp_path / "found.json", tmp_path / "model.gbm"
    status = run_cli(["--model", "coulomb", "--train", logs[0], "--test", logs[1], "--json", str(out),
                      "--out", str(tmp_path / "report"), "--save-model", str(model), "--quiet",
                      "--max-effects", "1"])
    assert status == 0
    document = json.loads(out.read_text())
    assert document["verdict"] == "named"
    assert document["effects"][0]["name"] == "position_periodic_friction"
    assert document["logs"] == {"train": [logs[0]], "test": [logs[1]]}
    assert document["test_rmse_after"] < document["test_rmse_before"]
    for name in ("discovery.json", "residual_train.png", "residual_test.png", "evidence.png"):
        assert (tmp_path / "report" / name).stat().st_size > 0
    loaded = load_model(model)
    assert type(loaded) is AugmentedModel and loaded.effects_[0]["name"] == "position_periodic_friction"
    printed = capsys.readouterr().out
    assert "verdict: named" in printed and "position_periodic_friction" in printed


def test_outputs_never_overwrite_inputs_or_models(logs, tmp_path):
    with pytest.raises(GreyboxError, match="one of the input logs"):
        run_cli(["--model", "coulomb", "--train", logs[0], "--test", logs[1], "--json", logs[1], "--quiet"])
    findings = tmp_path / "findings.json"
    findings.write_text("keep")
    with pytest.raises(GreyboxError, match="use --force"):
        run_cli(["--model", "coulomb", "--train", logs[0], "--test", logs[1], "--json", str(findings), "--quiet"])
    assert findings.read_text() == "keep"
    existing = tmp_path / "model.gbm"
    existing.write_bytes(b"keep")
    with pytest.raises(GreyboxError, match="file exists"):
        run_cli(["--model", "coulomb", "--train", logs[0], "--test", logs[1], "--json", str(tmp_path / "a.json"),
                 "--save-model", str(existing), "--quiet"])
    assert existing.read_bytes() == b"keep"


def test_bad_options_are_refused(logs, tmp_path):
    out = str(tmp_path / "a.json")
    with pytest.raises(GreyboxError, match="unknown effect"):
        run_cli(["--model", "coulomb", "--train", logs[0], "--test", logs[1], "--json", out, "--effects", "gravity"])
    with pytest.raises(GreyboxError, match="does not apply"):
        run_cli(["--model", "stribeck", "--train", logs[0], "--test", logs[1], "--json", out, "--elements", "3"])
    with pytest.raises(SystemExit):
        run_cli(["--model", "augmented", "--train", logs[0], "--test", logs[1], "--json", out])


def test_a_null_too_small_for_alpha_is_refused_before_any_work(logs, tmp_path):
    with pytest.raises(GreyboxError, match="--null-replicates 19 or more"):
        run_cli(["--model", "coulomb", "--train", "missing.csv", "--test", "missing.csv", "--json",
                 str(tmp_path / "a.json"), "--null-replicates", "9"])


@pytest.mark.slow  # a discovery run, > 5 s
def test_effects_option_restricts_the_library(logs, tmp_path):
    out = tmp_path / "a.json"
    run_cli(["--model", "coulomb", "--train", logs[0], "--test", logs[1], "--json", str(out), "--quiet",
             "--effects", "constant_offset", "thermal_drift"])
    document = json.loads(out.read_text())
    assert document["settings"]["candidates"] == ["constant_offset", "thermal_drift"]
    assert all(entry["name"] in ("constant_offset", "thermal_drift") for entry in document["effects"])
    assert np.isfinite(document["test_rmse_before"])


@pytest.mark.slow  # a discovery run, > 5 s
def test_an_asymmetric_base_is_discovered_on(logs, tmp_path):
    model_path = tmp_path / "model.gbm"
    status = run_cli(["--model", "stribeck", "--asymmetric", "--train", logs[0], "--test", logs[1],
                      "--json", str(tmp_path / "found.json"), "--save-model", str(model_path), "--quiet",
                      "--max-effects", "1"])
    assert status == 0
    loaded = load_model(model_path)
    assert loaded.base_.asymmetric and loaded.base_.coulomb_neg_ > 0.0
    names = [row.name for row in loaded.parameter_table()]
    assert "base.coulomb_neg" in names and "base.v_s_neg" in names


def test_held_out_options_are_checked(logs, tmp_path):
    out = str(tmp_path / "a.json")
    with pytest.raises(GreyboxError, match="--held-out-blocks must be at least 2"):
        run_cli(["--model", "coulomb", "--train", logs[0], "--test", logs[1], "--json", out, "--held-out-blocks", "1"])
    with pytest.raises(SystemExit):  # argparse: a fraction in [0, 1) only
        run_cli(["--model", "coulomb", "--train", logs[0], "--test", logs[1], "--json", out, "--min-gain", "1.5"])


def test_base_misfit_is_reported_and_its_curve_saved(tmp_path, capsys):
    # a Stribeck excess hidden on a Coulomb plant: the Coulomb base's own law misfits
    directory = tmp_path / "logs"
    directory.mkdir()
    train, test, _ = case_logs(StudyCase("stribeck", 1.5, 2, "coulomb", 15.0))
    paths = []
    for name, log in (("train.csv", train), ("test.csv", test)):
        write_log(log.replace(acceleration=None, extras={}, attrs={}), directory / name)
        paths.append(str(directory / name))
    out, model = tmp_path / "found.json", tmp_path / "model.gbm"
    assert run_cli(["--model", "coulomb", "--train", paths[0], "--test", paths[1], "--json", str(out),
                    "--save-model", str(model), "--quiet"]) == 0
    document = json.loads(out.read_text())
    assert document["verdict"] == "base_misfit" and document["effects"] == []
    curve = document["base_misfit"]["refinements"]["velocity_curve"]
    assert document["base_misfit"]["detected"] and curve["kept"] and curve["held_out"]["passes"]
    assert curve["parameters"]["excess_at_rest_A"] > 0.0
    assert document["test_rmse_after"] < document["test_rmse_before"]
    assert load_model(model).effects_[0]["name"] == "velocity_curve"
    assert "base misfit: velocity_curve (friction along the speed" in capsys.readouterr().out
    # without the refinement the same excess is a named Stribeck effect
    assert run_cli(["--model", "coulomb", "--train", paths[0], "--test", paths[1], "--json", str(out), "--force",
                    "--quiet", "--no-refine-base", "--max-effects", "1"]) == 0
    document = json.loads(out.read_text())
    assert [entry["name"] for entry in document["effects"]] == ["stribeck"]
    assert document["base_misfit"] is None and document["settings"]["refine_base"] is False


@pytest.mark.slow  # a discovery run takes about half a minute
def test_the_printed_wall_time_counts_from_the_start_of_the_process(tmp_path, capsys):
    train, test, _ = case_logs(StudyCase("position_periodic_friction", 1.5, 3, "coulomb", 15.0))
    paths = []
    for name, log in (("train.csv", train), ("test.csv", test)):
        write_log(log.replace(acceleration=None, extras={}, attrs={}), tmp_path / name)
        paths.append(str(tmp_path / name))
    args = build_parser().parse_args(["discover", "--model", "coulomb", "--train", paths[0], "--test", paths[1],
                                      "--json", str(tmp_path / "found.json"), "--quiet", "--max-effects", "1"])
    args.started_s = time.perf_counter() - 100.0  # as main sets it: the process started 100 s ago
    args.startup_counted = True
    assert args.run(args) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    match = re.fullmatch(r"done in (\d+\.\d) s wall, start-up included", last)
    assert match and float(match.group(1)) >= 100.0
