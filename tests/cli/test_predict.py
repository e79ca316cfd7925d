"""``greybox predict`` on CSV, Parquet and MCAP outputs; refusals with clear messages."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import greybox.cli as cli
from greybox.data.io import read_log, write_log
from greybox.data.prepare import prepare
from greybox.models.files import save_model
from greybox.models.friction import GMSModel
from greybox.twin import make_dataset

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "axis_x.toml"
FORCE_PER_AMP = 1.35 * 2 * math.pi * 0.9 / 0.010  # examples/axis_x.toml, driving [N/A]
FORCE_PER_AMP_BACKDRIVEN = 1.35 * 2 * math.pi / 0.85 / 0.010  # the same file, back-driven [N/A]


@pytest.fixture(autouse=True)
def predict_registered(monkeypatch):
    if "predict" not in cli.COMMANDS:
        monkeypatch.setattr(cli, "COMMANDS", tuple(cli.COMMANDS) + ("predict",))


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A GMS model file trained on a short air cut, and a cutting log on another trajectory (MCAP)."""
    root = tmp_path_factory.mktemp("predict")
    train = prepare([make_dataset("X", "A", seed=11, duration_s=10)])[0]
    model = GMSModel(n_starts=1, max_iter=80).fit(train)
    model_path = root / "x.gbm"
    save_model(model, model_path)
    cut = make_dataset("X", "C", seed=12, duration_s=8, cutting=True)
    log_path = root / "cut.mcap"
    write_log(cut, log_path)
    return {"root": root, "model": model, "model_path": model_path, "log_path": log_path}


def _predict(capsys, *args):
    status = cli.main(["predict", *map(str, args)])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def _expected(files):
    log = prepare([read_log(files["log_path"])])[0]
    return log, files["model"].predict(log)


def _n_chunks(files, chunk_s: float) -> int:
    """Chunks of ``chunk_s`` seconds that cover the cutting log, the last one shorter.

    From the log's length, not a literal: how long the twin's motion for ``duration_s=8`` runs is up to
    its trajectory generator (about 7.3 s since the recalibration: few dwells, 0.1 s of rest at the end
    instead of 0.5 s; it was over 7.8 s).
    """
    log = prepare([read_log(files["log_path"])])[0]
    step_samples = round(chunk_s / log.sample_time)
    assert len(log) % step_samples != 1  # no stub of one sample, which predict merges into the chunk before
    n = math.ceil(len(log) / step_samples)
    assert n >= 3  # the state is carried across at least two chunk boundaries
    return n


