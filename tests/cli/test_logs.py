"""The log commands at the command line: bad input gives one line, exit 2, no traceback."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from greybox.cli import main
from greybox.data.io import write_log

REPO = Path(__file__).resolve().parents[2]

GOOD_CSV = "time_s,position_mm,current_A\n" + "".join(f"{0.002 * k:.3f},{0.01 * k},{0.1}\n" for k in range(400))


def bad_csv(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def rows(times, positions=None, currents=None):
    positions = positions if positions is not None else [0.01 * k for k in range(len(times))]
    currents = currents if currents is not None else [0.1] * len(times)
    body = "".join(f"{t},{p},{i}\n" for t, p, i in zip(times, positions, currents))
    return "time_s,position_mm,current_A\n" + body


STEP = [0.002 * k for k in range(400)]
CASES = {
    "missing_column.csv": ("time_s,position_mm\n0,1\n0.002,2\n", "current_A"),
    "nan.csv": (rows(STEP, currents=[0.1] * 100 + ["nan"] + [0.1] * 299), "NaN"),
    "inf.csv": (rows(STEP, positions=[0.0] * 50 + ["inf"] + [0.0] * 349), "inf"),
    "backwards.csv": (rows(STEP[:200] + [STEP[150]] + STEP[201:]), "backwards"),
    "repeated.csv": (rows(STEP[:200] + [STEP[199]] + STEP[201:]), "repeat"),
    "gap.csv": (rows(STEP[:200] + [t + 0.1 for t in STEP[200:]]), "gap"),
    "empty.csv": ("", "empty"),
    "header_only.csv": ("time_s,position_mm,current_A\n", "no data rows"),
    "unknown_unit.csv": (GOOD_CSV.replace("position_mm", "position_inch"), "unknown unit"),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_bad_csv_is_one_line_naming_file_and_problem(tmp_path, capsys, name):
    text, problem = CASES[name]
    path = bad_csv(tmp_path, name, text)
    assert main(["info", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert err.startswith(f"greybox info: error: {path}: ")
    assert problem.lower() in err.lower(), err


def test_corrupt_and_truncated_mcap(tmp_path, capsys, make_log):
    good = tmp_path / "good.mcap"
    write_log(make_log(n=3000), good)
    data = good.read_bytes()
    truncated = tmp_path / "truncated.mcap"
    truncated.write_bytes(data[: len(data) // 2])
    corrupt = tmp_path / "corrupt.mcap"
    corrupt.write_bytes(np.random.default_rng(0).integers(0, 256, 4000, dtype=np.uint8).tobytes())
    for path in (truncated, corrupt):
        assert main(["plot", str(path), "--out", str(tmp_path / "x.png")]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"greybox plot: error: {path}: ") and err.count("\n") == 1, err
    assert not (tmp_path / "x.png").exists()


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_console_script_exits_2_without_traceback(tmp_path):
    path = bad_csv(tmp_path, "gap.csv", CASES["gap.csv"][0])
    result = subprocess.run(
        [sys.executable, "-m", "greybox", "info", str(path)], capture_output=True, text=True, check=False
    )
    assert result.returncode == 2
    assert "Traceback" not in result.stderr and str(path) in result.stderr and "gap" in result.stderr


def test_info_reports_the_shipped_log_and_its_noise_floor(capsys):
    path = REPO / "data" / "X_D.mcap"
    assert main(["info", str(path), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["axis"] == "X" and summary["dataset"] == "D"
    assert summary["sample_time_ms"] == pytest.approx(2.0)
    assert summary["position_min_mm"] >= -510.0 - 1e-6 and summary["position_max_mm"] <= 1e-6
    # D runs at 1200 mm/min; derived speeds stay close to it
    assert summary["speed_max_mm_min"] == pytest.approx(1200.0, rel=0.05)
    assert 0.03 < summary["noise_floor_rmse_A"] < 0.1


def test_info_column_mapping_on_a_cnc_export(tmp_path, capsys):
    path = tmp_path / "export.csv"
    n = 300
    position = np.linspace(100.0, 130.0, n)
    lines = ["X1_ActualPosition,X1_CurrentFeedback,Machining_Process"]
    lines += [f"{p},{1.5},Layer 1 Up" for p in position]
    path.write_text("\n".join(lines) + "\n")
    status = main([
        "info", str(path), "--json", "--sample-time", "0.1",
        "--columns", "position_mm=X1_ActualPosition,current_A=X1_CurrentFeedback",
    ])
    assert status == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["samples"] == n and summary["duration_s"] == pytest.approx(0.1 * (n - 1))
    assert summary["effort_rms"] == pytest.approx(1.5)


def test_plot_writes_png_of_emps_force_log(tmp_path, capsys, real_data):
    out = tmp_path / "emps.png"
    assert main(["plot", str(real_data("EMPS") / "DATA_EMPS.mat"), "--out", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert str(out) in capsys.readouterr().out


def test_reproduce_finds_the_shipped_data_from_the_working_directory(tmp_path, monkeypatch):
    from greybox.cli.reproduce import default_data_dir

    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "X_A.mcap").write_bytes(b"")
    monkeypatch.chdir(tmp_path)
    assert default_data_dir() == tmp_path / "data"
    monkeypatch.chdir(tmp_path / "data")  # no data/ here: fall back to the source tree
    assert default_data_dir() == REPO / "data"
