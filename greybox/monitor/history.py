"""The fingerprint history: a Parquet dataset partitioned by machine / axis / date.

Layout (schema version :data:`SCHEMA_VERSION`, documented in docs/monitor.md)::

    DIR/machine=<machine>/axis=<axis>/date=<YYYY-MM-DD>/<sha256 of the log file>.parquet

Each file holds one row: the fingerprint of one log. The row is keyed by the SHA-256 of the log file's
bytes, so fingerprinting the same log again rewrites the same file with the same row (re-runs are
idempotent) and a log already in the history need not be fitted again. The partition columns are also
stored in the row, so every file can be read on its own. Files are written atomically.

Many small files are slow to query; :func:`compact_history` (which ``greybox monitor`` runs after filing
its logs) merges the row files of each machine and axis
into one file ``DIR/machine=<machine>/axis=<axis>/compacted.parquet`` (same schema, one row per log) and
removes them. The logs in it stay known (:func:`find_log`); a log filed again after compaction gets a row
file of its own, which wins over its row in the compacted file when the history is read.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import re
from pathlib import Path
from typing import Mapping

import pyarrow as pa
import pyarrow.parquet as pq

from ..atomic import atomic_output
from ..errors import GreyboxError
from .fingerprint import FEATURE_UNITS, FEATURES

__all__ = ["COMPACTED_NAME", "HistoryError", "SCHEMA", "SCHEMA_VERSION", "append_fingerprint", "compact_history",
           "file_sha256", "find_log", "has_log", "read_history", "row_path"]

#: File name of the compacted rows of one machine and axis.
COMPACTED_NAME = "compacted.parquet"

#: Version of the row schema; a history written with another version is refused.
SCHEMA_VERSION = 2

_KEY_FIELDS = [
    pa.field("schema_version", pa.int32(), nullable=False),
    pa.field("machine", pa.string(), nullable=False),
    pa.field("axis", pa.string(), nullable=False),
    pa.field("date", pa.date32(), nullable=False),
    pa.field("log_sha256", pa.string(), nullable=False),
    pa.field("source", pa.string()),
    pa.field("n_samples", pa.int64()),
]
#: The row schema: keys, then each feature with the ends of its interval (``<feature>_lo``, ``<feature>_hi``),
#: then the friction-along-travel map (bin centres and mean excess over the sliding level).
SCHEMA = pa.schema(_KEY_FIELDS + [
    pa.field(f"{name}{suffix}", pa.float64(), metadata={"unit": FEATURE_UNITS[name]})
    for name in FEATURES for suffix in ("", "_lo", "_hi")
] + [
    pa.field("map_position_mm", pa.list_(pa.float64()), metadata={"unit": "mm"}),
    pa.field("map_excess_A", pa.list_(pa.float64()), metadata={"unit": "A"}),
], metadata={"greybox.monitor.schema_version": str(SCHEMA_VERSION)})

_NAME = re.compile(r"^[A-Za-z0-9_.-]+$")
_SHA = re.compile(r"^[0-9a-f]{64}$")


class HistoryError(GreyboxError):
    """The history directory or one of its files is unusable (corrupt, foreign schema)."""


def file_sha256(path) -> str:
    """SHA-256 [hex] of a file's bytes.

    Parameters
    ----------
    path : path-like
        File to hash.
    """
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for chunk in iter(lambda: handle.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()


def _check_name(kind: str, value: str) -> str:
    if not _NAME.match(value or ""):
        raise HistoryError(f"{kind} name {value!r} is not usable in the history: use letters, digits, '_', '.', '-'")
    return value


def row_path(history, machine: str, axis: str, date: dt.date, sha256: str) -> Path:
    """The file of one fingerprint row in the history.

    Parameters
    ----------
    history : path-like
        History directory.
    machine, axis : str
        Machine and axis names (letters, digits, ``_ . -``).
    date : datetime.date
        Day of the log.
    sha256 : str
        SHA-256 [hex] of the log file.
    """
    if not _SHA.match(sha256):
        raise HistoryError(f"not a SHA-256 digest: {sha256!r}")
    return (Path(history) / f"machine={_check_name('machine', machine)}" / f"axis={_check_name('axis', axis)}"
            / f"date={date.isoformat()}" / f"{sha256}.parquet")


def has_log(history, sha256: str) -> Path | None:
    """The history's file of the log with this SHA-256, if there is one.

    Parameters
    ----------
    history : path-like
        History directory (need not exist).
    sha256 : str
        SHA-256 [hex] of the log file.
    """
    root = Path(history)
    if not root.is_dir():
        return None
    return next(iter(sorted(root.glob(f"machine=*/axis=*/date=*/{sha256}.parquet"))), None)


def find_log(history, sha256: str) -> tuple[str, str, dt.date, Path] | None:
    """Where the history holds the row of the log with this SHA-256: machine, axis, day and file.

    Parameters
    ----------
    history : path-like
        History directory (need not exist).
    sha256 : str
        SHA-256 [hex] of the log file.

    Returns
    -------
    (str, str, datetime.date, Path) or None
        The row's machine, axis, day and the file holding it (its own row file, else a compacted file).
    """
    found = has_log(history, sha256)
    if found is not None:
        return (found.parts[-4][len("machine="):], found.parts[-3][len("axis="):],
                dt.date.fromisoformat(found.parts[-2][len("date="):]), found)
    root = Path(history)
    for path in sorted(root.glob(f"machine=*/axis=*/{COMPACTED_NAME}")) if root.is_dir() else []:
        table = _read_row_file(path, columns=("machine", "axis", "date", "log_sha256"))
        hits = [i for i, key in enumerate(table.column("log_sha256").to_pylist()) if key == sha256]
        if hits:
            return (table.column("machine")[hits[0]].as_py(), table.column("axis")[hits[0]].as_py(),
                    table.column("date")[hits[0]].as_py(), path)
    return None


def append_fingerprint(history, *, machine: str, axis: str, date: dt.date, sha256: str, source: str,
                       n_samples: int, values: Mapping[str, float], lower: Mapping[str, float],
                       upper: Mapping[str, float], map_position_mm=(), map_excess_A=()) -> Path:
    """Write the fingerprint of one log to the history (replacing the row of the same log).

    Parameters
    ----------
    history : path-like
        History directory (created if missing).
    machine, axis : str
        Machine and axis names.
    date : datetime.date
        Day of the log.
    sha256 : str
        SHA-256 [hex] of the log file: the row's key.
    source : str
        Name of the log file (for people reading the history).
    n_samples : int
        Number of samples fitted.
    values, lower, upper : mapping of str to float
        Point estimate and interval ends of each feature of :data:`~greybox.monitor.fingerprint.FEATURES`.
    map_position_mm, map_excess_A : sequence of float, optional
        The friction-along-travel map: bin centres [mm] and mean friction excess [A] (empty by default).

    Returns
    -------
    Path
        The file written.
    """
    path = row_path(history, machine, axis, date, sha256)
    earlier = has_log(history, sha256)
    row = {"schema_version": [SCHEMA_VERSION], "machine": [machine], "axis": [axis], "date": [date],
           "log_sha256": [sha256], "source": [str(source)], "n_samples": [int(n_samples)]}
    for name in FEATURES:
        row[name], row[f"{name}_lo"], row[f"{name}_hi"] = [values[name]], [lower[name]], [upper[name]]
    positions, excess = [float(p) for p in map_position_mm], [float(e) for e in map_excess_A]
    if len(positions) != len(excess):
        raise HistoryError(f"map of {len(positions)} positions and {len(excess)} values")
    row["map_position_mm"], row["map_excess_A"] = [positions], [excess]
    table = pa.Table.from_pydict(row, schema=SCHEMA)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as temporary:
        pq.write_table(table, temporary)
    if earlier is not None and earlier != path:  # the same log filed under another machine, axis or date before
        earlier.unlink()
    return path


def _read_row_file(path: Path, columns=None) -> pa.Table:
    """The rows of one history file (only ``columns``, in the schema's order, if given), checked."""
    names = SCHEMA.names if columns is None else [name for name in SCHEMA.names if name in columns]
    try:
        file_schema = pq.read_schema(path)
        missing = [name for name in SCHEMA.names if name not in file_schema.names]
        table = pq.read_table(path, columns=[name for name in names if name not in missing])
    except (pa.ArrowException, OSError) as error:
        raise HistoryError(f"{path}: not a readable Parquet file of the fingerprint history ({error})") from None
    version = file_schema.metadata and file_schema.metadata.get(b"greybox.monitor.schema_version")
    if version != str(SCHEMA_VERSION).encode():
        found = version.decode() if version else "none"
        raise HistoryError(f"{path}: history schema version {found}; this greybox reads version {SCHEMA_VERSION}")
    if missing:
        raise HistoryError(f"{path}: history file lacks the columns {', '.join(missing)}")
    return table.select(names).cast(pa.schema([SCHEMA.field(name) for name in names], metadata=SCHEMA.metadata))


def read_history(history, *, machine: str | None = None, axis: str | None = None,
                 since: dt.date | None = None) -> pa.Table:
    """All fingerprint rows of the history, sorted by machine, axis, date and log.

    Only the partitions that match ``machine``, ``axis`` and ``since`` are opened.

    Parameters
    ----------
    history : path-like
        History directory.
    machine, axis : str, optional
        Only this machine / axis.
    since : datetime.date, optional
        Only days on or after this one.

    Returns
    -------
    pyarrow.Table
        Rows of schema :data:`SCHEMA` (empty when the history is).

    Raises
    ------
    HistoryError
        If ``history`` is not a directory, or a file in it is corrupt or of another schema version.
    """
    root = Path(history)
    if root.exists() and not root.is_dir():
        raise HistoryError(f"{root}: history is a file, not a directory")
    pattern = f"machine={machine or '*'}/axis={axis or '*'}/date=*/*.parquet"
    tables = []
    for path in sorted(root.glob(pattern)) if root.is_dir() else []:
        if since is not None and path.parent.name[len("date="):] < since.isoformat():
            continue
        tables.append(_read_row_file(path))
    compacted = f"machine={machine or '*'}/axis={axis or '*'}/{COMPACTED_NAME}"
    for path in sorted(root.glob(compacted)) if root.is_dir() else []:
        rows = _read_row_file(path)
        if since is not None:
            rows = rows.filter(pa.array([d >= since for d in rows.column("date").to_pylist()]))
        tables.append(rows)
    if not tables:
        return SCHEMA.empty_table()
    table = _first_per_log(pa.concat_tables(tables))
    return table.sort_by([("machine", "ascending"), ("axis", "ascending"), ("date", "ascending"),
                          ("log_sha256", "ascending")])


def _first_per_log(table: pa.Table) -> pa.Table:
    """The first row of every log (row files come before compacted files, so they win)."""
    seen, keep = set(), []
    for key in table.column("log_sha256").to_pylist():
        keep.append(key not in seen)
        seen.add(key)
    return table if all(keep) else table.filter(pa.array(keep))


def compact_history(history) -> int:
    """Merge the row files of every machine and axis into one compacted file each, and remove them.

    Parameters
    ----------
    history : path-like
        History directory.

    Returns
    -------
    int
        Number of row files merged.

    Raises
    ------
    HistoryError
        If a file is corrupt or of another schema version (nothing is removed then).
    """
    root = Path(history)
    if not root.is_dir():
        raise HistoryError(f"{root}: history is not a directory")
    merged = 0
    for axis_dir in sorted(root.glob("machine=*/axis=*")):
        files = sorted(axis_dir.glob("date=*/*.parquet"))
        if not files:
            continue
        target = axis_dir / COMPACTED_NAME
        tables = [_read_row_file(path) for path in files]
        if target.exists():
            tables.append(_read_row_file(target))
        table = _first_per_log(pa.concat_tables(tables)).sort_by([("date", "ascending"), ("log_sha256", "ascending")])
        with atomic_output(target) as temporary:
            pq.write_table(table, temporary)
        for path in files:
            path.unlink()
            if not any(path.parent.iterdir()):
                path.parent.rmdir()
        merged += len(files)
    return merged
