"""Tables and plots of a feed-forward comparison.

One table per reference, as Tables 2 and 3 of Tjahjowidodo et al. (2005)
(tracking errors on the low-stroke and on the high-stroke reference): a row
per friction feed-forward with the RMS and the peak (maximum absolute)
tracking error, here in micrometres, and the RMS error relative to the row
"none" (inertia feed-forward only). Files written by :func:`write_report`
into the output directory:

``compensation.md``
    The tables and the settings of the run.
``compensation.csv``
    One line per reference and feed-forward (errors in mm, RMS current in A,
    fraction of controller periods at the current limit).
``compensation.json``
    Settings and the same rows.
``tracking_error_<reference>.png``
    Reference position, and the tracking error of every feed-forward over time.
"""

from __future__ import annotations

import csv
import io
import json
import re
from pathlib import Path

import numpy as np

from ..atomic import write_text_atomic
from ..errors import GreyboxError
from ..evaluate.plots import finish_figure, import_pyplot
from ..provenance import provenance, provenance_line
from .loop import LoopResult

__all__ = ["REPORT_FILES", "report_paths", "comparison_rows", "format_tables", "plot_tracking_errors",
           "write_report"]

#: Files of every report, besides one plot per reference.
REPORT_FILES = ("compensation.md", "compensation.csv", "compensation.json")

#: Name of the row every other row is compared with.
BASELINE = "none"


