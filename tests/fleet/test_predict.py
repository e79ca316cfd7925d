"""Fleet runs: ``greybox predict MODEL LOG... --out DIR`` on a Dask cluster (a LocalCluster of 2 workers here)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.dataset as ds
import pytest

import greybox.cli as cli
from greybox.data.io import write_log
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError
from greybox.fleet import expand_logs
from greybox.models.files import save_model
from greybox.models.friction import StribeckModel
from greybox.models.plant import MANIFEST
from greybox.twin import make_dataset

#: The module's tests take long together (model fits, end-to-end runs): left out of the default run;
#: `pytest -m slow` runs them, as .ci/run does.
pytestmark = pytest.mark.slow

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "axis_x.toml"


@pytest.fixture(scope="module")
def plant(tmp_path_factory):
    """Two machines' logs (one of them broken) and a model file."""
    root = tmp_path_factory.mktemp("plant")
    (root / "mill1").mkdir()
    (root / "mill2").mkdir()
    write_log(make_dataset("X", "D", 11, cutting=True), root / "mill1" / "monday.mcap")
    write_log(make_dataset("X", "C", 12, duration_s=20, cutting=True), root / "mill1" / "tuesday.parquet")
    write_log(make_dataset("X", "D", 13, cutting=True), root / "mill2" / "monday.csv")
    (root / "mill2" / "broken.csv").write_text("not,a\nlog,x\n")
    save_model(StribeckModel().fit(prepare([make_dataset("X", "A", 1, duration_s=20)])), root / "x.gbm")
    return root


def test_logs_come_from_files_directories_and_patterns(plant):
    logs = expand_logs([str(plant)])
    assert [path.name for path in logs] == ["monday.mcap", "tuesday.parquet", "broken.csv", "monday.csv"]
    assert expand_logs([str(plant / "mill*" / "monday.*")]) == [plant / "mill1" / "monday.mcap",
                                                                 plant / "mill2" / "monday.csv"]
    with pytest.raises(GreyboxError, match="matches no log file"):
        expand_logs([str(plant / "*.tdms")])
    with pytest.raises(GreyboxError, match="no such log, directory or pattern"):
        expand_logs([str(plant / "absent.csv")])


def test_a_fleet_run_writes_a_partitioned_dataset_and_a_manifest(plant, tmp_path, capsys):
    out = tmp_path / "results"
    argv = ["predict", str(plant / "x.gbm"), str(plant / "mill1"), str(plant / "mill2"), "--out", str(out),
            "--axis-config", str(EXAMPLE), "--workers", "2", "--quiet"]
    assert cli.main(argv) == 2  # one log is broken: reported, the others predicted
    printed = capsys.readouterr().out
    assert "3 predicted, 0 skipped" in printed and "1 failed of 4 logs" in printed and "on 2 worker(s)" in printed
    assert "broken.csv: missing required column" in printed
    manifest = json.loads((out / MANIFEST).read_text())
    assert manifest["counts"] == {"ok": 3, "skipped": 0, "failed": 1} and manifest["versions"]["distributed"]
    table = ds.dataset(out, format="parquet", partitioning="hive").to_table().to_pandas()
    assert set(table["machine"]) == {"mill1", "mill2"} and set(table["axis"]) == {"X"}
    assert set(table["log"]) == {"mill1/monday.mcap", "mill1/tuesday.parquet", "mill2/monday.csv"}
    # a log's partition holds what greybox predict writes for that log alone
    single = tmp_path / "single.parquet"
    assert cli.main(["predict", str(plant / "x.gbm"), str(plant / "mill2" / "monday.csv"), "--out", str(single),
                     "--axis-config", str(EXAMPLE), "--quiet"]) == 0
    alone = pd.read_parquet(single)
    part = pd.read_parquet(out / "machine=mill2" / "axis=X" / "log=mill2%2Fmonday.csv" / "part-0.parquet")
    pd.testing.assert_frame_equal(part, alone)
    assert np.any(np.abs(part["force_process_N"]) > 100.0)

    capsys.readouterr()
    assert cli.main(argv) == 2  # a re-run skips what is complete
    assert "0 predicted, 3 skipped" in capsys.readouterr().out
    log = plant / "mill1" / "tuesday.parquet"
    os.utime(log, ns=(log.stat().st_atime_ns, log.stat().st_mtime_ns + 10**9))  # the log changed
    assert cli.main(argv) == 2
    assert "1 predicted, 2 skipped" in capsys.readouterr().out
    assert cli.main(argv + ["--force"]) == 2
    assert "3 predicted, 0 skipped" in capsys.readouterr().out
    assert cli.main(argv + ["--cutoff-hz", "40"]) == 2  # another read option: predicted again
    assert "3 predicted, 0 skipped" in capsys.readouterr().out
    assert cli.main(argv + ["--cutoff-hz", "40"]) == 2
    assert "0 predicted, 3 skipped" in capsys.readouterr().out
    axis_file = tmp_path / "axis.toml"  # the same axis file elsewhere: skipped; its content changed: predicted
    axis_file.write_text(EXAMPLE.read_text())
    moved = [str(axis_file) if part == str(EXAMPLE) else part for part in argv] + ["--cutoff-hz", "40"]
    assert cli.main(moved) == 2
    assert "0 predicted, 3 skipped" in capsys.readouterr().out
    axis_file.write_text(EXAMPLE.read_text().replace("screw_lead_mm = 10.0", "screw_lead_mm = 12.0"))
    assert cli.main(moved) == 2
    assert "3 predicted, 0 skipped" in capsys.readouterr().out


