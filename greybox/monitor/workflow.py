"""``greybox monitor``: fingerprint logs into the history, detect changes, write the dashboard."""

from __future__ import annotations

import datetime as dt
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ..data.io import read_log
from ..data.prepare import prepare
from ..errors import GreyboxError, LogError
from ..provenance import file_sha256
from .cutting import uncut_samples
from .detect import ChangeDetector
from .fingerprint import FrictionFingerprint, spindle_idle_samples, unloaded_samples
from .history import append_fingerprint, compact_history, find_log, read_history, row_path
from .report import write_report

__all__ = ["DuplicateLogError", "MonitorResult", "finish_run", "fingerprint_file", "log_date", "run_monitor",
           "start_run"]

#: Axis name of a log of one axis that names none, without ``--axis``.
DEFAULT_AXIS = "axis"

_DATE_IN_NAME = re.compile(r"(\d{4}-\d{2}-\d{2})")


class DuplicateLogError(LogError):
    """A log whose bytes the history already holds under another day of the same machine and axis (a copy)."""


def log_date(log, path) -> dt.date:
    """The day of a log: its ``date`` attribute (ISO), else the first ``YYYY-MM-DD`` in its file name.

    The attribute is a day (``YYYY-MM-DD``) or an ISO date and time, nothing after it; the day is no later
    than the file was last written, nor than today (a day of slack for time zones).

    Parameters
    ----------
    log : AxisLog
        The log read from ``path``.
    path : path-like
        Its file.

    Raises
    ------
    LogError
        If neither gives a valid date, or the day lies after the file was written or after today.
    """
    text = log.attrs.get("date") if isinstance(log.attrs, dict) else None
    found = _DATE_IN_NAME.search(Path(path).name)
    text = text or (found.group(1) if found else None)
    if not text:
        raise LogError(path, "no date: the log has no 'date' attribute and its name no YYYY-MM-DD")
    try:
        day = dt.datetime.fromisoformat(str(text).strip()).date()
    except ValueError:
        raise LogError(path, f"date {text!r} is not a valid YYYY-MM-DD day (or ISO date and time)") from None
    written = dt.datetime.fromtimestamp(Path(path).stat().st_mtime, dt.timezone.utc).date()
    latest = min(written, dt.datetime.now(dt.timezone.utc).date()) + dt.timedelta(days=1)
    if day > latest:
        raise LogError(path, f"date {day.isoformat()} lies after the file was written ({written.isoformat()}) or "
                             "after today; give the day the log was recorded")
    return day


def _read_axis(path, axis: str | None):
    """The log of ``axis`` in ``path``; a file of one axis without an axis name is that axis (``--axis`` names it)."""
    if axis is None:
        return read_log(path)
    try:
        return read_log(path, axis=axis)
    except LogError as error:
        try:
            log = read_log(path)
        except GreyboxError:
            raise error from None
        if log.axis not in (None, "", axis):
            raise error from None
        return log


