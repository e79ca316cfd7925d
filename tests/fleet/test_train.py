"""Fleet training: ``greybox train --per-machine`` on a Dask cluster (a LocalCluster of 2 workers here)."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import greybox.cli as cli
from greybox.data.io import read_log, write_log
from greybox.data.prepare import prepare
from greybox.fleet import expand_logs
from greybox.fleet.train import train_jobs, train_model
from greybox.metrics import metrics_table
from greybox.models.files import load_model
from greybox.models.friction import CoulombModel
from greybox.models.plant import MANIFEST
from greybox.twin import make_dataset

#: The module's tests take long together (model fits, end-to-end runs): left out of the default run;
#: `pytest -m slow` runs them, as .ci/run does.
pytestmark = pytest.mark.slow

#: A short GMS identification (one start, 100 iterations): seconds per model, the same for fleet and plain runs.
QUICK = ["--model", "gms", "--set", "n_starts=1", "--set", "max_iter=100", "--quiet"]


@pytest.fixture(scope="module")
def plant(tmp_path_factory):
    """Three machines' air cuts: mill1 two logs, mill2 one, mill3 a broken one."""
    root = tmp_path_factory.mktemp("plant")
    for machine in ("mill1", "mill2", "mill3"):
        (root / machine).mkdir()
    write_log(make_dataset("X", "A", 1, duration_s=30), root / "mill1" / "a.mcap")
    write_log(make_dataset("X", "A", 2, duration_s=30), root / "mill1" / "b.parquet")
    write_log(make_dataset("X", "A", 3, duration_s=30), root / "mill2" / "a.csv")
    (root / "mill3" / "broken.csv").write_text("not,a\nlog,x\n")
    return root


