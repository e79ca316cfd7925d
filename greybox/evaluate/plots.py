"""Figures of axis logs and model results (matplotlib, written as PNG)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..atomic import atomic_output
from ..data.log import AxisLog

__all__ = ["plot_log", "save_figure", "import_pyplot", "finish_figure"]


def import_pyplot(path: str | os.PathLike | None):
    """``matplotlib.pyplot``, on the non-interactive Agg backend when the figure goes to a file.

    Parameters
    ----------
    path : path-like or None
        Where the figure will be written; ``None`` leaves the backend alone
        (the caller shows or returns the figure).
    """
    import matplotlib

    if path is not None:
        matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def finish_figure(figure, path: str | os.PathLike | None):
    """Return ``figure`` when ``path`` is None, else write it with :func:`save_figure` and return the path."""
    if path is None:
        return figure
    return save_figure(figure, path)


def save_figure(figure, path: str | os.PathLike, *, dpi: int = 120) -> Path:
    """Write a matplotlib figure to ``path`` atomically and close it.

    The figure is rendered to a temporary file in the target directory and
    moved into place, so an interrupted run never leaves a half-written image.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        Figure to save.
    path : path-like
        Target file; the format follows its extension (``.png``, ``.svg``, ``.pdf``).
    dpi : int, default 120
        Resolution of raster formats [dots per inch].

    Returns
    -------
    pathlib.Path
        The written file.
    """
    import matplotlib.pyplot as plt

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        with atomic_output(path) as temporary:
            figure.savefig(temporary, dpi=dpi, format=path.suffix.lstrip(".") or "png")
    finally:
        plt.close(figure)
    return path


def plot_log(log: AxisLog, path: str | os.PathLike | None = None, *, max_points: int = 200_000):
    """Draw position, velocity and effort over time, and effort over velocity.

    Parameters
    ----------
    log : AxisLog
        The log to draw. Velocity is drawn only when present (derive it with
        :func:`greybox.data.prepare.derive`).
    path : path-like, optional
        Write the figure there (PNG by extension) and close it.
    max_points : int, default 200000
        Longer logs are thinned by an integer stride for drawing only.

    Returns
    -------
    matplotlib.figure.Figure or pathlib.Path
        The figure, or the written file when ``path`` is given.
    """
    plt = import_pyplot(path)
    stride = max(1, int(np.ceil(len(log) / max_points)))
    t = log.time[::stride]
    effort = log.effort[::stride]
    effort_label = "motor current [A]" if log.effort_unit == "A" else "force [N]"
    has_velocity = log.velocity is not None

    figure = plt.figure(figsize=(11, 8), layout="constrained")
    grid = figure.add_gridspec(3, 2, width_ratios=(2.2, 1))
    ax_pos = figure.add_subplot(grid[0, 0])
    ax_vel = figure.add_subplot(grid[1, 0], sharex=ax_pos)
    ax_eff = figure.add_subplot(grid[2, 0], sharex=ax_pos)
    ax_map = figure.add_subplot(grid[:, 1])

    ax_pos.plot(t, log.position[::stride], lw=0.8)
    ax_pos.set_ylabel("position [mm]")
    if has_velocity:
        ax_vel.plot(t, log.velocity[::stride], lw=0.8)
    else:
        ax_vel.text(0.5, 0.5, "velocity not logged", ha="center", va="center", transform=ax_vel.transAxes)
    ax_vel.set_ylabel("velocity [mm/s]")
    ax_eff.plot(t, effort, lw=0.5)
    ax_eff.set_ylabel(effort_label)
    ax_eff.set_xlabel("time [s]")
    for ax in (ax_pos, ax_vel):
        ax.tick_params(labelbottom=False)

    if has_velocity:
        ax_map.plot(log.velocity[::stride], effort, ".", ms=1, alpha=0.3)
        ax_map.set_xlabel("velocity [mm/s]")
    else:
        ax_map.text(0.5, 0.5, "velocity not logged", ha="center", va="center", transform=ax_map.transAxes)
    ax_map.set_ylabel(effort_label)
    ax_map.set_title("effort over velocity")
    for ax in (ax_pos, ax_vel, ax_eff, ax_map):
        ax.grid(True, alpha=0.3)

    name = " / ".join(p for p in (log.axis and f"axis {log.axis}", log.dataset and f"dataset {log.dataset}") if p)
    title = name or "axis log"
    if log.source:
        title += f"  ({Path(log.source).name})"
    figure.suptitle(title)
    return finish_figure(figure, path)
