"""Questions to the fingerprint history, answered by DuckDB over its Parquet files.

:func:`changed_most` answers "which axes changed most this month": per machine, axis and feature the mean
of the last ``days`` days (up to the history's latest day, or ``until``) against the baseline (the first
``baseline_days`` days of that axis with a fingerprint, mean and sample standard deviation, as the change
detector takes it), in baseline standard deviations; per axis the feature with the largest absolute change.
Every Parquet file of the history is read (row files and compacted files, a log's row taken from its first
file in :func:`~greybox.monitor.history.by_precedence` order, as :func:`~greybox.monitor.history.read_history`
takes it: :func:`load_rows`); a history of one file per
log is slow to read (milliseconds per file): ``greybox monitor`` compacts the history
(:func:`~greybox.monitor.history.compact_history`) after filing its logs.
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import pyarrow as pa

from ..errors import ParameterError
from .fingerprint import FEATURES
from .history import COMPACTED_NAME, SCHEMA_VERSION, HistoryError, by_precedence, check_history, history_lock

__all__ = ["changed_most", "load_rows"]


def _sql_text(value: str) -> str:
    return "'" + str(value).replace("'", "''") + "'"


def changed_most(history, *, days: int = 30, until: dt.date | None = None, baseline_days: int = 28,
                 limit: int = 10, features=None) -> pa.Table:
    """The axes whose fingerprint changed most over the last ``days`` days, most changed first.

    Parameters
    ----------
    history : path-like
        History directory (:mod:`greybox.monitor.history`); every ``*.parquet`` file under it is read.
    days : int, default 30
        Length [days] of the recent period, ending on ``until``.
    until : datetime.date, optional
        Last day of the recent period; default the history's latest day.
    baseline_days : int, default 28
        First days of each axis (with a fingerprint) that set the baseline; at least 2.
    limit : int, default 10
        Axes returned (at least 1).
    features : sequence of str, optional
        Features compared; all of :data:`~greybox.monitor.fingerprint.FEATURES` by default.

    Returns
    -------
    pyarrow.Table
        Columns ``machine``, ``axis``, ``feature`` (the most changed), ``change_sd`` (its change in baseline
        standard deviations, signed), ``recent`` and ``baseline`` (the two means, in the feature's unit),
        ``recent_days`` (days with a fingerprint in the period); sorted by ``|change_sd|``, largest first.

    Raises
    ------
    ParameterError
        For bad options.
    HistoryError
        If the history is not a directory or holds no Parquet file.
    """

    chosen = tuple(FEATURES if features is None else features)
    unknown = [f for f in chosen if f not in FEATURES]
    if unknown or not chosen:
        raise ParameterError(f"unknown features {', '.join(unknown) or '(none given)'}; choose from "
                             f"{', '.join(FEATURES)}")
    for name, value, low in (("days", days, 1), ("baseline_days", baseline_days, 2), ("limit", limit, 1)):
        if isinstance(value, bool) or not isinstance(value, int) or value < low:
            raise ParameterError(f"{name} must be a whole number of at least {low}, got {value!r}")
    root = Path(history)
    if not root.is_dir():
        raise HistoryError(f"{root}: history is not a directory")
    with history_lock(root, shared=True):  # no compaction meanwhile
        return _query(root, check_history(root), chosen, days, until, baseline_days, limit)


def _query(root: Path, paths: list, chosen: tuple, days: int, until: dt.date | None, baseline_days: int,
           limit: int) -> pa.Table:
    """:func:`changed_most` on the history's checked files ``paths``."""
    import duckdb

    if not paths:
        raise HistoryError(f"{root}: the history holds no fingerprints")
    columns = ", ".join(f'avg("{f}") AS "{f}"' for f in chosen)
    names = ", ".join(f'"{f}"' for f in chosen)
    end = "(SELECT max(date) FROM daily)" if until is None else f"DATE {_sql_text(until.isoformat())}"
    query = f"""
        WITH daily AS (
            SELECT machine, axis, date, {columns}
            FROM rows GROUP BY machine, axis, date),
        numbered AS (
            SELECT *, dense_rank() OVER (PARTITION BY machine, axis ORDER BY date) AS day_number FROM daily),
        kept AS (
            SELECT * FROM numbered
            WHERE day_number <= {int(baseline_days)} OR (date > {end} - INTERVAL {int(days)} DAY AND date <= {end})),
        long AS (UNPIVOT kept ON {names} INTO NAME feature VALUE value),
        base AS (
            SELECT machine, axis, feature, avg(value) AS mean, stddev_samp(value) AS sd
            FROM long WHERE day_number <= {int(baseline_days)} AND isfinite(value)
            GROUP BY machine, axis, feature),
        recent AS (
            SELECT machine, axis, feature, avg(value) AS mean, count(*) AS n
            FROM long WHERE date > {end} - INTERVAL {int(days)} DAY AND date <= {end} AND isfinite(value)
            GROUP BY machine, axis, feature),
        change AS (
            SELECT r.machine, r.axis, r.feature, (r.mean - b.mean) / b.sd AS change_sd, r.mean AS recent,
                   b.mean AS baseline, r.n AS recent_days
            FROM recent r JOIN base b USING (machine, axis, feature)
            WHERE b.sd > 0)
        SELECT * FROM (
            SELECT machine, axis, arg_max(feature, abs(change_sd)) AS feature,
                   arg_max(change_sd, abs(change_sd)) AS change_sd, arg_max(recent, abs(change_sd)) AS recent,
                   arg_max(baseline, abs(change_sd)) AS baseline, max(recent_days) AS recent_days
            FROM change GROUP BY machine, axis)
        ORDER BY abs(change_sd) DESC, machine, axis
        LIMIT {int(limit)}"""
    with duckdb.connect() as connection:
        connection.execute("SET threads TO 1")
        try:
            load_rows(connection, root, paths, ["machine", "axis", "date", *chosen])
            relation = connection.sql(query)
            to_table = getattr(relation, "to_arrow_table", None) or relation.arrow  # DuckDB 2 / DuckDB 1
            return to_table()
        except duckdb.Error as error:
            raise HistoryError(f"{root}: not a readable fingerprint history ({str(error).splitlines()[0]})") from None


def load_rows(connection, root: Path, paths, columns) -> None:
    """Create the temporary table ``rows`` of the history's files: a log's row from its first file in
    :func:`~greybox.monitor.history.by_precedence` order, the rule :func:`~greybox.monitor.history.read_history`
    follows.

    Parameters
    ----------
    connection : duckdb.DuckDBPyConnection
        The connection the table is created in.
    root : Path
        The history directory, named in the messages.
    paths : sequence of Path
        The history's files (:func:`~greybox.monitor.history.check_history`).
    columns : sequence of str
        Columns of the table besides ``schema_version`` and ``log_sha256`` (each file is read once, only
        these columns).

    Raises
    ------
    HistoryError
        For rows of another schema version.
    """
    ordered = by_precedence(paths)
    files = "[" + ", ".join(_sql_text(str(path)) for path in ordered) + "]"
    needed = ", ".join(f'"{name}"' for name in dict.fromkeys(["schema_version", "log_sha256", *columns]))
    # a history of compacted files only (as greybox monitor leaves it) holds every log once: nothing to choose
    choose = any(path.name != COMPACTED_NAME for path in ordered)
    unique = (f"QUALIFY row_number() OVER (PARTITION BY log_sha256 ORDER BY list_position({files}, filename)) = 1"
              if choose else "")
    connection.execute(f"""
        CREATE TEMP TABLE rows AS
        SELECT {needed}
        FROM read_parquet({files}, hive_partitioning = false, union_by_name = false, filename = {str(choose).lower()})
        {unique}""")
    versions = connection.execute("SELECT DISTINCT schema_version FROM rows").fetchall()
    if sorted(v for (v,) in versions) != [SCHEMA_VERSION]:
        found = ", ".join(str(v) for (v,) in versions)
        raise HistoryError(f"{root}: history rows of schema version {found}; this greybox reads version "
                           f"{SCHEMA_VERSION}")
