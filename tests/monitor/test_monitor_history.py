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


# -- the history as a database: lock, moves, only its own files, checked footers (issue 41) -------------------

import os  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import textwrap  # noqa: E402
import types  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from greybox.errors import LogError  # noqa: E402
from greybox.monitor import history as history_module  # noqa: E402
from greybox.monitor.history import LOCK_NAME, MAX_MAP_BINS, SCHEMA, history_lock  # noqa: E402
from greybox.monitor.workflow import log_date  # noqa: E402

#: A worker of the concurrency test: files its logs one by one, compacting after each, as `greybox monitor` does.
WRITER = textwrap.dedent("""
    import datetime as dt, sys
    from greybox.monitor.fingerprint import FEATURES
    from greybox.monitor.history import append_fingerprint, compact_history, read_history
    history, worker, logs = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    for i in range(logs):
        values = {name: float(i) for name in FEATURES}
        append_fingerprint(history, machine=f"m{i % 3}", axis="X", date=dt.date(2026, 1, 1) + dt.timedelta(days=i),
                           sha256=f"{worker:032x}{i:032x}", source="log", n_samples=1, values=values,
                           lower=values, upper=values)
        compact_history(history)
        read_history(history)
""")


def _concurrent_writers(history: Path, workers: int, logs: int) -> None:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path(__file__).resolve().parents[2]),
                                                        os.environ.get("PYTHONPATH", "")])}
    running = [subprocess.Popen([sys.executable, "-c", WRITER, str(history), str(worker), str(logs)], env=env,
                                stderr=subprocess.PIPE, text=True) for worker in range(workers)]
    for process in running:
        _, error = process.communicate(timeout=600)
        assert process.returncode == 0, error[-2000:]
    table = read_history(history)
    keys = table.column("log_sha256").to_pylist()
    assert sorted(keys) == sorted(f"{w:032x}{i:032x}" for w in range(workers) for i in range(logs))  # once each
    compact_history(history)
    assert sorted(read_history(history).column("log_sha256").to_pylist()) == sorted(keys)


def test_concurrent_writers_keep_every_row_exactly_once(tmp_path):
    # before: compaction listed the row files, merged and deleted them without a lock: rows were lost
    _concurrent_writers(tmp_path, workers=2, logs=4)


@pytest.mark.slow
def test_four_monitor_processes_of_thirty_logs_keep_every_row_exactly_once(tmp_path):
    _concurrent_writers(tmp_path, workers=4, logs=30)


