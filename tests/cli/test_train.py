"""``greybox train`` on CSV, MCAP and EMPS logs: fit, report, save; refusals with clear messages."""

from __future__ import annotations

import numpy as np
import pytest

import greybox.cli as cli
from greybox.data.io import write_log
from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.models.files import load_model
from greybox.models.friction import CoulombModel
from greybox.models.friction.backlash import BacklashModel

#: The module's tests take long together (model fits, end-to-end runs): left out of the default run;
#: `pytest -m slow` runs them, as .ci/run does.
pytestmark = pytest.mark.slow

# Coulomb + viscous + offset truth: J [A s^2/mm], Fc [A], Fv [A s/mm], offset [A]
TRUTH = {"J_": 2e-3, "coulomb_pos_": 1.2, "viscous_pos_": 0.015, "offset_": -0.3}


@pytest.fixture(autouse=True)
def train_registered(monkeypatch):
    if "train" not in cli.COMMANDS:
        monkeypatch.setattr(cli, "COMMANDS", tuple(cli.COMMANDS) + ("train",))


def _run(seed: int, n: int = 1500, dt: float = 0.002, with_motion: bool = True) -> AxisLog:
    """A run whose current is exactly inertia + Coulomb + viscous + offset of its logged motion."""
    t = np.arange(n) * dt
    w1, w2 = 2 * np.pi * 0.6, 2 * np.pi * 1.9
    position = 30 * np.sin(w1 * t) + 3 * np.sin(w2 * t + seed)
    velocity = 30 * w1 * np.cos(w1 * t) + 3 * w2 * np.cos(w2 * t + seed)
    acceleration = -30 * w1**2 * np.sin(w1 * t) - 3 * w2**2 * np.sin(w2 * t + seed)
    current = (TRUTH["J_"] * acceleration + TRUTH["coulomb_pos_"] * np.sign(velocity)
               + TRUTH["viscous_pos_"] * velocity + TRUTH["offset_"])
    return AxisLog(time=t, position=position, effort=current, axis="X",
                   velocity=velocity if with_motion else None,
                   acceleration=acceleration if with_motion else None)


def _train(capsys, *args):
    status = cli.main(["train", *map(str, args)])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_csv_coulomb_recovers_the_truth_and_saves(tmp_path, capsys):
    log_path = tmp_path / "run.csv"
    write_log(_run(0), log_path)
    out = tmp_path / "coulomb.gbm"
    status, stdout, _ = _train(capsys, "--model", "coulomb", "--offset", "--train", log_path, "--out", out, "--quiet")
    assert status == 0
    model = load_model(out)
    for name, value in TRUTH.items():
        assert getattr(model, name) == pytest.approx(value, rel=1e-6)
    assert "RE %" in stdout and "RE = RMSE / mean |effort|" in stdout
    assert "J              = 0.002 A s^2/mm" in stdout
    assert f"wrote {out}" in stdout


def test_mcap_runs_train_a_gms_model_with_progress(tmp_path, capsys):
    paths = []
    for seed in (1, 2):
        paths.append(tmp_path / f"run{seed}.mcap")
        write_log(_run(seed, n=800), paths[-1])
    out = tmp_path / "gms.gbm"
    status, stdout, stderr = _train(capsys, "--model", "gms", "--elements", "2", "--train", *paths, "--out", out)
    assert status == 0, stderr
    assert "GMS" in stderr  # progress display
    assert "all runs" in stdout and "run1.mcap" in stdout and "run2.mcap" in stdout
    model = load_model(out)
    assert model.n_elements == 2 and model.k_.shape == (2,)


def test_same_seed_gives_identical_model_files(tmp_path, capsys):
    log_path = tmp_path / "run.mcap"
    write_log(_run(3, n=600), log_path)
    files = []
    for name in ("a.gbm", "b.gbm"):
        files.append(tmp_path / name)
        status, _, stderr = _train(capsys, "--model", "lugre", "--model-seed", "7", "--train", log_path,
                                   "--out", files[-1],
                                   "--quiet")
        assert status == 0 and stderr == ""
    assert files[0].read_bytes() == files[1].read_bytes()


def test_emps_file_gives_the_benchmark_mass(tmp_path, capsys, real_data):
    out = tmp_path / "emps.gbm"
    status, stdout, _ = _train(capsys, "--model", "coulomb", "--offset", "--cutoff-hz", "100",
                               "--train", real_data("EMPS") / "DATA_EMPS.mat", "--out", out, "--quiet")
    assert status == 0
    model = load_model(out)
    assert model.effort_unit_ == "N"
    assert 1e3 * model.J_ == pytest.approx(95.1089, rel=0.02)  # published IDIM-LS mass [kg]
    assert "N s^2/mm" in stdout


