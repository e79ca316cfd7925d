"""The check's report: a table of the parts, a table of the stretches, the whole as JSON, figures.

``parts.csv`` has one row per part (file, number, start, shift, flagged, kinds, ``D`` and its limit, mean cut
load, stretches); ``stretches.csv`` one row per stretch (part, kind, start and end [s] since the part's first
sample, peak in band half-widths, mean load deviation); ``report.json`` both with the envelope's settings;
``part_<file>_<NNN>.png`` the part's signal over the envelope, for the flagged parts (the worst first, at most
``figures``) or, when none is flagged, the first part; ``report.html`` the tables and those parts as interactive
charts (:mod:`greybox.process.html`).
"""

from __future__ import annotations

import csv
import io
import json
import re
from os import PathLike
from pathlib import Path
from typing import Sequence

import numpy as np

from ..atomic import write_text_atomic
from ..evaluate.plots import finish_figure, import_pyplot, legend_outside
from ..json_values import jsonable
from .html import write_html_report

__all__ = ["PART_FIELDS", "STRETCH_FIELDS", "part_rows", "stretch_rows", "plot_part", "write_report"]

#: Columns of ``parts.csv``.
PART_FIELDS = ("file", "part", "start_s", "shift_s", "flagged", "kinds", "deviation", "deviation_limit",
               "cut_load", "stretches")
#: Columns of ``stretches.csv``.
STRETCH_FIELDS = ("file", "part", "kind", "start_s", "end_s", "peak", "deviation")


def part_rows(checks: Sequence) -> list[dict]:
    """One row per part check (:data:`PART_FIELDS`).

    Parameters
    ----------
    checks : sequence of PartCheck
        The checks.
    """
    return [{"file": Path(c.source).name, "part": c.number, "start_s": round(c.start_s, 3),
             "shift_s": round(c.shift_s, 3), "flagged": c.flagged, "kinds": ";".join(c.kinds),
             "deviation": c.deviation, "deviation_limit": c.deviation_limit, "cut_load": c.cut_load,
             "stretches": len(c.stretches)} for c in checks]


def stretch_rows(checks: Sequence) -> list[dict]:
    """One row per stretch (:data:`STRETCH_FIELDS`).

    Parameters
    ----------
    checks : sequence of PartCheck
        The checks.
    """
    return [{"file": Path(c.source).name, "part": c.number, "kind": s.kind, "start_s": round(s.start_s, 3),
             "end_s": round(s.end_s, 3), "peak": s.peak, "deviation": s.deviation}
            for c in checks for s in c.stretches]


def _csv(rows: list[dict], fields: Sequence[str]) -> str:
    stream = io.StringIO()
    writer = csv.DictWriter(stream, fieldnames=list(fields), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return stream.getvalue()


def plot_part(envelope, check, path: str | PathLike | None = None, *, title: str = ""):
    """Draw a part's signal over its envelope, the stretches outside shaded.

    Parameters
    ----------
    envelope : Envelope
        The envelope.
    check : PartCheck
        The part's check (its ``signal`` on the reference grid).
    path : path-like, optional
        Write the figure there and close it.
    title : str, default ""
        Title of the figure.

    Returns
    -------
    matplotlib.figure.Figure or pathlib.Path
    """
    plt = import_pyplot(path)
    time = np.arange(envelope.centre_.size) * envelope.sample_time_
    figure, ax = plt.subplots(figsize=(10, 4), layout="constrained")
    ax.fill_between(time, envelope.centre_ - envelope.band_, envelope.centre_ + envelope.band_, color="0.85",
                    label="envelope")
    ax.plot(time, envelope.centre_, color="0.4", lw=0.8, label="taught centre")
    ax.plot(time, check.signal, color="tab:blue", lw=0.8, label=f"part {check.number}")
    for index, stretch in enumerate(check.stretches):
        ax.axvspan(stretch.start_s - check.shift_s, stretch.end_s - check.shift_s, color="tab:red", alpha=0.25,
                   label="outside" if index == 0 else None)
    unit = f" [{envelope.unit_}]" if envelope.unit_ else ""
    ax.set_xlabel("time along the reference part [s]")
    ax.set_ylabel(f"{envelope.signal_.get('kind', 'signal')}{unit}")
    ax.set_title(title or f"{Path(check.source).name}, part {check.number}: "
                 + (", ".join(check.kinds) if check.flagged else "inside"), fontsize="medium")
    legend_outside(ax)
    return finish_figure(figure, path)


def write_report(envelope, checks: Sequence, out_dir: str | PathLike, *, figures: int = 3) -> list[Path]:
    """Write the report of a check into ``out_dir`` (created if missing).

    Parameters
    ----------
    envelope : Envelope
        The envelope the parts were checked against.
    checks : sequence of PartCheck
        The checks, in order.
    out_dir : str or path-like
        Output directory.
    figures : int, default 3
        Largest number of part figures.

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    parts, stretches = part_rows(checks), stretch_rows(checks)
    written = [write_text_atomic(out / "parts.csv", _csv(parts, PART_FIELDS)),
               write_text_atomic(out / "stretches.csv", _csv(stretches, STRETCH_FIELDS))]
    summary = {"envelope": {**envelope.to_dict()["params"], "unit": envelope.unit_, "signal": envelope.signal_,
                            "teach_parts": envelope.n_parts_, "band_factor": envelope.band_factor_,
                            "deviation_limit": envelope.deviation_limit_},
               "parts_checked": len(checks), "parts_flagged": sum(c.flagged for c in checks),
               "parts": parts, "stretches": stretches}
    written.append(write_text_atomic(out / "report.json", json.dumps(jsonable(summary), indent=1) + "\n"))
    flagged = [c for c in checks if c.flagged]
    worst = sorted(flagged, key=lambda c: -max([abs(c.deviation) / max(c.deviation_limit, 1e-300)]
                                               + [s.peak for s in c.stretches]))
    figured = worst[:figures] if flagged else list(checks[:1])
    for check in figured:
        stem = re.sub(r"[^A-Za-z0-9_.-]", "_", Path(check.source).stem)
        written.append(plot_part(envelope, check, out / f"part_{stem}_{check.number:03d}.png"))
    written.append(write_html_report(envelope, checks, figured, out / "report.html"))
    return written