def test_a_killed_holder_leaves_no_stale_lock_and_a_held_lock_times_out_in_one_line(tmp_path, monkeypatch):
    holder = subprocess.Popen([sys.executable, "-c", textwrap.dedent(f"""
        import sys, time
        from greybox.monitor.history import history_lock
        with history_lock({str(tmp_path)!r}):
            print("held", flush=True)
            time.sleep(600)
    """)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        monkeypatch.setattr(history_module, "LOCK_TIMEOUT_S", 0.3)
        with pytest.raises(HistoryError, match="locked by another greybox run"):
            _append(tmp_path)
    finally:
        holder.kill()  # SIGKILL: no clean-up runs
        holder.wait()
    assert (tmp_path / LOCK_NAME).is_file()
    _append(tmp_path)  # the kernel released the dead holder's lock
    assert read_history(tmp_path).num_rows == 1


def test_refiling_a_log_under_another_machine_moves_its_row(tmp_path):
    # before: the compacted row under the old machine stayed and was read first
    _append(tmp_path, machine="mill1")
    compact_history(tmp_path)
    _append(tmp_path, machine="mill2", level=2.0)
    table = read_history(tmp_path)
    assert table.column("machine").to_pylist() == ["mill2"] and table.column("sliding_pos").to_pylist() == [2.0]
    compact_history(tmp_path)
    assert read_history(tmp_path).column("machine").to_pylist() == ["mill2"]
    assert find_log(tmp_path, SHA_A)[0] == "mill2"


def test_links_and_fifos_in_the_history_are_refused_never_followed(tmp_path):
    history, outside = tmp_path / "history", tmp_path / "outside"
    _append(history)
    outside.mkdir()
    os.rename(history / "machine=mill1", outside / "machine=mill1")
    (history / "machine=mill1").symlink_to(outside / "machine=mill1")
    before = sorted(p.relative_to(outside).as_posix() for p in outside.rglob("*"))
    for action in (read_history, compact_history, lambda h: _append(h, SHA_B)):
        with pytest.raises(HistoryError, match="machine=mill1: a symbolic link in the history; refused"):
            action(history)
    assert sorted(p.relative_to(outside).as_posix() for p in outside.rglob("*")) == before  # nothing written there
    (history / "machine=mill1").unlink()
    _append(history)
    fifo = history / "machine=mill1" / "axis=X" / "date=2026-03-01" / f"{SHA_B}.parquet"
    os.mkfifo(fifo)  # before: opening it hung `monitor` for good
    for action in (read_history, compact_history):
        with pytest.raises(HistoryError, match="not a regular file or directory in the history"):
            action(history)
    with pytest.raises(HistoryError, match="not a regular file"):
        history_module._read_row_file(fifo)


def test_a_small_file_claiming_millions_of_map_values_is_refused_before_reading(tmp_path):
    path = _append(tmp_path)
    table = pq.read_table(path)
    claimed = 2 * (MAX_MAP_BINS + 1)
    zeros = pa.ListArray.from_arrays(pa.array([0, claimed], pa.int32()), pa.array(np.zeros(claimed)))
    forged = table.set_column(table.schema.get_field_index("map_excess_A"), SCHEMA.field("map_excess_A"), zeros)
    pq.write_table(forged, path, compression="zstd")
    assert path.stat().st_size < 100_000
    with pytest.raises(HistoryError, match=rf"map_excess_A claims {claimed} values in 1 rows"):
        read_history(tmp_path)


def test_a_file_of_the_right_metadata_but_wrong_column_types_is_refused_in_one_line(tmp_path):
    path = _append(tmp_path)
    table = pq.read_table(path)
    index = table.schema.get_field_index("sliding_pos")
    wrong = table.set_column(index, "sliding_pos", pa.array(["1.0"]))
    pq.write_table(wrong.replace_schema_metadata(SCHEMA.metadata), path)
    with pytest.raises(HistoryError, match="column sliding_pos is of type string, not double"):
        read_history(tmp_path)


def test_names_with_a_trailing_newline_are_refused(tmp_path):
    with pytest.raises(HistoryError, match="machine name 'mill1\\\\n'"):
        _append(tmp_path, machine="mill1\n")
    with pytest.raises(HistoryError, match="not a SHA-256"):
        _append(tmp_path, sha=SHA_A + "\n")


def test_compaction_removes_the_temporary_files_a_killed_writer_left(tmp_path):
    path = _append(tmp_path)
    left = path.parent / f".{path.name}.0123456789abcdef.tmp"
    left.write_bytes(b"x" * 1000)
    compact_history(tmp_path)
    assert not left.exists() and read_history(tmp_path).num_rows == 1


def test_a_log_day_after_the_file_was_written_or_with_junk_is_refused(tmp_path):
    path = tmp_path / "log.csv"
    path.write_text("")
    day = dt.datetime.fromtimestamp(path.stat().st_mtime, dt.timezone.utc).date()
    assert log_date(types.SimpleNamespace(attrs={"date": day.isoformat()}), path) == day
    assert log_date(types.SimpleNamespace(attrs={"date": f"{day.isoformat()}T08:30:00"}), path) == day
    for text, message in (("2999-12-31", "lies after the file was written"),
                          (f"{day.isoformat()}junk", "is not a valid YYYY-MM-DD day"),
                          (f"{day.isoformat()} 99", "is not a valid YYYY-MM-DD day")):
        with pytest.raises(LogError, match=message):
            log_date(types.SimpleNamespace(attrs={"date": text}), path)


def test_a_lock_is_taken_once_by_readers_together(tmp_path):
    _append(tmp_path)
    with history_lock(tmp_path, shared=True):
        assert subprocess.run([sys.executable, "-c", "import sys; from greybox.monitor.history import read_history;"
                               f"sys.exit(read_history({str(tmp_path)!r}).num_rows != 1)"], timeout=120).returncode == 0