def _asymmetric_run(seed: int, n: int = 2000) -> AxisLog:
    """A run whose friction is 1.5 A in positive and 0.9 A in negative motion."""
    log = _run(seed, n=n)
    levels = np.where(log.velocity > 0, 1.5, np.where(log.velocity < 0, -0.9, 0.0))
    return log.replace(effort=TRUTH["J_"] * log.acceleration + levels + 0.01 * log.velocity)


@pytest.mark.parametrize("kind, suffix", [("stribeck", ".csv"), ("lugre", ".mcap"), ("gms", ".parquet"),
                                          ("gms", ".csv"), ("gmssvr", ".parquet")])
def test_asymmetric_models_train_from_the_log_formats(tmp_path, capsys, kind, suffix):
    log = _asymmetric_run(4)
    log_path = tmp_path / f"run{suffix}"
    write_log(log, log_path)
    out = tmp_path / f"{kind}.gbm"
    extra = ["--set", "optimize=false"] if kind == "gmssvr" else []
    status, stdout, stderr = _train(capsys, "--model", kind, "--asymmetric", *extra, "--train", log_path,
                                    "--out", out, "--quiet")
    assert status == 0, stderr
    model = load_model(out)
    physical = model.gms_ if kind == "gmssvr" else model
    assert physical.asymmetric
    predicted = physical.predict(prepare([log])[0])
    sliding = np.abs(log.velocity) > 20
    error = predicted[sliding] - log.effort[sliding]
    assert np.sqrt(np.mean(error ** 2)) < 0.1  # a symmetric model is 0.3 A off in each direction


def test_emps_file_trains_an_asymmetric_gms_model(tmp_path, capsys, real_data):
    out = tmp_path / "emps-gms.gbm"
    status, stdout, stderr = _train(capsys, "--model", "gms", "--asymmetric", "--cutoff-hz", "100",
                                    "--train", real_data("EMPS") / "DATA_EMPS.mat", "--out", out, "--quiet")
    assert status == 0, stderr
    model = load_model(out)
    assert model.asymmetric and model.effort_unit_ == "N"
    stiffness = float(np.sum(model.k_ * model.alpha_))
    positive, negative = stiffness * model.s_inf_, stiffness * model.s_inf_neg_
    assert 5.0 < positive < 60.0 and 5.0 < negative < 60.0  # sliding levels of tens of newtons
    assert "s_inf_neg" in stdout and "viscous_neg" in stdout


def test_backlash_wraps_the_model_and_identifies_its_width(tmp_path, capsys):
    log = _run(0, n=3000)
    truth = BacklashModel(base=CoulombModel(fit_offset=True), width=2.0).fit(prepare([log])[0])
    assert truth.base_.coulomb_pos_ == pytest.approx(TRUTH["coulomb_pos_"], rel=0.05)
    log = log.replace(effort=truth.predict(prepare([log])[0]))  # Coulomb friction behind 2 mm of backlash
    log_path = tmp_path / "run.parquet"
    write_log(log, log_path)
    out = tmp_path / "backlash.gbm"
    status, stdout, stderr = _train(capsys, "--model", "coulomb", "--offset", "--backlash", "--train", log_path,
                                    "--out", out)
    assert status == 0, stderr
    assert "backlash width" in stderr  # progress of the width search
    model = load_model(out)
    assert type(model).__name__ == "BacklashModel" and type(model.base_).__name__ == "CoulombModel"
    assert model.width_ == pytest.approx(2.0, rel=0.05) and "width" in stdout


def test_existing_model_is_kept_unless_forced(tmp_path, capsys):
    log_path = tmp_path / "run.csv"
    write_log(_run(0), log_path)
    out = tmp_path / "model.gbm"
    out.write_text("precious")
    status, _, stderr = _train(capsys, "--model", "coulomb", "--train", log_path, "--out", out)
    assert status == 2
    assert str(out) in stderr and "--force" in stderr and "Traceback" not in stderr
    assert out.read_text() == "precious"
    status, _, _ = _train(capsys, "--model", "coulomb", "--train", log_path, "--out", out, "--force", "--quiet")
    assert status == 0 and load_model(out).J_ > 0


