"""read_log / write_log dispatch, atomic writes, the command-line column mapping."""

from __future__ import annotations

import os

import numpy as np
import pytest
from log_errors import assert_read_fails

from greybox.data.io import format_of, parse_column_mapping, read_log, write_log
from greybox.errors import GreyboxError, LogError


def test_missing_file(tmp_path):
    assert_read_fails(tmp_path / "nothere.csv", "no such file")


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mcap", ".mat"])
def test_zero_byte_file(tmp_path, suffix):
    path = tmp_path / f"empty{suffix}"
    path.write_bytes(b"")
    assert_read_fails(path, "empty file (0 bytes)")


def test_unknown_extension(tmp_path):
    path = tmp_path / "log.xlsx"
    path.write_bytes(b"data")
    assert_read_fails(path, "unknown log file extension '.xlsx'")


def test_directory(tmp_path):
    folder = tmp_path / "dir.csv"
    folder.mkdir()
    assert_read_fails(folder, "is a directory")


def test_format_override_and_inapplicable_options(tmp_path, make_log):
    path = tmp_path / "log.txt"
    write_log(make_log(n=50), path, fmt="csv")
    assert len(read_log(path, fmt="csv")) == 50
    assert_read_fails(path, "option 'topic' does not apply to csv files", fmt="csv", topic="/axis/X")
    assert format_of("a.PQ") == "parquet" and format_of("b.mat") == "mat"


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mcap"])
def test_write_replaces_atomically_and_leaves_no_temporary_file(tmp_path, make_log, suffix):
    path = tmp_path / f"log{suffix}"
    write_log(make_log(n=50), path)
    write_log(make_log(n=80), path)
    assert len(read_log(path)) == 80
    sidecar = [f"{path.name}.json"] if suffix == ".csv" else []  # CSV metadata go to log.csv.json
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name, *sidecar]
    mode = os.stat(path).st_mode & 0o777
    umask = os.umask(0)
    os.umask(umask)
    assert mode == 0o666 & ~umask


def test_failed_write_keeps_the_old_file(tmp_path, make_log):
    path = tmp_path / "log.csv"
    write_log(make_log(n=50), path)
    before = path.read_bytes(), (tmp_path / "log.csv.json").read_bytes()
    with pytest.raises(TypeError):
        write_log(make_log(n=50, attrs={"not json": object()}), path)
    assert (path.read_bytes(), (tmp_path / "log.csv.json").read_bytes()) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["log.csv", "log.csv.json"]


def test_refuses_to_overwrite_its_input(tmp_path, make_log):
    path = tmp_path / "log.csv"
    write_log(make_log(n=50), path)
    log = read_log(path)
    with pytest.raises(LogError, match="refusing to overwrite"):
        write_log(log, path)
    write_log(log, tmp_path / "copy.csv")


def test_write_errors(tmp_path, make_log):
    with pytest.raises(LogError, match="can be read but not written"):
        write_log(make_log(), tmp_path / "out.mat")
    with pytest.raises(LogError, match="axis name '' cannot prefix columns"):
        write_log([make_log(axis=""), make_log(axis="Y")], tmp_path / "out.csv")
    with pytest.raises(LogError, match="several logs of axis X"):
        write_log([make_log(), make_log()], tmp_path / "out.parquet")


def test_parse_column_mapping():
    text = " position_mm = X1_ActualPosition, current_A=X1_CurrentFeedback,velocity_mm_min=F=1 "
    assert parse_column_mapping(text) == {
        "position_mm": "X1_ActualPosition",
        "current_A": "X1_CurrentFeedback",
        "velocity_mm_min": "F=1",
    }


@pytest.mark.parametrize(
    "text, problem",
    [
        ("position_mm", "not of the form"),
        ("position_mm=", "empty name"),
        ("pos=X1", "'pos' is not a quantity"),
        ("position_inch=X1", "'position_inch' is not a quantity with a known unit"),
        ("current_A=a,current_A=b", "given twice"),
        (" , ", "no pairs"),
    ],
)
def test_parse_column_mapping_errors(text, problem):
    with pytest.raises(GreyboxError, match=problem):
        parse_column_mapping(text)


def test_read_log_result_is_validated(tmp_path, make_log):
    log = make_log(n=100)
    bad = log.replace(time=np.where(np.arange(100) < 50, log.time, log.time + 1.0))
    write_log(bad, tmp_path / "gap.parquet")
    assert_read_fails(tmp_path / "gap.parquet", "gap of 1002 ms at t = 0.098 s")
