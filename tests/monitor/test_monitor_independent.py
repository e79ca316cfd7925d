"""``greybox monitor`` on the independent simulator's production histories (issue 40's development split)."""

from __future__ import annotations

import datetime as dt
import json
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from greybox.monitor.workflow import run_monitor

#: The development split of the independent histories: ``../shared/data/independent`` beside the repository.
HISTORIES = Path(__file__).resolve().parents[3] / "shared" / "data" / "independent" / "histories_dev"

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def histories():
    if not HISTORIES.is_dir():
        pytest.skip(f"independent development histories not found: no folder {HISTORIES}")
    return HISTORIES


def test_local_defect_found_without_a_spindle_column(histories, tmp_path):
    truth = json.loads((histories / "truth.json").read_text())["machines"]["d4"]
    logs = []
    for path in sorted((histories / "d4").glob("*.parquet")):  # the days without their spindle-load column
        logs.append(tmp_path / "logs" / path.name)
        logs[-1].parent.mkdir(exist_ok=True)
        pq.write_table(pq.read_table(path).drop_columns(["spindle_load_pct"]), logs[-1])
    result = run_monitor(logs, tmp_path / "h", tmp_path / "r", machine="d4", find_cuts=True)
    onset = dt.date.fromisoformat(truth["onset_date"])
    alarms = result.detector.alarms_
    assert alarms and all(alarm.detected >= onset for alarm in alarms)  # nothing before the onset
    first = min(alarms, key=lambda alarm: alarm.detected)
    assert (first.feature, first.direction) == ("local_excess", "rises")
    assert (first.detected - onset).days <= 7
    low, high = truth["at"]
    assert low - 5.0 <= first.position_mm <= high + 5.0  # where the defect is
