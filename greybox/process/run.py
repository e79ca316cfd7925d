"""The two workflows behind ``greybox process``: teach an envelope from good parts, check parts against it."""

from __future__ import annotations

import time
from os import PathLike
from pathlib import Path
from typing import Callable, Mapping, NamedTuple, Sequence

from ..atomic import check_output_path
from ..errors import GreyboxError
from .check import check_part
from .envelope import Envelope
from .parts import PartSignal
from .report import write_report

__all__ = ["Checked", "teach_logs", "check_logs"]


class Checked(NamedTuple):
    """What :func:`check_logs` did.

    Attributes
    ----------
    checks : list of PartCheck
        One per part, in order.
    written : list of pathlib.Path
        The report's files.
    log_s : float
        Length [s] of the parts checked.
    elapsed_s : float
        Wall time [s] of reading, computing the signal and checking (the report not included).
    """

    checks: list
    written: list
    log_s: float
    elapsed_s: float


def teach_logs(logs: Sequence[str | PathLike], out: str | PathLike, *, model: str | None = None,
               axis_config: str | None = None, read: Mapping | None = None, min_rest_s: float = 2.0,
               force: bool = False, progress: Callable[[str], None] | None = None, **settings) -> Envelope:
    """Learn an envelope from the good parts in ``logs`` and write it.

    Parameters
    ----------
    logs : sequence of str or path-like
        Logs of good parts: one part each, or series (:class:`~greybox.process.parts.PartSignal`).
    out : str or path-like
        The envelope file (JSON) to write.
    model : str, optional
        Model file; without it the envelope watches the raw current.
    axis_config : str, optional
        Axis file: the model's process force instead of its process current.
    read : mapping, optional
        Options of reading and preparing the logs.
    min_rest_s : float, default 2.0
        Shortest rest [s] between the parts of a log without a part counter.
    force : bool, default False
        Replace an existing envelope file (never an input).
    progress : callable, optional
        Called with one line per log read.
    **settings
        :class:`~greybox.process.envelope.Envelope` settings (false_alarm_rate, smoothing_s, max_shift_s,
        relevel, cut_share).

    Raises
    ------
    GreyboxError
        For bad settings, logs, model or axis files, or an output that must not be written.
    """
    inputs = [*logs, *([model] if model else []), *([axis_config] if axis_config else [])]
    check_output_path(out, overwrite=force, protect=inputs)
    source = PartSignal(model=model, axis_config=axis_config, read=read, min_rest_s=min_rest_s)
    parts, units = [], set()
    for log in logs:
        found, unit = source.parts(str(log))
        parts += found
        units.add(unit)
        if progress:
            progress(f"{Path(log).name}: {len(found)} part(s)")
    if len(units) > 1:
        raise GreyboxError(f"the logs give the signal in different units ({', '.join(sorted(units))})")
    envelope = Envelope(**settings).fit(parts, unit=units.pop(), signal=source.describe())
    envelope.save(out)
    return envelope


def check_logs(envelope_path: str | PathLike, logs: Sequence[str | PathLike], out: str | PathLike, *,
               model: str | None = None, axis_config: str | None = None, figures: int = 3,
               force: bool = False, progress: Callable[[str], None] | None = None) -> Checked:
    """Check every part of ``logs`` against an envelope and write the report into the directory ``out``.

    Parameters
    ----------
    envelope_path : str or path-like
        Envelope file (``greybox process teach``).
    logs : sequence of str or path-like
        Logs to check: one part each, or series.
    out : str or path-like
        Report directory (:func:`~greybox.process.report.write_report`).
    model : str, optional
        Model file, when it moved since the teach-in (default the envelope's; it must be the same file by its
        SHA-256).
    axis_config : str, optional
        Axis file, likewise.
    figures : int, default 3
        Largest number of part figures.
    force : bool, default False
        Write into a report directory that holds files.
    progress : callable, optional
        Called with one line per log checked.

    Raises
    ------
    GreyboxError
        For a bad envelope, logs or model, another model than the teach-in's, or a report directory that
        holds files without ``force``.
    """
    envelope = Envelope.load(envelope_path)
    described = envelope.signal_
    target = Path(out)
    if target.exists() and not target.is_dir():
        raise GreyboxError(f"{target}: is a file, not a report directory")
    if target.is_dir() and any(target.iterdir()) and not force:
        raise GreyboxError(f"{target}: directory is not empty; pass --force to write the report into it")
    model = model or described.get("model")
    axis_config = axis_config or described.get("axis_config")
    source = PartSignal(model=model, axis_config=axis_config, read=described.get("read"),
                        min_rest_s=float(described.get("min_rest_s", 2.0)))
    if source.kind != described.get("kind"):
        raise GreyboxError(f"{Path(envelope_path).name}: taught on the {described.get('kind')} signal; "
                           f"the check would compute the {source.kind} signal")
    if model and source.describe()["model_sha256"] != described.get("model_sha256"):
        raise GreyboxError(f"{Path(model).name}: not the model file the envelope was taught with (SHA-256 differs)")
    started = time.perf_counter()
    checks, log_s = [], 0.0
    for log in logs:
        parts, unit = source.parts(str(log))
        if unit != envelope.unit_:
            raise GreyboxError(f"{Path(log).name}: signal in {unit}, the envelope's in {envelope.unit_}")
        found = [check_part(envelope, part) for part in parts]
        checks += found
        log_s += sum(float(part.time[-1]) for part in parts)
        if progress:
            progress(f"{Path(log).name}: {len(found)} part(s), {sum(c.flagged for c in found)} flagged")
    elapsed = time.perf_counter() - started
    written = write_report(envelope, checks, target, figures=figures)
    return Checked(checks, written, log_s, elapsed)