def _main(capsys, argv) -> tuple[int, str, str]:
    status = cli.main([str(item) for item in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def _parameters(model) -> dict:
    return {row.name: np.asarray(row.value, dtype=float) for row in model.parameter_table()}


@pytest.fixture(scope="module")
def trained(plant, tmp_path_factory):
    """The plant's fleet trained once on 2 workers: (command line, exit status, models directory)."""
    out = tmp_path_factory.mktemp("trained") / "models"
    argv = ["train", *QUICK, "--train", plant, "--per-machine", "--out", out, "--workers", "2"]
    return argv, cli.main([str(item) for item in argv]), out


def test_a_model_per_machine_equals_plain_training_on_its_logs(plant, trained, tmp_path, capsys):
    _, status, out = trained
    assert status == 2  # mill3 fails, mill1 and mill2 are trained
    manifest = json.loads((out / MANIFEST).read_text())
    assert manifest["format"] == "greybox-fleet-models" and manifest["cluster"]["workers"] == 2
    assert manifest["versions"]["distributed"] and manifest["counts"] == {"ok": 2, "skipped": 0, "failed": 1}
    entries = {entry["machine"]: entry for entry in manifest["models"]}
    assert entries["mill3"]["status"] == "failed" and not (out / "mill3").exists()
    assert "broken.csv: missing required column" in entries["mill3"]["error"]
    assert [Path(log["path"]).name for log in entries["mill1"]["logs"]] == ["a.mcap", "b.parquet"]
    assert entries["mill1"]["logs"][1]["size"] == (plant / "mill1" / "b.parquet").stat().st_size
    assert entries["mill1"]["model"]["params"]["n_starts"] == 1 and entries["mill1"]["peak_rss_mb"] > 0
    for machine in ("mill1", "mill2"):
        entry = entries[machine]
        assert entry["status"] == "ok" and entry["axis"] == "X" and entry["output"] == f"{machine}/X.gbm"
        fleet = load_model(out / machine / "X.gbm")
        logs = [log["path"] for log in entry["logs"]]
        plain = tmp_path / f"{machine}.gbm"
        assert _main(capsys, ["train", *QUICK, "--train", *logs, "--out", plain])[0] == 0
        expected = _parameters(load_model(plain))
        for name, value in _parameters(fleet).items():
            np.testing.assert_allclose(value, expected[name], rtol=1e-9, atol=0, err_msg=f"{machine} {name}")
        runs = prepare([read_log(log) for log in logs])
        table = metrics_table(np.concatenate([run.effort for run in runs]),
                              np.concatenate([fleet.predict(run) for run in runs]))
        assert entry["re"] == pytest.approx(table["re"], rel=1e-9) and entry["samples"] == table["n"]
    assert not np.allclose(_parameters(load_model(out / "mill1" / "X.gbm"))["k"],
                           _parameters(load_model(out / "mill2" / "X.gbm"))["k"])


def test_a_rerun_skips_complete_models_and_force_retrains(plant, trained, tmp_path, capsys):
    argv, _, trained_out = trained
    out = tmp_path / "models"
    shutil.copytree(trained_out, out)  # the manifest names its models relative to the directory
    argv = [out if item == trained_out else item for item in argv]
    log = plant / "mill2" / "a.csv"
    os.utime(log, ns=(log.stat().st_atime_ns, log.stat().st_mtime_ns + 10**9))  # mill2's log changed
    status, printed, _ = _main(capsys, argv)
    assert status == 2 and "1 trained, 1 skipped" in printed and "1 failed of 3 models" in printed
    assert "mill1/X: 2 log(s)" in printed and "(skipped)" in printed and "failed: mill3: " in printed
    modified = (out / "mill1" / "X.gbm").stat().st_mtime_ns
    status, printed, _ = _main(capsys, argv + ["--force"])
    assert status == 2 and "2 trained, 0 skipped" in printed
    assert (out / "mill1" / "X.gbm").stat().st_mtime_ns > modified


def test_each_log_is_predicted_with_its_machines_model(plant, trained, tmp_path, capsys):
    models = trained[2]
    out = tmp_path / "results"
    status, printed, _ = _main(capsys, ["predict", models, plant / "mill1", plant / "mill2", "--out", out,
                                        "--workers", "2", "--quiet"])
    assert status == 0 and "3 predicted" in printed
    entries = json.loads((out / MANIFEST).read_text())["logs"]
    used = {Path(entry["log"]).parent.name: entry["model"] for entry in entries}
    assert used == {"mill1": str(models / "mill1" / "X.gbm"), "mill2": str(models / "mill2" / "X.gbm")}
    single = tmp_path / "single.parquet"
    assert _main(capsys, ["predict", models / "mill2" / "X.gbm", plant / "mill2" / "a.csv", "--out", single,
                          "--quiet"])[0] == 0
    part = pd.read_parquet(out / "machine=mill2" / "axis=X" / "log=mill2%2Fa.csv" / "part-0.parquet")
    pd.testing.assert_frame_equal(part, pd.read_parquet(single))
    from_directory = tmp_path / "from_directory.parquet"  # one log, the models directory: its machine's model
    status, printed, _ = _main(capsys, ["predict", models, plant / "mill2" / "a.csv", "--out", from_directory,
                                        "--quiet"])
    assert status == 0 and str(models / "mill2" / "X.gbm") in printed
    pd.testing.assert_frame_equal(pd.read_parquet(from_directory), pd.read_parquet(single))
    status, _, error = _main(capsys, ["predict", models, plant, "--out", tmp_path / "r2"])
    assert status == 2 and "no trained model of machine mill3" in error and "\n" not in error.strip()


def test_a_run_stopped_midway_keeps_the_models_it_finished(plant, tmp_path, capsys, monkeypatch):
    import greybox.cli._fleet as cli_fleet
    import greybox.fleet.engine as fleet

    def stop_after_the_first(noun, quiet, label):
        def show(done, total, entry):
            raise KeyboardInterrupt  # Ctrl-C while the second model trains

        return show

    monkeypatch.setattr(fleet, "SAVE_EVERY_S", 0.0)
    monkeypatch.setattr(cli_fleet, "fleet_progress", stop_after_the_first)
    out = tmp_path / "models"
    argv = ["train", *QUICK, "--train", plant / "mill1", plant / "mill2", "--per-machine", "--out", out,
            "--workers", "2"]
    assert _main(capsys, argv)[0] == 130
    (finished,) = json.loads((out / MANIFEST).read_text())["models"]
    assert finished["status"] == "ok" and (out / finished["output"]).is_file()
    monkeypatch.undo()
    status, printed, _ = _main(capsys, argv)
    assert status == 0 and "1 trained, 1 skipped" in printed and f"{finished['machine']}/X: " in printed


def test_several_axes_a_model_each_and_one_axis_per_machine(tmp_path):
    (tmp_path / "mill1").mkdir()
    (tmp_path / "mixed").mkdir()
    x, y = make_dataset("X", "A", 4, duration_s=10), make_dataset("Y", "A", 4, duration_s=10)
    write_log([x, y], tmp_path / "mill1" / "both.mcap")
    write_log(x, tmp_path / "mixed" / "x.mcap")
    write_log(y, tmp_path / "mixed" / "y.mcap")
    out = tmp_path / "models"
    jobs = train_jobs(expand_logs([str(tmp_path / "mill1")]), CoulombModel(), str(out), axes=["X", "Y"])
    assert [(job.machine, job.read["axis"]) for job in jobs] == [("mill1", "X"), ("mill1", "Y")]
    for job, log in zip(jobs, (x, y)):
        entry = train_model(job)
        assert entry["status"] == "ok" and entry["output"] == f"mill1/{log.axis}.gbm"
        alone = CoulombModel().fit(prepare([log]))
        np.testing.assert_allclose(load_model(out / entry["output"]).coulomb_pos_, alone.coulomb_pos_, rtol=1e-12)
    (mixed,) = train_jobs(expand_logs([str(tmp_path / "mixed")]), CoulombModel(), str(out))
    entry = train_model(mixed)
    assert entry["status"] == "failed" and "machine mixed: its logs are of several axes, X (x.mcap), Y (y.mcap)" \
        in entry["error"]


def test_fleet_training_options_are_checked(plant, tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    (tmp_path / "file.gbm").write_text("")
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / MANIFEST).write_text('{"format": "greybox-fleet"}')  # a fleet prediction's output
    base = ["train", "--model", "coulomb", "--train"]
    for argv, message in (
            ([plant, "--out", tmp_path / "m"], "--train " + str(plant) + ": a directory or pattern"),
            ([plant / "mill1" / "a.mcap", "--out", tmp_path / "m.gbm", "--workers", "2"],
             "--scheduler and --workers apply with --per-machine"),
            ([plant, "--per-machine", "--out", tmp_path / "m", "--stage2", plant / "mill2" / "a.csv"],
             "--stage2 does not apply with --per-machine"),
            ([plant, "--per-machine", "--out", tmp_path / "m", "--machine", "m.toml"],
             "--machine does not apply with --per-machine"),
            ([tmp_path / "empty", "--per-machine", "--out", tmp_path / "m"], "empty: no log file"),
            ([plant, "--per-machine", "--out", tmp_path / "file.gbm"], "exists and is not a directory"),
            ([plant, "--per-machine", "--out", plant], "is one of the inputs"),
            ([plant, "--per-machine", "--out", tmp_path / "results"], "_manifest.json of another kind of run"),
            ([plant, "--per-machine", "--out", tmp_path / "m", "--axes", "X", "--columns", "position_mm=p"],
             "--columns does not apply with --axes"),
            ([plant, "--per-machine", "--out", tmp_path / "m", "--elements", "3"],
             "option --elements does not apply to the coulomb model")):
        status, _, error = _main(capsys, base + argv)
        assert status == 2 and message in error and "\n" not in error.strip(), (argv, error)
