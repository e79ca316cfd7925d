"""The fingerprint history: a Parquet dataset partitioned by machine / axis / date, a small database.

Layout (schema version :data:`SCHEMA_VERSION`, documented in docs/monitor.md)::

    DIR/machine=<machine>/axis=<axis>/date=<YYYY-MM-DD>/<sha256 of the log file>.parquet
    DIR/machine=<machine>/axis=<axis>/compacted.parquet
    DIR/.lock

Each row file holds one row: the fingerprint of one log. The row is keyed by the SHA-256 of the log file's
bytes, so fingerprinting the same log again rewrites the same file with the same row (re-runs are
idempotent) and a log already in the history need not be fitted again. The partition columns are also
stored in the row, so every file can be read on its own. Files are written atomically.

Many small files are slow to query; :func:`compact_history` (which ``greybox monitor`` runs after filing
its logs) merges the row files of each machine and axis into one file ``compacted.parquet`` (same schema,
one row per log) and removes them. The logs in it stay known (:func:`find_log`).

Guarantees (docs/monitor.md, "The history as a database"):

- **One writer at a time.** Every change (:func:`append_fingerprint`, :func:`compact_history`) holds the
  exclusive lock of ``DIR/.lock`` (:func:`history_lock`, the operating system's ``flock``); every read
  holds it shared, so a reader never sees a compaction half done. The lock belongs to the open file, so a
  process that is killed releases it: no stale lock is left to clear by hand. Waiting for it ends after
  :data:`LOCK_TIMEOUT_S` with one line.
- **Each log exactly once.** Filing a log removes its row from anywhere else in the history (another machine,
  axis or day, a compacted file included): re-filing moves the row.
- **Only its own files.** A symbolic link, FIFO, socket or device where the history keeps its directories
  and files is refused in one line, never followed or opened (``lstat``; files are opened with
  ``O_NOFOLLOW | O_NONBLOCK`` and checked to be regular).
- **Checked before read.** A file's schema version, column names and types, its row count and the number
  of values every column chunk claims (the map columns at most :data:`MAX_MAP_BINS` per row) are checked
  from its footer before any column is read.
- Hidden temporary files a killed writer left (``.*.tmp``) are removed by the next compaction.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import os
import re
import stat
import time
from pathlib import Path
from typing import Iterator, Mapping

import pyarrow as pa
import pyarrow.parquet as pq

from ..atomic import atomic_output
from ..errors import GreyboxError
from .fingerprint import FEATURE_UNITS, FEATURES

__all__ = ["COMPACTED_NAME", "HistoryError", "LOCK_NAME", "LOCK_TIMEOUT_S", "MAX_MAP_BINS", "MAX_ROWS", "SCHEMA",
           "SCHEMA_VERSION", "append_fingerprint", "by_precedence", "check_history", "compact_history", "find_log",
           "has_log", "history_lock", "read_history", "row_path"]

#: File name of the compacted rows of one machine and axis.
COMPACTED_NAME = "compacted.parquet"

#: File name of the history's lock (hidden: no dataset reader takes it for data).
LOCK_NAME = ".lock"

#: Longest wait for the history's lock [s] before giving up with one line.
LOCK_TIMEOUT_S = 600.0

#: Most rows a history file may hold (a compacted file: one row per log of one machine and axis).
MAX_ROWS = 1_000_000

#: Most bins of a friction-along-travel map per row (0.1 mm bins over 1 m of travel).
MAX_MAP_BINS = 10_000

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

_NAME = re.compile(r"[A-Za-z0-9_.-]+")
_SHA = re.compile(r"[0-9a-f]{64}")


class HistoryError(GreyboxError):
    """The history directory or one of its files is unusable (corrupt, foreign schema)."""


def _check_name(kind: str, value: str) -> str:
    if not isinstance(value, str) or not _NAME.fullmatch(value) or value in (".", ".."):
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
    if not isinstance(sha256, str) or not _SHA.fullmatch(sha256):
        raise HistoryError(f"not a SHA-256 digest: {sha256!r}")
    return (Path(history) / f"machine={_check_name('machine', machine)}" / f"axis={_check_name('axis', axis)}"
            / f"date={date.isoformat()}" / f"{sha256}.parquet")


# -- the lock ------------------------------------------------------------------------------------------------


def _try_lock(fd: int, shared: bool) -> bool:
    """Take the lock of the open lock file without waiting; whether it was taken."""
    try:
        import fcntl
    except ImportError:  # Windows: one lock, exclusive, on the file's first byte
        import msvcrt

        try:
            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
        except OSError:
            return False
        return True
    try:
        fcntl.flock(fd, (fcntl.LOCK_SH if shared else fcntl.LOCK_EX) | fcntl.LOCK_NB)
    except (BlockingIOError, PermissionError):
        return False
    return True


def _unlock(fd: int) -> None:
    try:
        import fcntl
    except ImportError:
        import msvcrt

        os.lseek(fd, 0, os.SEEK_SET)
        msvcrt.locking(fd, msvcrt.LK_UNLCK, 1)
        return
    fcntl.flock(fd, fcntl.LOCK_UN)


def _open_lock(root: Path, shared: bool) -> int | None:
    """The lock file's descriptor (created if missing); None for a reader of a history it cannot write."""
    path = root / LOCK_NAME
    flags = os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(path, flags, 0o666)
    except OSError as error:
        if shared and not path.is_symlink():  # a read-only history: no writer can change it either
            try:
                fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
            except OSError:
                return None
        else:
            raise HistoryError(f"{path}: cannot open the history's lock ({error.strerror or error})") from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise HistoryError(f"{path}: the history's lock is not a regular file; refused")
    return fd


