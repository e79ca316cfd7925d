"""``greybox.fleet.monitor``: ``greybox monitor`` with its fingerprints on a Dask cluster (the run end to end with
logs: ``tests/monitor/test_monitor_cli.py::test_fleet_run_matches_the_sequential_one``)."""

from __future__ import annotations

import datetime as dt

import pytest

from greybox.errors import GreyboxError
from greybox.fleet.monitor import monitor_fleet
from greybox.monitor.fingerprint import FEATURES
from greybox.monitor.history import append_fingerprint
from greybox.monitor.workflow import run_monitor


def test_without_logs_it_ends_as_the_run_in_one_process_does(tmp_path):
    history = tmp_path / "history"
    for day in range(6):
        values = {f: 1.0 + (0.5 if day >= 4 and f == "backlash" else 0.01 * day) for f in FEATURES}
        append_fingerprint(history, machine="m", axis="X", date=dt.date(2026, 1, 1) + dt.timedelta(days=day),
                           sha256=f"{day:064x}", source="log", n_samples=1, values=values, lower=values, upper=values)
    fleet = monitor_fleet([], history, tmp_path / "a", baseline_days=3, workers=1)  # no log: no cluster
    alone = run_monitor([], history, tmp_path / "b", baseline_days=3)
    assert (fleet.fitted, fleet.known, fleet.duplicates) == (alone.fitted, alone.known, alone.duplicates) == (0, 0, [])
    assert [alarm.describe() for alarm in fleet.detector.alarms_] == [
        alarm.describe() for alarm in alone.detector.alarms_]
    assert fleet.page.read_text() == alone.page.read_text().replace(str(tmp_path / "b"), str(tmp_path / "a"))


@pytest.mark.parametrize("workers", [0, True, 1.5])
def test_a_bad_number_of_workers_is_refused_before_any_work(tmp_path, workers):
    with pytest.raises(GreyboxError, match="workers must be a positive whole number"):
        monitor_fleet([tmp_path / "missing.csv"], tmp_path / "history", tmp_path / "out", workers=workers)
    assert not (tmp_path / "history").exists() and not (tmp_path / "out").exists()
