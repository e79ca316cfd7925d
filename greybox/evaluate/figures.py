"""Report figures comparing models with the measured current (PNG, matplotlib).

- :func:`error_boxplot`: absolute error per model as box plots (the paper's
  Figs. 3 and 5), one panel per axis or test set;
- :func:`time_comparison`: measured and modelled current over time on each
  test run, with a zoom on a reversal (the paper's Figs. 4 and 6);
- :func:`residual_vs_position`: measured minus modelled current against the
  position, by direction of motion: what a model misses along the screw.

Every function takes the measured current of prepared runs and predictions
keyed by model name (one array per run, or the runs concatenated), writes the
figure with :func:`greybox.evaluate.plots.save_figure` and returns the path.
Axes and default titles name the runs' effort: current [A], or force [N] for
drives that log force (EMPS).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from ..data.log import AxisLog, split_runs
from .plots import finish_figure, import_pyplot, legend_outside
from .report import MODEL_LABELS

__all__ = ["MODEL_COLORS", "effort_name", "error_boxplot", "time_comparison", "residual_vs_position"]

#: Line colours of the models, the same in every figure.
MODEL_COLORS = {
    "coulomb": "#8c564b",
    "stribeck": "#ff7f0e",
    "lugre": "#9467bd",
    "gms": "#2ca02c",
    "svr": "#d62728",
    "gmssvr": "#1f77b4",
    "gmssvr_eq8": "#17becf",
    "noise_floor": "#7f7f7f",
}
_MEASURED = "#000000"


def _color(model: str, k: int) -> str:
    return MODEL_COLORS.get(model, f"C{k % 10}")


def effort_name(runs: Sequence[AxisLog]) -> tuple[str, str]:
    """What the runs' effort is and its unit: ``("current", "A")``, ``("force", "N")`` or ``("torque", "Nm")``.

    Parameters
    ----------
    runs : sequence of AxisLog
        Runs whose ``effort_unit`` is read; all must carry the same one.

    Raises
    ------
    ValueError
        If the runs carry different effort units.
    """
    units = sorted({run.effort_unit for run in runs})
    if len(units) != 1:
        raise ValueError(f"the runs carry effort in different units ({', '.join(units)}); draw them apart")
    return ("current" if units[0] == "A" else runs[0].units.load), units[0]


def error_boxplot(panels: Sequence[tuple[str, Sequence[AxisLog], Mapping[str, object]]],
                  path: str | os.PathLike, *, title: str | None = None) -> Path:
    """Box plots of ``|I_model - I|`` per model, one panel per entry of ``panels``.

    Parameters
    ----------
    panels : sequence of (title, runs, predictions)
        ``runs``: prepared runs whose ``effort`` is the measured current [A]
        (or force [N]); ``predictions``: ``{model: prediction}`` (concatenated or per run).
    path : path-like or None
        PNG file to write, or None to return the open figure (a page of a PDF report).
    title : str, optional
        Figure title; default "Absolute error of the modelled current" (or force).

    Returns
    -------
    pathlib.Path
        Boxes span the quartiles, whiskers the 5th to 95th percentiles;
        outliers are not drawn.
    """
    noun, unit = effort_name([run for panel in panels for run in panel[1]])
    plt = import_pyplot(path)
    n_models = max(len(p[2]) for p in panels)
    figure, axes = plt.subplots(1, len(panels), figsize=(max(5.0, 1.0 + 0.9 * n_models) * len(panels), 4.5),
                                squeeze=False, layout="constrained")
    for ax, (panel_title, runs, predictions) in zip(axes[0], panels):
        measured = np.concatenate([run.effort for run in runs])
        names = list(predictions)
        errors = [np.abs(np.concatenate(split_runs(runs, predictions[name])) - measured) for name in names]
        boxes = ax.boxplot(errors, whis=(5, 95), showfliers=False, patch_artist=True, widths=0.6)
        for k, (patch, name) in enumerate(zip(boxes["boxes"], names)):
            patch.set_facecolor(_color(name, k))
            patch.set_alpha(0.6)
        ax.set_xticks(range(1, len(names) + 1), [MODEL_LABELS.get(n, n) for n in names], rotation=30,
                      ha="right")
        ax.set_ylabel(f"absolute error [{unit}]")
        ax.set_title(panel_title)
        ax.grid(True, axis="y", alpha=0.3)
    figure.suptitle(title or f"Absolute error of the modelled {noun}")
    return finish_figure(figure, path)


def _zoom_window(run: AxisLog, width_s: float) -> tuple[float, float]:
    """A window of ``width_s`` around the direction reversal nearest the middle of the run [s]."""
    moving = np.abs(run.velocity) > 0.01 * max(float(np.max(np.abs(run.velocity))), 1e-12)
    signs = np.sign(run.velocity[moving])
    times = run.time[moving]
    flips = times[1:][signs[1:] != signs[:-1]]
    middle = 0.5 * (run.time[0] + run.time[-1])
    centre = float(flips[np.argmin(np.abs(flips - middle))]) if flips.size else middle
    start = max(float(run.time[0]), centre - 0.5 * width_s)
    return start, min(float(run.time[-1]), start + width_s)


def time_comparison(runs: Sequence[AxisLog], predictions: Mapping[str, object], path: str | os.PathLike, *,
                    names: Sequence[str] | None = None, zoom_s: float = 4.0, max_points: int = 20_000,
                    title: str | None = None) -> Path:
    """Measured and modelled current over time, each run in full and zoomed on a reversal.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared test runs; their ``effort`` is the measured current [A] (or force [N]).
    predictions : dict
        ``{model: prediction}`` (concatenated or per run) [A] (or [N]).
    path : path-like or None
        PNG file to write, or None to return the open figure (a page of a PDF report).
    names : sequence of str, optional
        Run names for the panel titles (default: the runs' dataset or source).
    zoom_s : float, default 4.0
        Width of the zoom window [s].
    max_points : int, default 20000
        Full-run curves are thinned to at most this many points for drawing.
    title : str, optional
        Figure title; default "Measured and modelled current" (or force).

    Returns
    -------
    pathlib.Path
    """
    noun, unit = effort_name(runs)
    plt = import_pyplot(path)
    per_run = {model: split_runs(runs, p) for model, p in predictions.items()}
    if names is None:
        names = [run.dataset or (Path(run.source).stem if run.source else "") or f"run {i + 1}"
                 for i, run in enumerate(runs)]
    figure, axes = plt.subplots(len(runs), 2, figsize=(14, 3.6 * len(runs)), squeeze=False,
                                gridspec_kw={"width_ratios": (2.2, 1)}, layout="constrained")
    for i, run in enumerate(runs):
        full, zoom = axes[i]
        stride = max(1, int(np.ceil(len(run) / max_points)))
        start, stop = _zoom_window(run, zoom_s)
        window = (run.time >= start) & (run.time <= stop)
        full.plot(run.time[::stride], run.effort[::stride], color=_MEASURED, lw=0.5, alpha=0.5, label="measured")
        zoom.plot(run.time[window], run.effort[window], color=_MEASURED, lw=0.7, alpha=0.6, label="measured")
        for k, (model, parts) in enumerate(per_run.items()):
            style = {"color": _color(model, k), "lw": 0.9, "label": MODEL_LABELS.get(model, model)}
            full.plot(run.time[::stride], parts[i][::stride], **style)
            zoom.plot(run.time[window], parts[i][window], **style)
        full.axvspan(start, stop, color="0.85", zorder=0)
        full.set_title(f"{names[i]}: full run")
        zoom.set_title(f"{names[i]}: {start:.1f} to {stop:.1f} s (around a reversal)")
        for ax in (full, zoom):
            ax.set_xlabel("time [s]")
            ax.set_ylabel(f"{noun} [{unit}]")
            ax.grid(True, alpha=0.3)
    legend_outside(axes[0, -1])  # right of the top row: the same lines in both panels
    figure.suptitle(title or f"Measured and modelled {noun}")
    return finish_figure(figure, path)


def residual_vs_position(runs: Sequence[AxisLog], predictions: Mapping[str, object], path: str | os.PathLike,
                         *, n_bins: int = 40, max_points: int = 20_000,
                         title: str = "Residual against position, by direction of motion") -> Path:
    """Measured minus modelled current (or force) against the position, one panel per model.

    Samples moving in +/- direction are drawn in two colours (thinned to at
    most ``max_points`` per panel, standstill left out), with the mean residual
    of each direction in ``n_bins`` position bins as a line.

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs (position [mm or deg], velocity, measured current [A] or load [N or Nm]).
    predictions : dict
        ``{model: prediction}`` (concatenated or per run) [A] (or [N]).
    path : path-like or None
        PNG file to write, or None to return the open figure (a page of a PDF report).
    n_bins : int, default 40
        Number of equal-width position bins of the mean-residual lines.
    max_points : int, default 20000
        Most samples drawn per panel: each direction's samples are thinned to at most half of it
        (a stride of their count divided by ``max_points // 2``, rounded up).
    title : str, default "Residual against position, by direction of motion"
        Figure title.

    Returns
    -------
    pathlib.Path
    """
    unit = effort_name(runs)[1]
    plt = import_pyplot(path)
    position = np.concatenate([run.position for run in runs])
    velocity = np.concatenate([run.velocity for run in runs])
    measured = np.concatenate([run.effort for run in runs])
    standstill = 0.01 * max(float(np.max(np.abs(velocity))), 1e-12)
    # (label, samples, colour of the points, colour of the mean line)
    directions = (("+", velocity > standstill, "#6baed6", "#08306b"),
                  ("-", velocity < -standstill, "#fdae6b", "#7f2704"))
    edges = np.linspace(position.min(), position.max(), n_bins + 1)
    centres = 0.5 * (edges[1:] + edges[:-1])
    n = len(predictions)
    columns = min(3, n)
    rows = int(np.ceil(n / columns))
    figure, axes = plt.subplots(rows, columns, figsize=(5.2 * columns, 3.6 * rows), squeeze=False,
                                sharex=True, sharey=True, layout="constrained")
    for ax, (model, prediction) in zip(axes.ravel(), predictions.items()):
        residual = measured - np.concatenate(split_runs(runs, prediction))
        for label, mask, color, _ in directions:
            index = np.flatnonzero(mask)
            shown = index[:: max(1, -(-index.size // max(1, max_points // 2)))]  # half the points each
            ax.plot(position[shown], residual[shown], ".", ms=1, color=color, alpha=0.3, label=f"samples, v {label}")
        for label, mask, _, color in directions:
            index = np.flatnonzero(mask)
            counts = np.histogram(position[index], edges)[0]
            sums = np.histogram(position[index], edges, weights=residual[index])[0]
            with np.errstate(invalid="ignore", divide="ignore"):
                ax.plot(centres, sums / counts, color=color, lw=1.8, label=f"mean, v {label}")
        ax.axhline(0.0, color="0.3", lw=0.6)
        ax.set_title(MODEL_LABELS.get(model, model))
        ax.grid(True, alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel(f"position [{runs[0].units.length}]")
    for ax in axes[:, 0]:
        ax.set_ylabel(f"measured - model [{unit}]")
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    legend_outside(axes[0, min(columns, n) - 1], markerscale=8)  # right of the top row
    figure.suptitle(title)
    return finish_figure(figure, path)