@contextlib.contextmanager
def history_lock(history, *, shared: bool = False, timeout_s: float | None = None) -> Iterator[None]:
    """Hold the history's lock: exclusive to change it, shared to read it.

    The lock is the operating system's lock (``flock``) of ``DIR/.lock``, held by the open file: a process
    that dies releases it, so a killed run leaves no stale lock. A process holds it once (taking it again
    from the same process, on another open file, would wait for itself).

    Parameters
    ----------
    history : path-like
        History directory (an exclusive lock creates it).
    shared : bool, default False
        A reader's lock (many at once, no writer meanwhile).
    timeout_s : float, optional
        Longest wait [s]; default :data:`LOCK_TIMEOUT_S`.

    Raises
    ------
    HistoryError
        When the lock is not free within the wait, or its file is not a regular file.
    """
    root = Path(history)
    if shared and not root.is_dir():
        yield
        return
    if not shared:
        root.mkdir(parents=True, exist_ok=True)
    fd = _open_lock(root, shared)
    if fd is None:
        yield
        return
    try:
        deadline = time.monotonic() + (LOCK_TIMEOUT_S if timeout_s is None else timeout_s)
        pause = 0.005
        while not _try_lock(fd, shared):
            if time.monotonic() >= deadline:
                raise HistoryError(f"{root}: the history is locked by another greybox run (its lock {LOCK_NAME}); "
                                   "try again when it has finished")
            time.sleep(pause)
            pause = min(2 * pause, 0.2)
        try:
            yield
        finally:
            _unlock(fd)
    finally:
        os.close(fd)


# -- the tree: only the history's own directories and regular files ------------------------------------------


def _refuse(path: str, entry: os.DirEntry | None = None) -> HistoryError:
    what = "a symbolic link" if entry is not None and entry.is_symlink() else "not a regular file or directory"
    return HistoryError(f"{path}: {what} in the history; refused (the history holds only its own directories "
                        "and files)")


def _listing(directory: str, prefix: str, want_dir: bool) -> list[os.DirEntry]:
    """The entries of ``directory`` named ``prefix...``, sorted; a link or an entry of the wrong kind refused."""
    found = []
    with os.scandir(directory) as entries:
        for entry in entries:
            if not entry.name.startswith(prefix) or entry.name.startswith("."):
                continue
            if entry.is_symlink() or not (entry.is_dir(follow_symlinks=False) if want_dir
                                          else entry.is_file(follow_symlinks=False)):
                raise _refuse(entry.path, entry)
            found.append(entry)
    return sorted(found, key=lambda entry: entry.name)