def fingerprint_file(path, history, *, machine: str | None = None, axis: str | None = None, model=None,
                     spindle_column: str | None = None, find_cuts: bool = False,
                     fingerprint: FrictionFingerprint | None = None) -> tuple[Path, bool]:
    """Fingerprint one log file into the history, unless the same file is there already.

    Parameters
    ----------
    path : path-like
        Log file (any supported format), motor current in A.
    history : path-like
        History directory.
    machine : str, optional
        Machine name; default the log's ``machine`` attribute.
    axis : str, optional
        Axis to read from a file of several axes, and its name; a file of one axis is read whole under this
        name. Default the log's own axis, else :data:`DEFAULT_AXIS`.
    model : estimator, optional
        Reference model of the axis: only the samples where its residual stays within its noise are fitted
        (:func:`~greybox.monitor.fingerprint.unloaded_samples`); without it (and without ``spindle_column``)
        the whole log is taken as an air cut.
    spindle_column : str, optional
        Column of the log with the spindle load: only the samples where the spindle idles are fitted
        (:func:`~greybox.monitor.fingerprint.spindle_idle_samples`); with ``model`` too, only those both keep.
    find_cuts : bool, default False
        Production logs without a spindle-load column: only the samples where the current follows a
        friction model learned from the log's fastest moves are fitted
        (:func:`~greybox.monitor.cutting.uncut_samples`); with ``model`` or ``spindle_column``, only those all
        keep.
    fingerprint : FrictionFingerprint, optional
        Settings of the fit; default :class:`FrictionFingerprint()`.

    Returns
    -------
    (Path, bool)
        The history file of the log's row, and whether it was fitted now (False: already in the history).

    Raises
    ------
    DuplicateLogError
        If the history holds the same bytes under another day of the same machine and axis: a copy of one
        log under two dates is filed once, under the first day filed.
    """
    if Path(path).is_file():  # a log already in the history under the machine and axis asked for: not read again
        known = find_log(history, file_sha256(path))
        named = _DATE_IN_NAME.search(Path(path).name)
        if known is not None and machine in (None, known[0]) and axis in (None, known[1]) \
                and (named is None or named.group(1) == known[2].isoformat()):
            return known[3], False
    log = _read_axis(path, axis)
    machine = machine or (log.attrs.get("machine") if isinstance(log.attrs, dict) else None)
    if not machine:
        raise LogError(path, "no machine name: the log has no 'machine' attribute; give --machine")
    name = axis or log.axis or DEFAULT_AXIS
    if log.effort_unit != "A":
        raise LogError(path, f"effort in {log.effort_unit}: fingerprints are of motor current in A")
    date = log_date(log, path)
    sha = file_sha256(path)
    row_path(history, str(machine), str(name), date, sha)  # refuses names unusable in the history before any fit
    known = find_log(history, sha)
    if known is not None and known[:3] == (str(machine), str(name), date):
        return known[3], False
    if known is not None and known[:2] == (str(machine), str(name)):
        raise DuplicateLogError(path, f"the same bytes as the log of {machine}/{name} filed under "
                                      f"{known[2].isoformat()}: a copy, not filed again under {date.isoformat()}")
    if spindle_column is not None and spindle_column not in log.extras:
        raise LogError(path, f"no spindle-load column {spindle_column!r}; the log has "
                             f"{', '.join(sorted(log.extras)) or 'no extra columns'}")
    runs = prepare(log)
    unloaded = None
    if model is not None or spindle_column is not None or find_cuts:
        unloaded = []
        for run in runs:
            keep = np.ones(len(run), dtype=bool)
            if model is not None:
                keep &= unloaded_samples(run.effort - model.predict(run))
            if spindle_column is not None:
                keep &= spindle_idle_samples(run.extras[spindle_column])
            if find_cuts:
                keep &= uncut_samples(run.velocity, run.acceleration, run.effort)
            unloaded.append(keep)
    fitted = (fingerprint or FrictionFingerprint()).fit(runs, unloaded=unloaded)
    written = append_fingerprint(history, machine=str(machine), axis=str(name), date=date, sha256=sha,
                                 source=Path(path).name, n_samples=fitted.n_samples_, values=fitted.values_,
                                 lower=fitted.lower_, upper=fitted.upper_,
                                 map_position_mm=fitted.map_position_mm_, map_excess_A=fitted.map_excess_A_)
    return written, True


@dataclass
class MonitorResult:
    """What ``greybox monitor`` did.

    Parameters
    ----------
    fitted : int
        Logs fingerprinted now.
    known : int
        Logs already in the history (not fitted again).
    detector : ChangeDetector
        The detector fitted on the whole history.
    page : Path
        The dashboard written.
    duplicates : list of str
        One line per log not filed because the history holds the same bytes under another day
        (:class:`DuplicateLogError`).
    """

    fitted: int
    known: int
    detector: ChangeDetector
    page: Path
    duplicates: list = field(default_factory=list)


def start_run(history, out_dir, *, baseline_days: int = 28, force: bool = False) -> ChangeDetector:
    """Refuse the options and outputs of a run of ``greybox monitor`` before any work; its change detector.

    Parameters
    ----------
    history : path-like
        History directory (created if missing).
    out_dir : path-like
        Directory of the dashboard ``index.html``.
    baseline_days : int, default 28
        Days that set each feature's baseline.
    force : bool, default False
        Replace the dashboard of an earlier run in ``out_dir``; otherwise it is an error.

    Returns
    -------
    ChangeDetector
        Not fitted yet.
    """
    page = Path(out_dir) / "index.html"
    if page.exists() and not force:
        raise GreyboxError(f"{page}: exists; give --force to replace the dashboard (or another --out)")
    detector = ChangeDetector(baseline_days=baseline_days)
    detector._check_params()  # refuse bad options before any work
    if Path(history).exists() and not Path(history).is_dir():
        raise GreyboxError(f"{history}: history is a file, not a directory")
    return detector