def _slug(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("_") or "reference"


def _plot_name(reference_name: str) -> str:
    return f"tracking_error_{_slug(reference_name)}.png"


def report_paths(reference_names, out_dir) -> list[Path]:
    """Every file :func:`write_report` writes for these references into ``out_dir``.

    Parameters
    ----------
    reference_names : iterable of str
        Names of the references, one tracking-error plot each.
    out_dir : path-like
        Output directory of the report.
    """
    out = Path(out_dir)
    return [out / name for name in REPORT_FILES] + [out / _plot_name(name) for name in reference_names]


def _reference_names(results) -> list[str]:
    return list(dict.fromkeys(result.reference.name for result in results))


def comparison_rows(results: list[LoopResult]) -> list[dict]:
    """Rows of the comparison: :meth:`LoopResult.summary` plus ``rms_vs_none`` (RMS / RMS of "none", or NaN).

    Parameters
    ----------
    results : list of LoopResult
        Runs of a comparison, grouped by reference in the order their references first appear.
    """
    rows = []
    for name in _reference_names(results):
        group = [result for result in results if result.reference.name == name]
        baseline = next((r.rms_error_mm for r in group if r.feedforward_name == BASELINE), float("nan"))
        for result in group:
            row = result.summary()
            row["rms_vs_none"] = result.rms_error_mm / baseline if baseline > 0 else float("nan")
            rows.append(row)
    return rows


def format_tables(results: list[LoopResult]) -> str:
    """Markdown tables of RMS and peak tracking error [um, or mdeg for a rotary axis], one per reference.

    Parameters
    ----------
    results : list of LoopResult
        Runs of a comparison; one table per reference they ran on.
    """
    lines = []
    for name in _reference_names(results):
        group = [result for result in results if result.reference.name == name]
        first, fine = group[0], group[0].units.fine_unit
        lines += [f"Tracking error on the {name} reference "
                  f"({first.reference.duration:g} s, plant {first.plant_name})", "",
                  f"| friction feed-forward | RMS error [{fine}] | max error [{fine}] | RMS vs none [%] |",
                  "|---|---:|---:|---:|"]
        rows = [row for row in comparison_rows(results) if row["reference"] == name]
        for result, row in zip(group, rows):
            relative = "" if np.isnan(row["rms_vs_none"]) else f"{100.0 * row['rms_vs_none']:.1f}"
            lines.append(f"| {row['feedforward']} | {1e3 * result.rms_error_mm:.4g} | "
                         f"{1e3 * result.peak_error_mm:.4g} | {relative} |")
        saturated = [r["feedforward"] for r in rows if r["saturated_fraction"] > 0]
        if saturated:
            lines.append(f"\nThe current hit its limit with: {', '.join(saturated)}.")
        lines.append("")
    return "\n".join(lines)


def plot_tracking_errors(results: list[LoopResult], reference_name: str, path=None):
    """Reference position and every feed-forward's tracking error [um, or mdeg] over time.

    Parameters
    ----------
    results : list of LoopResult
        Runs of a comparison; those on ``reference_name`` are drawn.
    reference_name : str
        Which reference.
    path : path-like, optional
        Write the figure there (atomically) and close it.

    Returns
    -------
    matplotlib.figure.Figure or pathlib.Path
    """
    plt = import_pyplot(path)
    group = [result for result in results if result.reference.name == reference_name]
    if not group:
        raise GreyboxError(f"no run on reference {reference_name!r}")
    reference = group[0].reference
    figure, axes = plt.subplots(len(group) + 1, 1, sharex=True, figsize=(10, 1.6 * (len(group) + 1) + 1),
                                layout="constrained")
    axes[0].plot(reference.time, reference.position, lw=0.8, color="k")
    units = group[0].units
    fine = units.fine_unit
    axes[0].set_ylabel(f"reference\n[{units.length}]")
    limit = max(1e3 * result.peak_error_mm for result in group)
    for ax, result in zip(axes[1:], group):
        ax.plot(reference.time, 1e3 * result.error_mm, lw=0.6)
        ax.set_ylim(-1.05 * limit, 1.05 * limit)
        ax.set_ylabel(f"{result.feedforward_name}\n[{fine}]")
        ax.text(0.995, 0.95, f"RMS {1e3 * result.rms_error_mm:.3g} {fine}, max {1e3 * result.peak_error_mm:.3g} {fine}",
                transform=ax.transAxes, ha="right", va="top", fontsize=8)
    for ax in axes:
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time [s]")
    figure.suptitle(f"tracking error on the {reference_name} reference (plant {group[0].plant_name})")
    return finish_figure(figure, path)


def _csv_text(rows: list[dict]) -> str:
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buffer.getvalue()


def write_report(results: list[LoopResult], out_dir, *, settings: dict | None = None, force: bool = False
                 ) -> list[Path]:
    """Write the tables, the rows and the plots of a comparison into ``out_dir`` (created if missing).

    Parameters
    ----------
    results : list of LoopResult
        Runs of :func:`greybox.control.loop.compare_feedforwards`.
    out_dir : path-like
        Output directory.
    settings : dict, optional
        JSON-serialisable description of the run (plant, models, command line), kept in the JSON file
        and listed in the Markdown file.
    force : bool, default False
        Overwrite existing report files; otherwise an existing one is an error and nothing is written.

    Returns
    -------
    list of Path
        The written files.
    """
    if not results:
        raise GreyboxError("nothing to report: no closed-loop runs")
    out = Path(out_dir)
    names = _reference_names(results)
    targets = report_paths(names, out)
    existing = [str(path) for path in targets if path.exists()]
    if existing and not force:
        raise GreyboxError(f"{existing[0]}: file exists ({len(existing)} of {len(targets)} report files exist); "
                           "nothing was written. Choose another directory or pass --force to overwrite")
    out.mkdir(parents=True, exist_ok=True)
    settings = dict(settings or {})
    machine = provenance()
    rows = comparison_rows(results)
    first = results[0].settings
    markdown = ["# Closed-loop tracking error with friction feed-forward", "", format_tables(results),
                "Errors are those of the true position against the reference at the reference samples; "
                "'none' feeds forward the inertia only. One set of PID gains for every row.", "",
                "## Settings", "", f"- controller: {json.dumps(first)}", f"- measured with: {provenance_line(machine)}"]
    markdown += [f"- {key}: {json.dumps(value)}" for key, value in settings.items()]
    write_text_atomic(targets[0], "\n".join(markdown) + "\n")
    write_text_atomic(targets[1], _csv_text(rows))
    strict_rows = [{key: (None if isinstance(value, float) and np.isnan(value) else value)
                    for key, value in row.items()} for row in rows]
    document = {"settings": {**settings, "controller": first}, "provenance": machine, "rows": strict_rows}
    write_text_atomic(targets[2], json.dumps(document, indent=2, allow_nan=False) + "\n")
    for name, path in zip(names, targets[len(REPORT_FILES):]):
        plot_tracking_errors(results, name, path)
    return targets