def test_a_fleet_runs_on_a_scheduler_address(plant, tmp_path, capsys):
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        assert cli.main(["predict", str(plant / "x.gbm"), str(plant / "mill1" / "*.mcap"), str(plant / "mill1"),
                         "--out", str(tmp_path / "r"), "--scheduler", cluster.scheduler_address, "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert "2 predicted" in printed and f"of {cluster.scheduler_address}" in printed


def test_fleet_options_are_checked(plant, tmp_path, capsys):
    base = ["predict", str(plant / "x.gbm"), str(plant / "mill1"), "--out"]
    for extra, message in (([str(tmp_path / "a"), "--plot", str(tmp_path / "p.png")], "--plot applies to one log"),
                           ([str(plant / "x.gbm")], "exists and is not a directory"),
                           ([str(tmp_path / "b"), "--scheduler", "tcp://127.0.0.1:9"], "cannot reach the Dask")):
        assert cli.main(base + extra) == 2
        error = capsys.readouterr().err.strip()
        assert message in error and "\n" not in error
    status = cli.main(["predict", str(plant / "x.gbm"), str(plant / "mill1" / "monday.mcap"), "--out",
                       str(tmp_path / "c.csv"), "--workers", "2"])
    assert status == 2 and "--scheduler and --workers apply to fleet runs" in capsys.readouterr().err


def test_logs_of_one_name_in_other_places_or_formats_get_outputs_of_their_own(plant, tmp_path, capsys):
    # were written to one file: "6 predicted, 0 failed", three files left, a re-run skipped both of a pair
    root = tmp_path / "logs"
    source = plant / "mill1" / "monday.mcap"
    for relative in ("a/m2/log.mcap", "b/m2/log.mcap", "c/X.mcap", "c/run 1.mcap", "c/run_1.mcap"):
        (root / relative).parent.mkdir(parents=True, exist_ok=True)
        (root / relative).write_bytes(source.read_bytes())
    write_log(make_dataset("X", "C", 12, duration_s=20, cutting=True), root / "c" / "X.parquet")
    out = root / "results"  # inside the input tree: never read back as logs
    argv = ["predict", str(plant / "x.gbm"), str(root), "--out", str(out), "--workers", "2", "--quiet"]
    assert cli.main(argv) == 0
    assert "6 predicted, 0 skipped (complete from an earlier run), 0 failed of 6 logs" in capsys.readouterr().out
    manifest = json.loads((out / MANIFEST).read_text())
    outputs = [entry["output"] for entry in manifest["logs"]]
    assert len(set(outputs)) == 6 and all(Path(path).is_file() for path in outputs)
    assert all(len(entry["log_sha256"]) == 64 for entry in manifest["logs"])
    table = ds.dataset(out, format="parquet", partitioning="hive").to_table().to_pandas()
    assert set(table["log"]) == {"a/m2/log.mcap", "b/m2/log.mcap", "c/X.mcap", "c/X.parquet", "c/run 1.mcap",
                                 "c/run_1.mcap"}
    assert cli.main(argv) == 0  # the output directory inside the tree is not read as logs on a re-run
    assert "0 predicted, 6 skipped" in capsys.readouterr().out


def test_a_run_where_every_log_failed_says_it_wrote_no_dataset(plant, tmp_path, capsys):
    (tmp_path / "m").mkdir()
    for name in ("a.csv", "b.csv"):
        (tmp_path / "m" / name).write_text("not,a\nlog,x\n")
    assert cli.main(["predict", str(plant / "x.gbm"), str(tmp_path / "m"), "--out", str(tmp_path / "none"),
                     "--workers", "1", "--quiet"]) == 2
    printed = capsys.readouterr().out
    assert "0 predicted" in printed and "every log failed: no output" in printed and "the dataset" not in printed