def finish_run(history, out_dir, detector: ChangeDetector, *, fitted: int = 0, known: int = 0,
               duplicates: Sequence[str] = ()) -> MonitorResult:
    """Compact the history, detect changes over all of it and write the dashboard: the end of every run.

    The history is compacted (:func:`~greybox.monitor.history.compact_history`) after the logs are filed:
    every machine and axis keeps one file, which its query (:func:`~greybox.monitor.query.changed_most`)
    reads quickly. Compacting is atomic per axis and idempotent.

    Parameters
    ----------
    history : path-like
        History directory.
    out_dir : path-like
        Directory of the dashboard ``index.html``.
    detector : ChangeDetector
        Of :func:`start_run`; fitted here on the whole history.
    fitted, known : int, default 0
        Logs fingerprinted now, and logs already in the history.
    duplicates : sequence of str, default ()
        One line per log not filed because the history holds the same bytes under another day.

    Returns
    -------
    MonitorResult
    """
    if Path(history).is_dir():
        compact_history(history)  # one file per machine and axis: the history stays quick to query
    table = read_history(history)
    if table.num_rows == 0:
        raise GreyboxError(f"{history}: the history holds no fingerprints; give logs to fingerprint")
    detector.fit(table)
    page = write_report(detector, out_dir)
    return MonitorResult(fitted, known, detector, page, list(duplicates))


def run_monitor(logs: Sequence, history, out_dir, *, machine: str | None = None, axis: str | None = None,
                model_path=None, spindle_column: str | None = None, find_cuts: bool = False,
                baseline_days: int = 28, progress: Callable[[str], None] | None = None,
                force: bool = False) -> MonitorResult:
    """Fingerprint ``logs`` into ``history`` one after the other, then detect changes and write the dashboard.

    The logs are fingerprinted in this process; :func:`greybox.fleet.monitor.monitor_fleet` fingerprints them
    on a Dask cluster instead. Both end in :func:`finish_run`: the history compacted, the change detection
    fitted on all of it, the dashboard written.

    Parameters
    ----------
    logs : sequence of path-like
        Log files (may be empty: then only the history is analysed).
    history : path-like
        History directory (created if missing).
    out_dir : path-like
        Directory of the dashboard ``index.html``.
    machine : str, optional
        Machine name of every log; default each log's ``machine`` attribute.
    axis : str, optional
        Axis to read from files of several axes.
    model_path : path-like, optional
        Reference model file (``greybox train``) to find the stretches without process load.
    spindle_column : str, optional
        Column of the logs with the spindle load, to find the stretches without process load.
    find_cuts : bool, default False
        Production logs without a spindle-load column: find the stretches without process load from the
        current (:func:`~greybox.monitor.cutting.uncut_samples`).
    baseline_days : int, default 28
        Days that set each feature's baseline.
    progress : callable, optional
        Called with one line per log.
    force : bool, default False
        Replace the dashboard of an earlier run in ``out_dir``; otherwise it is an error, before any work.

    Returns
    -------
    MonitorResult
    """
    detector = start_run(history, out_dir, baseline_days=baseline_days, force=force)
    fitted = known = 0
    duplicates = []
    model = None
    if model_path is not None and logs:
        from ..models.files import load_model

        model = load_model(model_path)
    for path in logs:
        try:
            row, new = fingerprint_file(path, history, machine=machine, axis=axis, model=model,
                                        spindle_column=spindle_column, find_cuts=find_cuts)
        except DuplicateLogError as copy:
            duplicates.append(str(copy))
            continue
        fitted, known = fitted + new, known + (not new)
        if progress is not None:
            progress(f"{path}: {'fingerprinted' if new else 'already in the history'} -> {row}")
    return finish_run(history, out_dir, detector, fitted=fitted, known=known, duplicates=duplicates)