def test_training_log_is_never_overwritten(tmp_path, capsys):
    log_path = tmp_path / "run.csv"
    write_log(_run(0), log_path)
    before = log_path.read_bytes()
    status, _, stderr = _train(capsys, "--model", "coulomb", "--train", log_path, "--out", log_path, "--force")
    assert status == 2 and "training logs" in stderr
    assert log_path.read_bytes() == before


@pytest.mark.parametrize(
    "arguments, message",
    [
        (["--model", "svr", "--asymmetric"], "--asymmetric does not apply to the svr model"),
        (["--model", "gms", "--asymmetric", "--offset"], "choose --asymmetric or --offset, not both"),
        (["--model", "coulomb", "--elements", "3"], "--elements does not apply to the coulomb model"),
        (["--model", "lugre", "--set", "colour=red"], "--set colour=...: the lugre model has no such hyperparameter"),
        (["--model", "lugre", "--set", "n_starts"], "NAME=VALUE"),
        (["--model", "gmssvr", "--set", "optimize=maybe"], "optimize must be True or False"),
        (["--model", "gmssvr", "--set", 'bounds={"C": [1, 0]}'], "must satisfy 0 < low < high < inf"),
        (["--model", "svr", "--set", "bounds=garbage"], "bounds must map hyperparameter names"),
        (["--model", "coulomb", "--set", "fit_offset=yes"], "must be True or False, got 'yes'"),
    ],
)
def test_options_foreign_to_the_model_are_refused(tmp_path, capsys, arguments, message):
    log_path = tmp_path / "run.csv"
    write_log(_run(0), log_path)
    status, _, stderr = _train(capsys, *arguments, "--train", log_path, "--out", tmp_path / "m.gbm")
    assert status == 2 and message in stderr
    assert not (tmp_path / "m.gbm").exists()


@pytest.mark.parametrize("spelling", ["False", "false", "FALSE"])
def test_set_takes_python_and_json_spellings_of_false(spelling):
    from greybox.cli._build import parse_setting

    assert parse_setting(spelling) is False and parse_setting("None") is None and parse_setting("2.5") == 2.5


def test_bad_logs_are_named(tmp_path, capsys):
    missing = tmp_path / "missing.csv"
    status, _, stderr = _train(capsys, "--model", "coulomb", "--train", missing, "--out", tmp_path / "m.gbm")
    assert status == 2 and "missing.csv" in stderr and "Traceback" not in stderr
    standing = _run(0, with_motion=False)
    standing = standing.replace(position=np.full(len(standing), 5.0))
    write_log(standing, tmp_path / "standing.csv")
    status, _, stderr = _train(capsys, "--model", "coulomb", "--train", tmp_path / "standing.csv",
                               "--out", tmp_path / "m.gbm")
    assert status == 2 and "standing.csv" in stderr
    assert not (tmp_path / "m.gbm").exists()


def test_gmssvr_stages_take_their_own_logs(tmp_path, capsys):
    first, second = tmp_path / "stage1.mcap", tmp_path / "stage2.csv"
    write_log(_run(4, n=600), first)
    write_log(_run(5, n=600), second)
    out = tmp_path / "gmssvr.gbm"
    fixed = ["--set", "C=1.0", "--set", "epsilon=0.01", "--set", "gamma=0.5", "--set", "n_subset=300"]
    status, stdout, stderr = _train(capsys, "--model", "gmssvr", "--train", first, "--stage2", second,
                                    *fixed, "--out", out, "--quiet")
    assert status == 0, stderr
    assert "stage1.mcap" in stdout and "stage2.csv" in stdout
    assert "gms.k" in stdout  # the frozen GMS stage is listed with its parameters
    model = load_model(out)
    assert model.gms_.n_samples_fit_ == 600  # GMS stage fitted on --train alone
    assert (model.C_, model.epsilon_, model.gamma_, model.n_subset) == (1.0, 0.01, 0.5, 300)
    status, _, stderr = _train(capsys, "--model", "gms", "--train", first, "--stage2", second,
                               "--out", tmp_path / "x.gbm")
    assert status == 2 and "--stage2 does not apply to the gms model" in stderr


def test_parameter_lines_align_their_equals_signs_whatever_the_longest_name():
    from svr_runs import FIXED, sweep_run

    from greybox.cli._model_text import parameter_lines
    from greybox.models.svr import SVRCurrentModel

    lines = parameter_lines(SVRCurrentModel(**FIXED, velocity_weight=4.0).fit(sweep_run(1, n=1500)))
    assert any(line.startswith("  velocity_weight = 4 ") or line == "  velocity_weight = 4" for line in lines)
    assert len({line.index(" = ") for line in lines}) == 1, lines
