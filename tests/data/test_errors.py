"""Bad input gives a LogError naming the file and the problem, in every table format."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from log_errors import assert_read_fails

GOOD = {
    "time_s": np.arange(10) * 0.002,
    "position_mm": np.linspace(0.0, 1.0, 10),
    "current_A": np.ones(10),
}


def _write(frame: pd.DataFrame, path):
    if path.suffix == ".csv":
        frame.to_csv(path, index=False)
    else:
        frame.to_parquet(path, index=False)


def _case(tmp_path, suffix, **changes):
    columns = {**GOOD, **changes}
    frame = pd.DataFrame({k: v for k, v in columns.items() if v is not None})
    path = tmp_path / f"log{suffix}"
    _write(frame, path)
    return path


table_formats = pytest.mark.parametrize("suffix", [".csv", ".parquet"])


@table_formats
def test_missing_required_column(tmp_path, suffix):
    assert_read_fails(_case(tmp_path, suffix, current_A=None), "missing required column 'current_A'", "'position_mm'")
    assert_read_fails(_case(tmp_path, suffix, position_mm=None), "missing required column 'position_mm'")


@table_formats
@pytest.mark.parametrize("value, shown", [(np.nan, "nan"), (np.inf, "inf"), (-np.inf, "-inf")])
def test_non_finite_values(tmp_path, suffix, value, shown):
    current = np.ones(10)
    current[6] = value
    assert_read_fails(_case(tmp_path, suffix, current_A=current), f"channel 'current_A' holds {shown} at t = 0.012 s")


@table_formats
def test_time_backwards(tmp_path, suffix):
    time = GOOD["time_s"].copy()
    time[[4, 5]] = time[[5, 4]]
    assert_read_fails(_case(tmp_path, suffix, time_s=time), "time goes backwards at sample 5")


@table_formats
def test_time_repeated(tmp_path, suffix):
    time = GOOD["time_s"].copy()
    time[5] = time[4]
    assert_read_fails(_case(tmp_path, suffix, time_s=time), "time repeats at sample 5")


@table_formats
def test_gap_beyond_tolerance(tmp_path, suffix):
    time = GOOD["time_s"] + np.where(np.arange(10) >= 7, 0.010, 0.0)
    assert_read_fails(_case(tmp_path, suffix, time_s=time), "gap of 12 ms at t = 0.012 s")


@table_formats
def test_unknown_unit(tmp_path, suffix):
    assert_read_fails(_case(tmp_path, suffix, position_mm=None, position_inch=GOOD["position_mm"]),
                      "unknown unit 'inch'", "position_inch")
    assert_read_fails(_case(tmp_path, suffix, time_s=None, time_h=GOOD["time_s"]), "unknown unit 'h'")


@table_formats
def test_header_only(tmp_path, suffix):
    path = tmp_path / f"header{suffix}"
    _write(pd.DataFrame({name: pd.Series([], dtype=float) for name in GOOD}), path)
    assert_read_fails(path, "no data rows")


@table_formats
def test_text_in_a_base_column(tmp_path, suffix):
    position = GOOD["position_mm"].astype(object)
    position[3] = "1.2.3"
    path = _case(tmp_path, suffix, position_mm=position.astype(str))
    assert_read_fails(path, "column 'position_mm' (position) is not numeric: row 3 holds '1.2.3'")


@table_formats
def test_no_time_column_without_sample_time(tmp_path, suffix):
    assert_read_fails(_case(tmp_path, suffix, time_s=None), "no time column", "sample_time")


@table_formats
def test_mapped_column_not_in_file(tmp_path, suffix):
    assert_read_fails(_case(tmp_path, suffix), "column 'X1_CurrentFeedback' (mapped to current_A) not found",
                      columns={"current_A": "X1_CurrentFeedback"})


@table_formats
def test_two_columns_of_one_quantity(tmp_path, suffix):
    assert_read_fails(_case(tmp_path, suffix, position_um=GOOD["position_mm"] * 1e3), "several position columns")


def test_csv_with_only_comments(tmp_path):
    path = tmp_path / "comments.csv"
    path.write_text("# exported by the trace tool\n# nothing recorded\n")
    assert_read_fails(path, "no header row")


def test_csv_header_only_text(tmp_path):
    path = tmp_path / "header.csv"
    path.write_text("time_s,position_mm,current_A\n")
    assert_read_fails(path, "no data rows (the file holds only a header)")


def test_csv_ragged_rows(tmp_path):
    path = tmp_path / "ragged.csv"
    path.write_text("time_s,position_mm,current_A\n0,1,2\n0.002,1,2,7,8\n")
    assert_read_fails(path, "malformed CSV")


def test_csv_not_utf8(tmp_path):
    path = tmp_path / "latin.csv"
    path.write_bytes("time_s,position_mm,current_A,Spannung_\xb5V\n0,1,2,3\n".encode("latin-1"))
    assert_read_fails(path, "not UTF-8")
