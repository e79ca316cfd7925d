"""``greybox train --model auto`` and the inertia options, from the command line on CSV, MCAP and MAT logs."""

from __future__ import annotations

import json

import numpy as np
import pytest
from friction_signals import motion_log, velocity_profile
from scipy.io import savemat

import greybox.cli as cli
from greybox.data.io import write_log
from greybox.models.files import load_model


def _log(seed: int, duration: float = 5.0):
    """A run of Coulomb + viscous friction and inertia, with a little noise."""
    velocity = velocity_profile(duration, seed=seed, v_max=60.0)
    log = motion_log(velocity)
    noise = 0.01 * np.random.default_rng(seed).standard_normal(len(velocity))
    return log.replace(effort=0.002 * log.acceleration + 0.9 * np.sign(velocity) + 0.01 * velocity + noise,
                       velocity=None, acceleration=None)


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("auto")
    paths = [folder / "a.csv", folder / "b.mcap", folder / "c.mat"]
    for seed, path in enumerate(paths[:2]):
        write_log(_log(seed), path)
    log = _log(2)  # MATLAB files are read, not written, by greybox
    savemat(paths[2], {"time_s": log.time, "position_mm": log.position, "current_A": log.effort})
    return paths


def _main(capsys, *args):
    status = cli.main([str(arg) for arg in args])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_auto_chooses_by_held_out_logs_prints_and_keeps_the_table(logs, tmp_path, capsys):
    out = tmp_path / "auto.gbm"
    status, stdout, stderr = _main(capsys, "train", "--model", "auto", "--candidates", "coulomb", "stribeck:offset",
                                   "--train", *logs, "--out", out, "--workers", "1", "--quiet")
    assert status == 0, stderr
    assert "model choice: 2 candidates, held out in turn: " in stdout
    for path in logs:
        assert str(path) in stdout
    assert "<- chosen" in stdout and "rule: lowest mean held-out RE" in stdout
    model = load_model(out)
    assert model.selection_["chosen"] in ("coulomb", "stribeck:offset")
    assert f"trained {model.selection_['chosen']} (chosen by held-out runs)" in stdout
    assert len(model.selection_["candidates"][0]["fold_re"]) == 3
    assert "95 % intervals by sandwich" in stdout and model.parameter_intervals_  # the chosen model's intervals
    status, stdout, _ = _main(capsys, "info", out)
    assert status == 0 and "model choice: 2 candidates" in stdout and "<- chosen" in stdout
    status, stdout, _ = _main(capsys, "info", "--json", out)
    summary = json.loads(stdout)
    summary = summary[0] if isinstance(summary, list) else summary
    assert summary["selection"]["chosen"] == model.selection_["chosen"]


def test_load_side_fits_no_inertia(logs, tmp_path, capsys):
    out = tmp_path / "load.gbm"
    status, stdout, stderr = _main(capsys, "train", "--model", "coulomb", "--load-side", "--train", logs[0],
                                   "--out", out, "--quiet")
    assert status == 0, stderr
    assert load_model(out).J_ == 0.0 and "load.gbm" in stdout
    status, _, _ = _main(capsys, "train", "--model", "coulomb", "--train", logs[0], "--out", tmp_path / "free.gbm",
                         "--quiet")
    assert status == 0 and load_model(tmp_path / "free.gbm").J_ > 0.0
    status, _, _ = _main(capsys, "train", "--model", "coulomb", "--inertia", "0.002", "--train", logs[0],
                         "--out", tmp_path / "known.gbm", "--quiet")
    assert status == 0 and load_model(tmp_path / "known.gbm").J_ == 0.002


@pytest.mark.parametrize("args, message", [
    (["--model", "auto", "--asymmetric"], "--asymmetric does not apply with --model auto"),
    (["--model", "auto", "--candidates", "gms:wobble"], "candidate 'gms:wobble': unknown option"),
    (["--model", "auto", "--candidates", "nosuch"], "unknown model kind 'nosuch'"),
    (["--model", "coulomb", "--candidates", "gms"], "--candidates applies with --model auto"),
])
def test_refusals_are_one_line_with_status_2(logs, tmp_path, capsys, args, message):
    status, stdout, stderr = _main(capsys, "train", *args, "--train", *logs, "--out", tmp_path / "x.gbm", "--quiet")
    assert status == 2
    assert message in stderr and "Traceback" not in stderr
    assert len(stderr.strip().splitlines()) == 1
    assert not (tmp_path / "x.gbm").exists()


def test_inertia_and_load_side_exclude_each_other(logs, tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_:
        cli.main(["train", "--model", "coulomb", "--inertia", "1", "--load-side", "--train", str(logs[0]),
                  "--out", str(tmp_path / "x.gbm")])
    assert exit_.value.code == 2
    assert "not allowed with argument" in capsys.readouterr().err
