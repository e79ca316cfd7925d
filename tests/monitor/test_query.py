"""``greybox.monitor.query``: DuckDB over the fingerprint history answers which axes changed most."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pyarrow.parquet as pq
import pytest

from greybox.errors import ParameterError
from greybox.monitor.fingerprint import FEATURES
from greybox.monitor.history import HistoryError, append_fingerprint, compact_history
from greybox.monitor.query import changed_most

DAY0 = dt.date(2026, 1, 1)


def _history(tmp_path, shifts: dict, days: int = 60):
    """Axes with every feature at 1 +- 1 % a day; ``shifts[(machine, axis)] = (feature, change)`` from day 40."""
    rng = np.random.default_rng(3)
    for (machine, axis) in [("m1", "X"), ("m1", "Y"), ("m2", "X")]:
        for day in range(days):
            values = {f: float(rng.normal(1.0, 0.01)) for f in FEATURES}
            feature, change = shifts.get((machine, axis), (None, 0.0))
            if feature is not None and day >= 40:
                values[feature] += change
            append_fingerprint(tmp_path, machine=machine, axis=axis, date=DAY0 + dt.timedelta(days=day),
                               sha256=f"{hash((machine, axis, day)) & (2**64 - 1):064x}", source="log", n_samples=1,
                               values=values, lower=values, upper=values)
    return tmp_path


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_axes_ranked_by_their_largest_change(tmp_path):
    history = _history(tmp_path, {("m2", "X"): ("backlash", 0.2), ("m1", "Y"): ("sliding_neg", -0.05)})
    table = changed_most(history, days=20)
    rows = table.to_pylist()
    assert [(r["machine"], r["axis"]) for r in rows] == [("m2", "X"), ("m1", "Y"), ("m1", "X")]
    assert rows[0]["feature"] == "backlash" and rows[0]["change_sd"] > 10 and rows[0]["recent_days"] == 20
    assert rows[1]["feature"] == "sliding_neg" and rows[1]["change_sd"] < -3
    assert rows[0]["recent"] == pytest.approx(1.2, abs=0.01) and rows[0]["baseline"] == pytest.approx(1.0, abs=0.01)
    assert abs(rows[2]["change_sd"]) < 5
    compact_history(history)  # the same answer from the compacted history
    assert changed_most(history, days=20).equals(table)
    # a period before the shift: no change stands out; limit cuts the list
    before = changed_most(history, days=10, until=DAY0 + dt.timedelta(days=39), limit=2).to_pylist()
    assert len(before) == 2 and all(abs(r["change_sd"]) < 5 for r in before)


def test_bad_options_and_histories(tmp_path):
    with pytest.raises(HistoryError, match="not a directory"):
        changed_most(tmp_path / "none")
    with pytest.raises(HistoryError, match="no fingerprints"):
        changed_most(tmp_path)
    for options in ({"days": 0}, {"limit": 0}, {"features": ["rust"]}, {"baseline_days": 1}):
        with pytest.raises(ParameterError):
            changed_most(tmp_path, **options)
    history = _history(tmp_path / "h", {}, days=5)
    path = next((tmp_path / "h").rglob("*.parquet"))
    table = pq.read_table(path)
    pq.write_table(table.replace_schema_metadata({}).set_column(0, "schema_version", [[np.int32(1)]]), path)
    with pytest.raises(HistoryError, match="schema version"):
        changed_most(history)
    pq.write_table(table.drop_columns(["backlash"]), path)  # a file of another layout among the others
    with pytest.raises(HistoryError, match="not a readable"):
        changed_most(history)
    path.write_bytes(b"not parquet")
    with pytest.raises(HistoryError, match="not a readable"):
        changed_most(history)


@pytest.mark.slow  # 2-11 s, the longest of the default run (300 s in all in session 18): in the slow run
def test_a_row_file_wins_over_its_compacted_row(tmp_path):
    history = _history(tmp_path, {})
    compact_history(history)
    first = changed_most(history, days=20).to_pylist()
    # every day of the last 20 of m1/X filed again with its backlash raised: the row files win, no row twice
    for day in range(40, 60):
        sha = f"{hash(('m1', 'X', day)) & (2**64 - 1):064x}"
        values = {f: 1.0 for f in FEATURES} | {"backlash": 1.5}
        append_fingerprint(history, machine="m1", axis="X", date=DAY0 + dt.timedelta(days=day), sha256=sha,
                           source="log", n_samples=1, values=values, lower=values, upper=values)
    rows = changed_most(history, days=20).to_pylist()
    assert (rows[0]["machine"], rows[0]["axis"], rows[0]["feature"]) == ("m1", "X", "backlash")
    assert rows[0]["recent"] == pytest.approx(1.5) and rows[0]["recent_days"] == 20
    assert first[0]["feature"] != "backlash" or abs(first[0]["change_sd"]) < 5


def test_both_readers_take_a_logs_row_from_the_same_file(tmp_path, monkeypatch):
    """A writer killed before it removed a log's older rows leaves them beside its row file: read_history (pyarrow)
    and the DuckDB reader of changed_most take the row of one file, the first in by_precedence order."""
    import duckdb

    from greybox.monitor import history as history_module
    from greybox.monitor.history import by_precedence, check_history, read_history
    from greybox.monitor.query import load_rows

    root = tmp_path / "h"

    def file(day: int, sha: str, level: float) -> None:
        values = {f: level for f in FEATURES}
        append_fingerprint(root, machine="m1", axis="X", date=DAY0 + dt.timedelta(days=day), sha256=sha,
                           source="log", n_samples=1, values=values, lower=values, upper=values)

    for day in range(4):
        file(day, f"{day:064x}", 1.0)
    compact_history(root)
    monkeypatch.setattr(history_module, "_forget", lambda *args, **kwargs: None)  # killed before forgetting
    file(1, f"{1:064x}", 2.0)  # a row file over the compacted row of the same log
    file(3, f"{2:064x}", 3.0)  # log 2 under a later day too: two row files and a compacted row
    file(2, f"{2:064x}", 4.0)
    paths = check_history(root)
    ordered = by_precedence(paths)
    assert [path.name == "compacted.parquet" for path in ordered] == [False, False, False, True]
    assert ordered[:3] == sorted(ordered[:3], key=str)
    table = read_history(root)
    with duckdb.connect() as connection:
        load_rows(connection, root, paths, ["machine", "axis", "date", *FEATURES])
        sql = connection.execute('SELECT log_sha256, date, "backlash" FROM rows ORDER BY log_sha256').fetchall()
    python = sorted(zip(table.column("log_sha256").to_pylist(), table.column("date").to_pylist(),
                        table.column("backlash").to_pylist()))
    assert sql == python
    assert [level for _, _, level in python] == [1.0, 2.0, 4.0, 1.0]  # log 1's row file, log 2's earlier path
