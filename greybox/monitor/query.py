"""Questions to the fingerprint history, answered by DuckDB over its Parquet files.

:func:`changed_most` answers "which axes changed most this month": per machine, axis and feature the mean
of the last ``days`` days (up to the history's latest day, or ``until``) against the baseline (the first
``baseline_days`` days of that axis with a fingerprint, mean and sample standard deviation, as the change
detector takes it), in baseline standard deviations; per axis the feature with the largest absolute change.
Every Parquet file of the history is read (row files and compacted files, a log's row file winning over its
row in a compacted file, as :func:`~greybox.monitor.history.read_history` does); a history of one file per
log is slow to read (milliseconds per file): ``greybox monitor`` compacts the history
(:func:`~greybox.monitor.history.compact_history`) after filing its logs.
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import pyarrow as pa

from ..errors import ParameterError
from .fingerprint import FEATURES
from .history import COMPACTED_NAME, SCHEMA_VERSION, HistoryError, check_history, history_lock

__all__ = ["changed_most"]


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
    files = "[" + ", ".join(_sql_text(str(path)) for path in paths) + "]"
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
    needed = ", ".join(["schema_version", "machine", "axis", "date", "log_sha256", *(f'"{f}"' for f in chosen)])
    with duckdb.connect() as connection:
        connection.execute("SET threads TO 1")
        # the files are read once, only the columns needed; a log's row file wins over a compacted row (a
        # history of compacted files only, as greybox monitor leaves it, holds every log once)
        row_files = any(path.name != COMPACTED_NAME for path in paths)
        unique = (f"QUALIFY row_number() OVER (PARTITION BY log_sha256 ORDER BY filename LIKE '%{COMPACTED_NAME}', "
                  f"filename) = 1") if row_files else ""
        try:
            connection.execute(f"""
                CREATE TEMP TABLE rows AS
                SELECT {needed}
                FROM read_parquet({files}, hive_partitioning = false, union_by_name = false,
                                  filename = {str(row_files).lower()})
                {unique}""")
            versions = connection.execute("SELECT DISTINCT schema_version FROM rows").fetchall()
            if sorted(v for (v,) in versions) != [SCHEMA_VERSION]:
                found = ", ".join(str(v) for (v,) in versions)
                raise HistoryError(f"{root}: history rows of schema version {found}; this greybox reads "
                                   f"version {SCHEMA_VERSION}")
            relation = connection.sql(query)
            to_table = getattr(relation, "to_arrow_table", None) or relation.arrow  # DuckDB 2 / DuckDB 1
            return to_table()
        except duckdb.Error as error:
            raise HistoryError(f"{root}: not a readable fingerprint history ({str(error).splitlines()[0]})") from None