def _read_table(path: Path) -> pd.DataFrame:
    if path.suffix == ".csv":
        return pd.read_csv(path)
    if path.suffix == ".parquet":
        return pd.read_parquet(path)
    log = read_log(path, columns={"current_A": "current_measured_A"})
    return pd.DataFrame({"time_s": log.time, "current_measured_A": log.current, **log.extras,
                         "position_mm": log.position, "velocity_mm_s": log.velocity})


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mcap"])
def test_outputs_hold_measured_model_process_and_force(files, tmp_path, capsys, suffix):
    out = tmp_path / f"out{suffix}"
    status, stdout, stderr = _predict(capsys, files["model_path"], files["log_path"], "--out", out,
                                      "--axis-config", EXAMPLE, "--chunk-s", "1.3")
    assert status == 0, stderr
    assert f"wrote {out}" in stdout and "763.407 N/A driving, 997.918 N/A back-driven" in stdout
    assert f"{_n_chunks(files, 1.3)} chunk(s) of 1.3 s" in stdout
    table = _read_table(out)
    for name in ("time_s", "current_measured_A", "current_model_A", "current_process_A", "force_process_N"):
        assert name in table.columns
    if suffix != ".mcap":
        assert list(table.columns)[:5] == ["time_s", "current_measured_A", "current_model_A", "current_process_A",
                                           "force_process_N"]
    log, model_current = _expected(files)
    np.testing.assert_allclose(table["time_s"], log.time, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(table["current_measured_A"], log.current)
    np.testing.assert_allclose(table["current_model_A"], model_current, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(table["current_process_A"], table["current_measured_A"] - table["current_model_A"])
    back = table["current_process_A"] * table["velocity_mm_s"] < 0
    factor = np.where(back, FORCE_PER_AMP_BACKDRIVEN, FORCE_PER_AMP)
    np.testing.assert_allclose(table["force_process_N"], factor * table["current_process_A"], rtol=1e-12)


def test_mcap_output_is_one_topic_with_one_message_per_sample(files, tmp_path, capsys):
    from mcap.reader import make_reader

    out = tmp_path / "out.mcap"
    assert _predict(capsys, files["model_path"], files["log_path"], "--out", out)[0] == 0
    with open(out, "rb") as stream:
        reader = make_reader(stream)
        messages = list(reader.iter_messages())
    topics = {channel.topic for _, channel, _ in messages}
    assert topics == {"/process/X"}
    schema = messages[0][0]
    assert schema.name == "greybox.ProcessSample" and schema.encoding == "jsonschema"
    first = json.loads(messages[1][2].data)
    assert set(first) == {"current_measured_A", "current_model_A", "current_process_A", "position_mm",
                          "velocity_mm_s", "outside_training"}
    assert len(messages) == len(_expected(files)[0])


def test_without_axis_metadata_there_is_no_force(files, tmp_path, capsys):
    out = tmp_path / "out.csv"
    status, stdout, _ = _predict(capsys, files["model_path"], files["log_path"], "--out", out)
    assert status == 0 and "force" not in stdout.split("\n", 1)[1].split("wrote")[0]
    assert "force_process_N" not in pd.read_csv(out).columns


def test_plot_is_written(files, tmp_path, capsys):
    out, picture = tmp_path / "out.parquet", tmp_path / "process.png"
    status, stdout, _ = _predict(capsys, files["model_path"], files["log_path"], "--out", out,
                                 "--axis-config", EXAMPLE, "--plot", picture)
    assert status == 0 and f"wrote {picture}" in stdout
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_existing_output_is_not_overwritten_without_force(files, tmp_path, capsys):
    out = tmp_path / "out.csv"
    out.write_text("keep me\n")
    status, _, stderr = _predict(capsys, files["model_path"], files["log_path"], "--out", out)
    assert status == 2 and f"{out}: file exists; use --force" in stderr
    assert out.read_text() == "keep me\n"
    picture = tmp_path / "p.png"
    picture.write_text("old picture")
    status, _, stderr = _predict(capsys, files["model_path"], files["log_path"], "--out", tmp_path / "new.csv",
                                 "--plot", picture)
    assert status == 2 and "file exists" in stderr and not (tmp_path / "new.csv").exists()
    assert picture.read_text() == "old picture"
    status, _, _ = _predict(capsys, files["model_path"], files["log_path"], "--out", out, "--force")
    assert status == 0 and "current_process_A" in out.read_text()


def test_inputs_are_never_overwritten(files, tmp_path, capsys):
    log_copy = tmp_path / "cut.csv"
    write_log(read_log(files["log_path"]), log_copy)
    before = log_copy.read_bytes()
    status, _, stderr = _predict(capsys, files["model_path"], log_copy, "--out", log_copy, "--force")
    assert status == 2 and "is an input of this command" in stderr
    assert log_copy.read_bytes() == before


def test_bad_axis_config_is_a_one_line_error(files, tmp_path, capsys):
    bad = tmp_path / "axis.toml"
    bad.write_text("torque_constant_Nm_per_A = 1.2\nscrew_lead_m = 0.01\ngear_ratio = 1\nefficiency = 0.9\n")
    out = tmp_path / "out.csv"
    status, _, stderr = _predict(capsys, files["model_path"], files["log_path"], "--out", out, "--axis-config", bad)
    assert status == 2 and not out.exists()
    assert stderr.startswith(f"greybox predict: error: {bad}: 'screw_lead_m'") and "Traceback" not in stderr


def test_channel_names_from_the_axis_config(files, tmp_path, capsys):
    """A CNC export with its own headers, mapped in the TOML's [channels] table."""
    log = read_log(files["log_path"])
    export = pd.DataFrame({"Zeit_s": log.time, "X1 Lageistwert": log.position, "X1 Strom": log.current})
    csv = tmp_path / "export.csv"
    export.to_csv(csv, index=False)
    config = tmp_path / "axis.toml"
    config.write_text(EXAMPLE.read_text() + '\n[channels]\ntime_s = "Zeit_s"\nposition_mm = "X1 Lageistwert"\n'
                      'current_A = "X1 Strom"\n')
    out = tmp_path / "out.csv"
    status, _, stderr = _predict(capsys, files["model_path"], csv, "--out", out, "--axis-config", config)
    assert status == 0, stderr
    table = pd.read_csv(out)
    np.testing.assert_array_equal(table["current_measured_A"], log.current)


@pytest.mark.parametrize("args, message", [
    (["--out", "{tmp}/out.txt"], "unknown output extension '.txt'"),
    (["--out", "{tmp}/out.csv", "--plot", "{tmp}/p.gif"], "unknown picture extension"),
    (["--out", "{tmp}/missing/out.csv"], "does not exist"),
])
def test_bad_output_paths(files, tmp_path, capsys, args, message):
    args = [a.format(tmp=tmp_path) for a in args]
    status, _, stderr = _predict(capsys, files["model_path"], files["log_path"], *args)
    assert status == 2 and message in stderr


def test_bad_chunk_length_is_an_argparse_error(files, tmp_path, capsys):
    with pytest.raises(SystemExit):
        cli.main(["predict", str(files["model_path"]), str(files["log_path"]), "--out", str(tmp_path / "o.csv"),
                  "--chunk-s", "0"])
    assert "argument --chunk-s: must be a positive number of seconds, got 0" in capsys.readouterr().err


def test_negative_moving_mean_window_is_an_argparse_error(files, tmp_path, capsys):
    with pytest.raises(SystemExit):
        cli.main(["predict", str(files["model_path"]), str(files["log_path"]), "--out", str(tmp_path / "o.csv"),
                  "--plot", str(tmp_path / "p.png"), "--plot-mean-s", "-0.1"])
    assert "argument --plot-mean-s: must be a non-negative number of seconds, got -0.1" in capsys.readouterr().err
    assert not (tmp_path / "o.csv").exists()


@pytest.mark.slow  # a discovery run, > 5 s
def test_model_file_of_discover_predicts_in_chunks(files, tmp_path, capsys):
    """The augmented model files 'greybox discover --save-model' writes work in predict, across chunks."""
    from greybox.models.augmented import AugmentedModel

    train = prepare([make_dataset("X", "A", seed=11, duration_s=10)])[0]
    model = AugmentedModel(base=GMSModel(n_starts=1, max_iter=80), effects=[("thermal_drift", 2.0)],
                           refine_shapes=False).fit(train)
    model_path = save_model(model, tmp_path / "augmented.gbm")
    out = tmp_path / "out.csv"
    status, stdout, stderr = _predict(capsys, model_path, files["log_path"], "--out", out, "--chunk-s", "1.5")
    assert status == 0, stderr
    assert "augmented model" in stdout and f"{_n_chunks(files, 1.5)} chunk(s) of 1.5 s" in stdout
    log = prepare([read_log(files["log_path"])])[0]
    table = pd.read_csv(out)
    np.testing.assert_allclose(table["current_model_A"], model.predict(log), rtol=0, atol=1e-9)