def _scan(root: Path, machine: str | None = None, axis: str | None = None) -> list[tuple[Path, list[Path],
                                                                                           Path | None]]:
    """Per machine and axis directory: its row files and its compacted file (None if none), links refused."""
    if not root.is_dir():
        return []
    layout = []
    for machine_dir in _listing(str(root), f"machine={machine}" if machine else "machine=", True):
        if machine and machine_dir.name != f"machine={machine}":
            continue
        for axis_dir in _listing(machine_dir.path, f"axis={axis}" if axis else "axis=", True):
            if axis and axis_dir.name != f"axis={axis}":
                continue
            rows: list[Path] = []
            compacted = None
            with os.scandir(axis_dir.path) as entries:
                names = sorted(entries, key=lambda entry: entry.name)
            for entry in names:
                if entry.name == COMPACTED_NAME:
                    if entry.is_symlink() or not entry.is_file(follow_symlinks=False):
                        raise _refuse(entry.path, entry)
                    compacted = Path(entry.path)
                elif entry.name.startswith("date="):
                    if entry.is_symlink() or not entry.is_dir(follow_symlinks=False):
                        raise _refuse(entry.path, entry)
                    rows += [Path(item.path) for item in _listing(entry.path, "", False)
                             if item.name.endswith(".parquet")]
            layout.append((Path(axis_dir.path), rows, compacted))
    return layout


def check_history(history) -> list[Path]:
    """Every Parquet file of the history, after checking that none is a link or not a regular file.

    Parameters
    ----------
    history : path-like
        History directory.

    Raises
    ------
    HistoryError
        If ``history`` is a file, or a link, FIFO or other non-regular entry sits where the history keeps
        its directories and files.
    """
    root = Path(history)
    if root.exists() and not root.is_dir():
        raise HistoryError(f"{root}: history is a file, not a directory")
    return [path for _, rows, compacted in _scan(root) for path in rows + ([compacted] if compacted else [])]


def _make_dirs(root: Path, target: Path) -> None:
    """Create the directories from ``root`` down to ``target``, refusing any that is a link or not a directory."""
    current = root
    for part in target.relative_to(root).parts:
        current = current / part
        try:
            info = os.lstat(current)
        except FileNotFoundError:
            os.mkdir(current)
            continue
        if not stat.S_ISDIR(info.st_mode):
            raise HistoryError(f"{current}: {'a symbolic link' if stat.S_ISLNK(info.st_mode) else 'not a directory'} "
                               "in the history; refused (the history holds only its own directories and files)")


# -- reading a file: checked from its footer first ------------------------------------------------------------


def _open_regular(path: Path):
    """``path`` opened for reading without following a link or waiting on a FIFO; refused unless a regular file."""
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(path, flags)
    except OSError as error:
        if os.path.islink(path):
            raise HistoryError(f"{path}: a symbolic link in the history; refused (the history holds only its own "
                               "directories and files)") from None
        raise HistoryError(f"{path}: cannot open the history file ({error.strerror or error})") from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise _refuse(str(path))
    return os.fdopen(fd, "rb")


def _check_footer(path: Path, parquet: pq.ParquetFile, names: list[str], one_row: bool) -> None:
    """Refuse a file whose schema or sizes, as its footer states them, are not those of a history file."""
    schema = parquet.schema_arrow
    version = schema.metadata and schema.metadata.get(b"greybox.monitor.schema_version")
    if version != str(SCHEMA_VERSION).encode():
        found = version.decode("utf-8", "replace") if version else "none"
        raise HistoryError(f"{path}: history schema version {found}; this greybox reads version {SCHEMA_VERSION}")
    missing = [name for name in SCHEMA.names if name not in schema.names]
    if missing:
        raise HistoryError(f"{path}: history file lacks the columns {', '.join(missing)}")
    for name in names:
        if schema.field(name).type != SCHEMA.field(name).type:
            raise HistoryError(f"{path}: history column {name} is of type {schema.field(name).type}, not "
                               f"{SCHEMA.field(name).type}")
    metadata = parquet.metadata
    rows = metadata.num_rows
    if rows < 0 or rows > MAX_ROWS or (one_row and rows != 1):
        raise HistoryError(f"{path}: history file of {rows} rows (a row file holds 1, a compacted file at most "
                           f"{MAX_ROWS})")
    for group in range(metadata.num_row_groups):
        for index in range(metadata.num_columns):
            column = metadata.row_group(group).column(index)
            top = column.path_in_schema.split(".")[0]
            most = rows * (MAX_MAP_BINS + 1) if isinstance(SCHEMA.field(top).type, pa.ListType) else rows
            if column.num_values > most:
                raise HistoryError(f"{path}: history column {top} claims {column.num_values} values in {rows} "
                                   f"rows (at most {most}); refused before reading it")


