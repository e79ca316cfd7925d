"""``greybox synth --history`` and ``greybox monitor``: files, re-runs, detection, one-line errors."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from greybox.cli import main
from greybox.data.io import read_log
from greybox.models.files import load_model
from greybox.monitor.fingerprint import FEATURES
from greybox.monitor.history import read_history
from greybox.monitor.workflow import fingerprint_file

#: The module's tests take long together (model fits, end-to-end runs): left out of the default run;
#: `pytest -m slow` runs them, as .ci/run does.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def twin_days(tmp_path_factory):
    """Four daily air-move logs of the twin's X axis."""
    out = tmp_path_factory.mktemp("twin")
    assert main(["synth", "--history", "4", "--axis", "X", "--seed", "2", "--out", str(out),
                 "--truth", "essential", "--start-date", "2026-05-01", "--machine", "mill7"]) == 0
    return out


def test_synth_history_writes_dated_logs(twin_days):
    names = sorted(p.name for p in twin_days.iterdir())
    assert names == [f"X_2026-05-0{d}.mcap" for d in range(1, 5)]
    log = read_log(twin_days / names[2])
    assert log.attrs["date"] == "2026-05-03" and log.attrs["machine"] == "mill7" and log.attrs["day"] == 2
    assert log.attrs["drift"]["drifts"] == []


def test_monitor_fingerprints_once_and_writes_the_page(twin_days, tmp_path, capsys):
    history, report = tmp_path / "history", tmp_path / "report"
    logs = sorted(str(p) for p in twin_days.iterdir())
    assert main(["monitor", *logs, "--history", str(history), "--out", str(report), "--baseline-days", "3"]) == 0
    out = capsys.readouterr().out
    assert "4 logs fingerprinted, 0 already in the history; 1 axes" in out
    files = sorted(history.rglob("*.parquet"))  # compacted after filing: one file of the axis
    assert [f.relative_to(history).as_posix() for f in files] == ["machine=mill7/axis=X/compacted.parquet"]
    assert [d.isoformat() for d in pq.read_table(files[0]).column("date").to_pylist()] == [
        f"2026-05-0{d}" for d in range(1, 5)]
    page = (report / "index.html").read_text()
    assert "Axes, most severe first" in page and "mill7" in page and "data:image/png;base64," in page
    row = pq.read_table(files[0]).slice(0, 1)
    assert row.num_rows == 1 and all(np.isfinite(row.column(name)[0].as_py()) for name in FEATURES)
    assert all(row.column(name)[0].as_py() > 0 for name in FEATURES if name != "local_excess")  # may be < 0
    assert len(row.column("map_position_mm")[0]) == len(row.column("map_excess_A")[0]) > 3


def test_fingerprinting_again_is_idempotent(twin_days, tmp_path):
    history = tmp_path / "history"
    log = sorted(twin_days.iterdir())[1]
    path, fitted = fingerprint_file(log, history)
    before = path.read_bytes()
    assert fitted and path.parts[-4:-1] == ("machine=mill7", "axis=X", "date=2026-05-02")
    assert fingerprint_file(log, history) == (path, False)  # known by its hash: not fitted again
    assert path.read_bytes() == before
    again, fitted = fingerprint_file(log, history, machine="mill8")  # filed under another machine: moved
    assert fitted and again.parts[-4] == "machine=mill8" and not path.exists()
    assert read_history(history).num_rows == 1


