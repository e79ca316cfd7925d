"""``greybox monitor`` on plain files: a one-axis CSV as it comes, copies of one log, too few days."""

from __future__ import annotations

import csv
import shutil

import pytest

from greybox.cli import main
from greybox.monitor.history import read_history
from greybox.monitor.workflow import DuplicateLogError, fingerprint_file
from greybox.twin.ageing import aged_log


def _plain_csv(path, day: int):
    """A twin day as a plain one-axis CSV: time_s, position_mm, velocity_mm_s, current_A, no axis name."""
    log = aged_log("X", day, 3)
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["time_s", "position_mm", "velocity_mm_s", "current_A"])
        writer.writerows(zip(log.time, log.position, log.velocity, log.effort))
    return path


@pytest.fixture(scope="module")
def plain_days(tmp_path_factory):
    folder = tmp_path_factory.mktemp("plain")
    return [_plain_csv(folder / f"day_2026-06-0{day + 1}.csv", day) for day in range(3)]


def test_a_plain_csv_is_monitored_as_it_comes(plain_days, tmp_path):
    path, fitted = fingerprint_file(plain_days[0], tmp_path / "h", machine="lathe")
    assert fitted and path.parts[-4:-1] == ("machine=lathe", "axis=axis", "date=2026-06-01")
    named, fitted = fingerprint_file(plain_days[1], tmp_path / "h", machine="lathe", axis="Z")  # --axis names it
    assert fitted and named.parts[-3] == "axis=Z"
    assert sorted(read_history(tmp_path / "h").column("axis").to_pylist()) == ["Z", "axis"]


def test_a_copy_under_another_day_is_not_filed_again(plain_days, tmp_path):
    copy = tmp_path / "day_2026-06-09.csv"
    shutil.copyfile(plain_days[0], copy)
    history = tmp_path / "h"
    first, fitted = fingerprint_file(plain_days[0], history, machine="lathe")
    assert fitted
    with pytest.raises(DuplicateLogError, match="filed under 2026-06-01: a copy, not filed again under 2026-06-09"):
        fingerprint_file(copy, history, machine="lathe")
    assert fingerprint_file(plain_days[0], history, machine="lathe") == (first, False)  # the same day: known
    table = read_history(history)
    assert table.num_rows == 1 and table.column("date")[0].as_py().isoformat() == "2026-06-01"


@pytest.mark.slow
def test_monitor_says_the_baseline_is_not_complete_and_names_copies(plain_days, tmp_path, capsys):
    copy = tmp_path / "day_2026-06-09.csv"
    shutil.copyfile(plain_days[2], copy)
    report = tmp_path / "r"
    assert main(["monitor", *map(str, plain_days), str(copy), "--machine", "lathe", "--history",
                 str(tmp_path / "h"), "--out", str(report)]) == 0
    out = capsys.readouterr().out
    assert "3 logs fingerprinted, 0 already in the history, 1 copies of logs filed under another day" in out
    assert f"note: {copy}: the same bytes as the log of lathe/axis filed under 2026-06-03" in out
    note = "baseline not yet complete: 3 of 28 days with a fingerprint; too few days to detect anything"
    assert f"note: lathe/axis: {note}" in out
    assert note in (report / "index.html").read_text()
