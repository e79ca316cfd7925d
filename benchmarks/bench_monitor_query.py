"""How fast the fingerprint history answers "which axes changed most this month" (DuckDB).

Usage::

    python benchmarks/bench_monitor_query.py [--machines 100] [--axes 3] [--days 60] [--repeat 5] [--json]

Writes a history of ``--machines`` x ``--axes`` axes with one fingerprint row per day for ``--days`` days in
the history's own layout (one Parquet file per log: ``machine=/axis=/date=/<sha256>.parquet``, schema of
:mod:`greybox.monitor.history`; random features, 1 % spread, a few axes with a shift in the last month) into a
temporary directory, then times :func:`greybox.monitor.query.changed_most` (the last 30 days against the first
28) ``--repeat`` times after one warm-up, one DuckDB thread, on the history as written and after
:func:`greybox.monitor.history.compact_history` (one file per machine and axis); ``--write-compacted`` writes
the compacted files directly instead (the same files compaction writes), and with ``--append-days N`` the
last N days as row files, compacted (timed) before the query as ``greybox monitor`` does after filing a day's
logs. Printed: the files, the
median and largest wall time per query, and whether the shifted axes came first.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import tempfile
import time
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from greybox.monitor.fingerprint import FEATURES
from greybox.monitor.history import COMPACTED_NAME, SCHEMA, SCHEMA_VERSION, compact_history, row_path
from greybox.monitor.query import changed_most

DAY0 = dt.date(2026, 1, 1)


def write_history(root: Path, machines: int, axes: int, days: int, rng, compacted: bool = False,
                  row_days: int = 0) -> list:
    shifted = []
    for m in range(machines):
        for a in range(axes):
            rows = []
            shift = m % 25 == 0 and a == 0
            if shift:
                shifted.append((f"m{m:03d}", f"A{a}"))
            for day in range(days):
                date = DAY0 + dt.timedelta(days=day)
                row = {"schema_version": SCHEMA_VERSION, "machine": f"m{m:03d}", "axis": f"A{a}", "date": date,
                       "log_sha256": f"{(m * 1000 + a) * 100000 + day:064x}", "source": "log", "n_samples": 5000,
                       "map_position_mm": [], "map_excess_A": []}
                for f in FEATURES:
                    value = float(rng.normal(1.0, 0.01)) + (0.1 if shift and f == "sliding_pos" and day >= days - 20
                                                            else 0.0)
                    row[f], row[f"{f}_lo"], row[f"{f}_hi"] = value, value - 0.02, value + 0.02
                if compacted and day < days - row_days:
                    rows.append(row)
                else:
                    path = row_path(root / "history", row["machine"], row["axis"], date, row["log_sha256"])
                    path.parent.mkdir(parents=True, exist_ok=True)
                    pq.write_table(pa.Table.from_pylist([row], schema=SCHEMA), path)
            if compacted:  # what compact_history writes, without the row files first
                path = root / "history" / f"machine=m{m:03d}" / f"axis=A{a}" / COMPACTED_NAME
                path.parent.mkdir(parents=True, exist_ok=True)
                pq.write_table(pa.Table.from_pylist(rows, schema=SCHEMA), path)
    return shifted


def timed(history: Path, repeat: int) -> tuple[list, list]:
    changed_most(history)
    times, top = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        top = changed_most(history, days=30, limit=10)
        times.append(time.perf_counter() - start)
    return times, top.to_pylist()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--machines", type=int, default=100)
    parser.add_argument("--axes", type=int, default=3)
    parser.add_argument("--days", type=int, default=60)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--only-compacted", action="store_true",
                        help="time the query only after compaction (the history as written takes ms per file)")
    parser.add_argument("--write-compacted", action="store_true",
                        help="write the compacted files directly (a year of row files takes long to write)")
    parser.add_argument("--append-days", type=int, default=0,
                        help="with --write-compacted: the last days as row files, compacted as greybox monitor "
                             "does after filing them (the compaction timed)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    results = {}
    with tempfile.TemporaryDirectory() as scratch:
        root = Path(scratch)
        shifted = write_history(root, args.machines, args.axes, args.days, np.random.default_rng(0),
                                args.write_compacted, args.append_days if args.write_compacted else 0)
        files_before = sum(1 for _ in (root / "history").glob("machine=*/axis=*/date=*/*.parquet"))
        names = ("compacted",) if args.only_compacted or args.write_compacted else ("history", "compacted")
        for name in names:
            if name == "compacted" and (args.append_days or not args.write_compacted):
                start = time.perf_counter()
                compact_history(root / "history")
                results["compaction_s"] = time.perf_counter() - start
            times, top = timed(root / "history", args.repeat)
            found = {(r["machine"], r["axis"]) for r in top[:len(shifted)]}
            if name == "compacted":
                results["files_before_compaction"] = files_before
            results[name] = {"files": sum(1 for _ in (root / "history").rglob("*.parquet")),
                             "median_s": float(np.median(times)), "max_s": float(np.max(times)),
                             "shifted_axes_first": found == set(shifted)}
    results["size"] = {"machines": args.machines, "axes": args.axes, "days": args.days}
    if args.json:
        print(json.dumps(results, indent=2))
        return
    if "compaction_s" in results:
        print(f"compact_history of {results['files_before_compaction']} row files took {results['compaction_s']:.1f} s")
    for name in names:
        r = results[name]
        print(f"{name}: {r['files']} Parquet files, changed_most median {r['median_s']:.3f} s, max {r['max_s']:.3f} s, "
              f"shifted axes first: {r['shifted_axes_first']}")


if __name__ == "__main__":
    main()