def _error(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    return err


def test_bad_logs_one_line_exit_2(twin_days, tmp_path, capsys):
    empty = tmp_path / "X_2026-05-09.csv"
    empty.write_bytes(b"")
    args = ["--history", str(tmp_path / "h"), "--out", str(tmp_path / "r")]
    assert main(["monitor", str(empty), *args]) == 2
    assert f"{empty}: empty file" in _error(capsys)
    columns = tmp_path / "X_2026-05-10.csv"
    columns.write_text("time_s,position_mm\n0,0\n0.002,0\n")
    assert main(["monitor", str(columns), *args]) == 2
    assert str(columns) in _error(capsys)
    undated = tmp_path / "undated.mcap"
    log = read_log(sorted(twin_days.iterdir())[0])
    from greybox.data.io import write_log

    write_log(log.replace(attrs={k: v for k, v in log.attrs.items() if k != "date"}), undated)
    assert main(["monitor", str(undated), *args]) == 2
    assert f"{undated}: no date" in _error(capsys)
    assert main(["monitor", *args]) == 2  # nothing given and nothing in the history
    assert "holds no fingerprints" in _error(capsys)


def test_corrupt_history_one_line_exit_2(twin_days, tmp_path, capsys):
    history = tmp_path / "history"
    bad = history / "machine=m" / "axis=X" / "date=2026-05-01" / ("0" * 64 + ".parquet")
    bad.parent.mkdir(parents=True)
    bad.write_bytes(b"garbage")
    assert main(["monitor", "--history", str(history), "--out", str(tmp_path / "r")]) == 2
    assert f"{bad}: not a readable Parquet file" in _error(capsys)
    pq.write_table(pa.table({"x": [1]}), bad)
    assert main(["monitor", "--history", str(history), "--out", str(tmp_path / "r")]) == 2
    assert "schema version none" in _error(capsys)


@pytest.mark.parametrize("args, message", [
    (["--history", "3", "--axis", "X", "--drift", "rust:1:0.1"], "unknown drift kind 'rust'"),
    (["--history", "3", "--axis", "X", "--drift", "lubrication:1"], "expected KIND:START:RATE"),
    (["--history", "3", "--axis", "X", "--drift", "preload:-1:0.1"], "start day must be a non-negative"),
    (["--history", "3", "--axis", "X", "--effect", "constant_offset"], "--effect does not apply"),
    (["--history", "3", "--axis", "X", "--start-date", "May 1"], "--start-date 'May 1'"),
    (["--axis", "X", "--drift", "none"], "--drift needs --history DAYS"),
    (["--history", "0", "--axis", "X"], "argument --history"),
])
def test_synth_history_option_errors(tmp_path, capsys, args, message):
    try:
        status = main(["synth", "--seed", "1", "--out", str(tmp_path / "o"), *args])
    except SystemExit as stop:  # an option argparse refuses
        status = stop.code
    assert status == 2
    assert message in _error(capsys)
    assert not (tmp_path / "o").exists()


@pytest.mark.slow
@pytest.mark.parametrize("kind, direction", [("lubrication", "rises"), ("preload", "falls")])
def test_drift_detected_within_a_week_and_named(tmp_path, capsys, kind, direction):
    """A drift of 1 % of the friction level per day from day 35 (of 45): alarmed within 7 days, on a level."""
    logs = tmp_path / "logs"
    assert main(["synth", "--history", "45", "--axis", "X", "--seed", "11", "--out", str(logs),
                 "--truth", "essential", "--drift", f"{kind}:35:0.01"]) == 0
    assert main(["monitor", *sorted(str(p) for p in logs.iterdir()), "--history", str(tmp_path / "h"),
                 "--out", str(tmp_path / "r")]) == 0
    alarms = [line for line in capsys.readouterr().out.splitlines() if line.startswith("alarm:")]
    assert alarms, "no alarm"
    first = alarms[0]  # earliest first
    onset = dt.date(2026, 1, 1) + dt.timedelta(days=35)
    detected = dt.date.fromisoformat(first.split("(detected ")[1][:10])
    assert onset <= detected <= onset + dt.timedelta(days=7), first
    assert f" {direction} " in first and any(f"X: {level} " in first for level in
                                            ("sliding_pos", "sliding_neg", "breakaway_pos", "breakaway_neg"))


@pytest.mark.slow
def test_stable_axis_no_alarm(tmp_path, capsys):
    logs = tmp_path / "logs"
    assert main(["synth", "--history", "45", "--axis", "X", "--seed", "12", "--out", str(logs),
                 "--truth", "essential", "--drift", "none"]) == 0
    assert main(["monitor", *sorted(str(p) for p in logs.iterdir()), "--history", str(tmp_path / "h"),
                 "--out", str(tmp_path / "r")]) == 0
    assert "1 axes, 0 alarms" in capsys.readouterr().out


def test_reference_model_leaves_out_a_process_load(twin_days, tmp_path, capsys):
    """With --model, a process current added to part of a log is left out: the levels stay those of the air cut."""
    from greybox.data.io import write_log
    from greybox.data.prepare import prepare
    from greybox.models.files import save_model
    from greybox.models.friction import CoulombModel

    source = sorted(twin_days.iterdir())[0]
    log = read_log(source)
    model_path = save_model(CoulombModel(asymmetric=True).fit(prepare(log)), tmp_path / "ref.gbx")
    fast = int(np.flatnonzero(np.abs(prepare(log)[0].velocity) >= 15.0)[0])
    load = np.zeros(len(log))
    load[fast:fast + 1500] = 0.8  # 3 s of a process force during the fast moves
    cut = tmp_path / "X_2026-05-01.mcap"
    write_log(log.replace(effort=log.effort + load), cut)
    plain = pq.read_table(fingerprint_file(source, tmp_path / "h0")[0])
    blind = pq.read_table(fingerprint_file(cut, tmp_path / "h1")[0])
    masked = pq.read_table(fingerprint_file(cut, tmp_path / "h2", model=load_model(model_path))[0])
    assert masked.column("n_samples")[0].as_py() < blind.column("n_samples")[0].as_py() - 1000
    for name in ("sliding_pos", "sliding_neg"):
        error_masked = abs(masked.column(name)[0].as_py() - plain.column(name)[0].as_py())
        error_blind = abs(blind.column(name)[0].as_py() - plain.column(name)[0].as_py())
        assert error_masked < 0.5 * error_blind, name
    garbage = tmp_path / "garbage.gbx"
    garbage.write_bytes(b"not a model")
    assert main(["monitor", str(cut), "--model", str(garbage), "--history", str(tmp_path / "h3"),
                 "--out", str(tmp_path / "r")]) == 2
    assert "garbage.gbx" in _error(capsys)


def test_production_days_fingerprinted_by_their_spindle_load(tmp_path, capsys):
    logs = tmp_path / "logs"
    assert main(["synth", "--history", "3", "--axis", "X", "--seed", "4", "--cutting", "--out", str(logs),
                 "--truth", "essential"]) == 0
    files = sorted(str(p) for p in logs.iterdir())
    log = read_log(files[0])
    assert "spindle_load_pct" in log.extras and np.count_nonzero(log.extras["truth_process_A"]) > 500
    capsys.readouterr()
    assert main(["monitor", files[0], "--history", str(tmp_path / "h"), "--out", str(tmp_path / "r"),
                 "--spindle-load", "nosuch", "--baseline-days", "3"]) == 2
    assert "no spindle-load column 'nosuch'" in _error(capsys)
    assert main(["monitor", *files, "--history", str(tmp_path / "h"), "--out", str(tmp_path / "r"),
                 "--spindle-load", "spindle_load_pct", "--baseline-days", "3"]) == 0
    table = read_history(tmp_path / "h")
    whole = fingerprint_file(files[0], tmp_path / "whole")[0]
    noise_whole = pq.read_table(whole).column("noise")[0].as_py()
    assert table.num_rows == 3 and table.column("noise")[0].as_py() < 0.7 * noise_whole  # the cut left out


def test_fleet_run_matches_the_sequential_one(twin_days, tmp_path, capsys):
    logs = sorted(str(p) for p in twin_days.iterdir())[:3]
    fleet, alone = tmp_path / "fleet", tmp_path / "alone"
    assert main(["monitor", *logs, "--history", str(fleet), "--out", str(tmp_path / "r1"), "--baseline-days", "3",
                 "--workers", "1"]) == 0
    assert "3 logs fingerprinted, 0 already in the history" in capsys.readouterr().out
    assert (fleet / "_manifest.json").is_file()
    assert main(["monitor", *logs, "--history", str(alone), "--out", str(tmp_path / "r2"),
                 "--baseline-days", "3"]) == 0
    capsys.readouterr()
    assert read_history(fleet).equals(read_history(alone))  # the same rows, whoever fitted them
    assert main(["monitor", *logs, "--history", str(fleet), "--out", str(tmp_path / "r1"), "--baseline-days", "3",
                 "--workers", "1", "--force"]) == 0
    assert "0 logs fingerprinted, 3 already in the history" in capsys.readouterr().out
    bad = tmp_path / "bad_2026-05-09.csv"
    bad.write_text("time_s,position_mm,current_A\n0,0,nan\n")
    assert main(["monitor", str(bad), "--history", str(fleet), "--out", str(tmp_path / "r1"), "--workers", "1",
                 "--force"]) == 2
    err = capsys.readouterr().err  # (Dask may note a busy dashboard port before it on a shared machine)
    assert "Traceback" not in err and "1 of 1 logs failed" in err.strip().splitlines()[-1]
    assert "at least 2 are needed" in err.strip().splitlines()[-1]


def test_monitor_compacts_the_history_it_appends_to(twin_days, tmp_path, capsys):
    history, report = tmp_path / "history", tmp_path / "report"
    logs = sorted(str(p) for p in twin_days.iterdir())
    assert main(["monitor", *logs[:3], "--history", str(history), "--out", str(report), "--baseline-days", "3"]) == 0
    page = (report / "index.html").read_bytes()
    capsys.readouterr()
    # before: the dashboard of the earlier run was replaced without --force
    assert main(["monitor", *logs, "--history", str(history), "--out", str(report), "--baseline-days", "3"]) == 2
    assert "index.html: exists; give --force" in capsys.readouterr().err
    assert (report / "index.html").read_bytes() == page and read_history(history).num_rows == 3  # nothing done
    assert main(["monitor", *logs, "--history", str(history), "--out", str(report), "--baseline-days", "3",
                 "--force"]) == 0
    assert "1 logs fingerprinted, 3 already in the history" in capsys.readouterr().out
    compacted = history / "machine=mill7" / "axis=X" / "compacted.parquet"
    assert sorted(history.rglob("*.parquet")) == [compacted]  # the new row files merged, none left
    before = compacted.read_bytes()
    assert pq.read_table(compacted).num_rows == 4 and read_history(history).num_rows == 4
    assert main(["monitor", *logs, "--history", str(history), "--out", str(report), "--baseline-days", "3",
                 "--force"]) == 0
    assert "0 logs fingerprinted, 4 already in the history" in capsys.readouterr().out
    assert compacted.read_bytes() == before  # compacting again changes nothing


def test_monitor_of_a_first_day_writes_the_page(twin_days, tmp_path, capsys):
    first = sorted(str(p) for p in twin_days.iterdir())[0]  # one day: no feature has a baseline yet
    assert main(["monitor", first, "--history", str(tmp_path / "h"), "--out", str(tmp_path / "r")]) == 0
    assert "1 logs fingerprinted, 0 already in the history; 1 axes, 0 alarms" in capsys.readouterr().out
    assert "Axes, most severe first" in (tmp_path / "r" / "index.html").read_text()
