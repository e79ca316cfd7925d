"""The fingerprint history (greybox.monitor.history): rows keyed by the log's hash, idempotent, validated."""

from __future__ import annotations

import datetime as dt

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from greybox.monitor.fingerprint import FEATURES
from greybox.monitor.history import (
    COMPACTED_NAME,
    SCHEMA_VERSION,
    HistoryError,
    append_fingerprint,
    compact_history,
    file_sha256,
    find_log,
    has_log,
    read_history,
    row_path,
)

SHA_A, SHA_B = "a" * 64, "b" * 64


def _append(history, sha=SHA_A, *, axis="X", date=dt.date(2026, 3, 1), level=1.0, machine="mill1"):
    values = {name: level for name in FEATURES}
    return append_fingerprint(history, machine=machine, axis=axis, date=date, sha256=sha, source="log.mcap",
                              n_samples=100, values=values, lower={k: v - 0.1 for k, v in values.items()},
                              upper={k: v + 0.1 for k, v in values.items()})


def test_rows_are_partitioned_and_read_back(tmp_path):
    path = _append(tmp_path, level=1.5)
    assert path == tmp_path / "machine=mill1" / "axis=X" / "date=2026-03-01" / f"{SHA_A}.parquet"
    _append(tmp_path, SHA_B, axis="Y", date=dt.date(2026, 3, 2), level=2.0)
    table = read_history(tmp_path)
    assert table.num_rows == 2
    assert table.column("axis").to_pylist() == ["X", "Y"]
    assert table.column("sliding_pos").to_pylist() == [1.5, 2.0]
    assert table.column("sliding_pos_hi").to_pylist() == [1.6, 2.1]
    assert table.column("schema_version").to_pylist() == [SCHEMA_VERSION] * 2
    assert read_history(tmp_path, axis="Y").column("log_sha256").to_pylist() == [SHA_B]
    assert read_history(tmp_path, since=dt.date(2026, 3, 2)).num_rows == 1
    assert read_history(tmp_path / "absent").num_rows == 0


def test_rerun_is_idempotent(tmp_path):
    _append(tmp_path)
    first = read_history(tmp_path)
    _append(tmp_path)
    assert read_history(tmp_path).equals(first)
    assert len(list(tmp_path.rglob("*.parquet"))) == 1
    _append(tmp_path, date=dt.date(2026, 3, 5))  # the same log filed under another day replaces its row
    table = read_history(tmp_path)
    assert table.num_rows == 1 and table.column("date").to_pylist() == [dt.date(2026, 3, 5)]
    assert has_log(tmp_path, SHA_A) == row_path(tmp_path, "mill1", "X", dt.date(2026, 3, 5), SHA_A)


def test_file_sha256_is_of_the_bytes(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    one.write_bytes(b"abc")
    two.write_bytes(b"abd")
    assert file_sha256(one) == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
    assert file_sha256(two) != file_sha256(one)


def test_corrupt_file_is_named(tmp_path):
    path = _append(tmp_path)
    path.write_bytes(b"PAR1 not really")
    with pytest.raises(HistoryError, match=rf"{path.name}: not a readable Parquet file"):
        read_history(tmp_path)


def test_other_schema_version_is_refused(tmp_path):
    path = _append(tmp_path)
    table = pq.read_table(path)
    pq.write_table(table.replace_schema_metadata({"greybox.monitor.schema_version": "99"}), path)
    with pytest.raises(HistoryError, match="schema version 99"):
        read_history(tmp_path)
    pq.write_table(pa.table({"x": [1]}), path)
    with pytest.raises(HistoryError, match="schema version none"):
        read_history(tmp_path)


def test_bad_names_are_refused(tmp_path):
    with pytest.raises(HistoryError, match="machine name 'a/b'"):
        _append(tmp_path, machine="a/b")
    with pytest.raises(HistoryError, match="not a SHA-256"):
        _append(tmp_path, sha="xyz")
    (tmp_path / "file").write_text("")
    with pytest.raises(HistoryError, match="is a file"):
        read_history(tmp_path / "file")


def test_compaction_keeps_every_row_and_the_logs_known(tmp_path):
    shas = [c * 64 for c in "abcdef"]
    for i, sha in enumerate(shas):
        _append(tmp_path, sha, axis="XY"[i % 2], date=dt.date(2026, 3, 1 + i), level=1.0 + i)
    before = read_history(tmp_path)
    assert compact_history(tmp_path) == 6
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*.parquet")) == [
        f"machine=mill1/axis={a}/{COMPACTED_NAME}" for a in "XY"]
    assert read_history(tmp_path).equals(before)
    assert read_history(tmp_path, axis="Y", since=dt.date(2026, 3, 4)).column("sliding_pos").to_pylist() == [4.0, 6.0]
    assert find_log(tmp_path, shas[2]) == ("mill1", "X", dt.date(2026, 3, 3),
                                            tmp_path / "machine=mill1" / "axis=X" / COMPACTED_NAME)
    assert find_log(tmp_path, "9" * 64) is None and has_log(tmp_path, shas[2]) is None
    # the same log filed again: its own row file wins; compacting again merges it without a duplicate
    _append(tmp_path, shas[2], axis="X", date=dt.date(2026, 3, 3), level=9.0)
    assert read_history(tmp_path).num_rows == 6
    assert 9.0 in read_history(tmp_path).column("sliding_pos").to_pylist()
    assert compact_history(tmp_path) == 1 and read_history(tmp_path).num_rows == 6
    assert 9.0 in read_history(tmp_path).column("sliding_pos").to_pylist()
    with pytest.raises(HistoryError, match="not a directory"):
        compact_history(tmp_path / "none")