def _read_row_file(path: Path, columns=None, *, one_row: bool = False) -> pa.Table:
    """The rows of one history file (only ``columns``, in the schema's order, if given), checked."""
    names = SCHEMA.names if columns is None else [name for name in SCHEMA.names if name in columns]
    with _open_regular(path) as stream:
        try:
            parquet = pq.ParquetFile(stream)
            _check_footer(path, parquet, names, one_row)
            table = parquet.read(columns=names)
            table = table.cast(pa.schema([SCHEMA.field(name) for name in names], metadata=SCHEMA.metadata))
        except (pa.ArrowException, OSError, ValueError, KeyError) as error:
            raise HistoryError(f"{path}: not a readable Parquet file of the fingerprint history "
                               f"({str(error).splitlines()[0] if str(error) else type(error).__name__})") from None
        except MemoryError:
            raise HistoryError(f"{path}: history file too large to read into memory; refused") from None
    return table


# -- queries and changes ------------------------------------------------------------------------------------


def _row_files_of(root: Path, sha256: str) -> list[Path]:
    return [path for _, rows, _ in _scan(root) for path in rows if path.name == f"{sha256}.parquet"]


def has_log(history, sha256: str) -> Path | None:
    """The history's row file of the log with this SHA-256, if there is one.

    Parameters
    ----------
    history : path-like
        History directory (need not exist).
    sha256 : str
        SHA-256 [hex] of the log file.
    """
    with history_lock(history, shared=True):
        return next(iter(_row_files_of(Path(history), sha256)), None)


def _find(root: Path, sha256: str) -> tuple[str, str, dt.date, Path] | None:
    found = next(iter(_row_files_of(root, sha256)), None)
    if found is not None:
        return (found.parts[-4][len("machine="):], found.parts[-3][len("axis="):],
                dt.date.fromisoformat(found.parts[-2][len("date="):]), found)
    for _, _, path in _scan(root):
        if path is None:
            continue
        table = _read_row_file(path, columns=("machine", "axis", "date", "log_sha256"))
        hits = [i for i, key in enumerate(table.column("log_sha256").to_pylist()) if key == sha256]
        if hits:
            return (table.column("machine")[hits[0]].as_py(), table.column("axis")[hits[0]].as_py(),
                    table.column("date")[hits[0]].as_py(), path)
    return None


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
    with history_lock(history, shared=True):
        return _find(Path(history), sha256)


def _forget(root: Path, sha256: str, keep: Path) -> None:
    """Remove the log's rows from everywhere in the history but ``keep`` (row files and compacted files)."""
    for path in _row_files_of(root, sha256):
        if path != keep:
            path.unlink()
            _remove_if_empty(path.parent)
    for _, _, compacted in _scan(root):
        if compacted is None or sha256 not in _read_row_file(compacted, columns=("log_sha256",)).column(
                "log_sha256").to_pylist():  # only the keys read; the whole file where the log is
            continue
        table = _read_row_file(compacted)
        keys = table.column("log_sha256").to_pylist()
        _write(compacted, table.filter(pa.array([key != sha256 for key in keys])))


def _remove_if_empty(directory: Path) -> None:
    with contextlib.suppress(OSError):  # not empty (or already gone): kept
        directory.rmdir()


def _write(path: Path, table: pa.Table) -> None:
    with atomic_output(path) as temporary:
        pq.write_table(table, temporary)


def append_fingerprint(history, *, machine: str, axis: str, date: dt.date, sha256: str, source: str,
                       n_samples: int, values: Mapping[str, float], lower: Mapping[str, float],
                       upper: Mapping[str, float], map_position_mm=(), map_excess_A=()) -> Path:
    """Write the fingerprint of one log to the history, removing its rows from anywhere else in it.

    Holds the history's exclusive lock (:func:`history_lock`) while it writes.

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
    row = {"schema_version": [SCHEMA_VERSION], "machine": [machine], "axis": [axis], "date": [date],
           "log_sha256": [sha256], "source": [str(source)], "n_samples": [int(n_samples)]}
    for name in FEATURES:
        row[name], row[f"{name}_lo"], row[f"{name}_hi"] = [values[name]], [lower[name]], [upper[name]]
    positions, excess = [float(p) for p in map_position_mm], [float(e) for e in map_excess_A]
    if len(positions) != len(excess):
        raise HistoryError(f"map of {len(positions)} positions and {len(excess)} values")
    if len(positions) > MAX_MAP_BINS:
        raise HistoryError(f"map of {len(positions)} bins; the history keeps at most {MAX_MAP_BINS}")
    row["map_position_mm"], row["map_excess_A"] = [positions], [excess]
    table = pa.Table.from_pydict(row, schema=SCHEMA)
    root = Path(history)
    with history_lock(root):
        _scan(root)  # a link or a FIFO in the history: refused before anything is written
        _make_dirs(root, path.parent)
        _write(path, table)
        _forget(root, sha256, keep=path)
    return path


def read_history(history, *, machine: str | None = None, axis: str | None = None,
                 since: dt.date | None = None) -> pa.Table:
    """All fingerprint rows of the history, sorted by machine, axis, date and log.

    Only the partitions that match ``machine``, ``axis`` and ``since`` are opened. Holds the history's lock
    shared (:func:`history_lock`): no compaction runs meanwhile.

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
        If ``history`` is not a directory, or a file in it is corrupt, of another schema version, too
        large for what it claims, a link or not a regular file.
    """
    root = Path(history)
    if root.exists() and not root.is_dir():
        raise HistoryError(f"{root}: history is a file, not a directory")
    with history_lock(root, shared=True):
        paths = [path for _, rows, compacted in _scan(root, machine, axis) for path in [*rows, compacted]
                 if path is not None and (since is None or path.name == COMPACTED_NAME
                                          or path.parent.name[len("date="):] >= since.isoformat())]
        tables = []
        for path in by_precedence(paths):
            rows = _read_row_file(path, one_row=path.name != COMPACTED_NAME)
            if since is not None and path.name == COMPACTED_NAME:
                rows = rows.filter(pa.array([d >= since for d in rows.column("date").to_pylist()], pa.bool_()))
            tables.append(rows)
    if not tables:
        return SCHEMA.empty_table()
    table = _first_per_log(pa.concat_tables(tables))
    return table.sort_by([("machine", "ascending"), ("axis", "ascending"), ("date", "ascending"),
                          ("log_sha256", "ascending")])


def by_precedence(paths) -> list[Path]:
    """The history's files in the order a log's row is taken from them: the first file holding it wins.

    A log's row file comes before every compacted file: a row file is the newer, written by a writer killed
    before it removed the log's older row from a compacted file (:func:`append_fingerprint`); files of one
    kind come by path. :func:`read_history` and :func:`compact_history` (in Python) and
    :func:`greybox.monitor.query.changed_most` (in SQL, by the position of a file in this list) both keep
    a log's row from its first file in this order.

    Parameters
    ----------
    paths : iterable of path-like
        Files of the history (:func:`check_history`).

    Returns
    -------
    list of Path
    """
    return sorted((Path(path) for path in paths), key=lambda path: (path.name == COMPACTED_NAME, str(path)))


def _first_per_log(table: pa.Table) -> pa.Table:
    """The first row of every log, the files read in :func:`by_precedence` order."""
    seen, keep = set(), []
    for key in table.column("log_sha256").to_pylist():
        keep.append(key not in seen)
        seen.add(key)
    return table if all(keep) else table.filter(pa.array(keep))


def _remove_temporaries(root: Path) -> None:
    """Remove the hidden temporary files (``.*.tmp``) killed writers left in the history's directories."""
    for folder, subfolders, files in os.walk(root):
        subfolders[:] = [name for name in subfolders if not os.path.islink(os.path.join(folder, name))]
        if Path(folder) == root:
            continue  # the root's own (a fleet manifest being written) are not under the lock
        for name in files:
            if name.startswith(".") and name.endswith(".tmp"):
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(os.path.join(folder, name))


def compact_history(history) -> int:
    """Merge the row files of every machine and axis into one compacted file each, and remove them.

    Holds the history's exclusive lock (:func:`history_lock`); first removes the temporary files a killed
    writer left.

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
        If a file is corrupt, of another schema version, a link or not a regular file (nothing is removed
        then).
    """
    root = Path(history)
    if not root.is_dir():
        raise HistoryError(f"{root}: history is not a directory")
    merged = 0
    with history_lock(root):
        layout = _scan(root)
        _remove_temporaries(root)
        for axis_dir, files, target in layout:
            if not files:
                continue
            tables = [_read_row_file(path, one_row=path.name != COMPACTED_NAME)
                      for path in by_precedence([*files, *([target] if target is not None else [])])]
            table = _first_per_log(pa.concat_tables(tables)).sort_by([("date", "ascending"),
                                                                     ("log_sha256", "ascending")])
            _write(axis_dir / COMPACTED_NAME, table)
            for path in files:
                path.unlink()
                _remove_if_empty(path.parent)
            merged += len(files)
    return merged
