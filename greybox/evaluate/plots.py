"""Figures of axis logs and model results (matplotlib, written as PNG).

Long signals are drawn as their envelope (:func:`envelope`): the minimum and
the maximum of each of about 2000 consecutive bins of samples, more bins than
an axis of these figures has pixel columns, so that an hour at 500 Hz draws
as fast as a minute and shows every peak, rather than a band of overlapping
lines. A time window (``window=(start_s, stop_s)``) shows the samples
themselves.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..atomic import atomic_output
from ..data.log import AxisLog
from ..errors import GreyboxError, Setting

__all__ = ["ENVELOPE_POINTS", "check_window", "envelope", "envelope_indices", "plot_log", "save_figure",
           "import_pyplot", "legend_outside", "finish_figure", "window_title"]

#: Points drawn per line at most: the minimum and maximum of 2000 bins (an axis of the figures here
#: spans about 900-1300 pixel columns at their size and resolution).
ENVELOPE_POINTS = 4000


def envelope_indices(n_samples: int, max_points: int) -> np.ndarray:
    """Start indices of the bins that thin a long signal for drawing while keeping its peaks.

    The samples are split into about ``max_points / 2`` bins of equal count;
    :func:`envelope` draws the minimum and maximum of each. Short signals are
    kept whole.

    Parameters
    ----------
    n_samples : int
        Signal length.
    max_points : int
        Upper bound of points to draw per line.

    Returns
    -------
    ndarray of int
        Start index of every bin (all indices when ``n_samples <= max_points``).
    """
    if n_samples <= max_points:
        return np.arange(n_samples)
    size = int(np.ceil(2 * n_samples / max_points))
    return np.arange(0, n_samples, size)


def band_envelope(time, lower, upper, max_points: int = ENVELOPE_POINTS
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A band thinned for drawing: per bin of samples (:func:`envelope_indices`) the lowest lower and highest upper.

    Parameters
    ----------
    time : array_like
        Time [s], increasing.
    lower, upper : array_like
        Bounds of the band, same length (any unit).
    max_points : int, default :data:`ENVELOPE_POINTS`
        Upper bound of points returned; bands this short are returned whole.

    Returns
    -------
    (ndarray, ndarray, ndarray)
        Times [s] (each bin's first), lower and upper bounds to fill between.
    """
    time, lower, upper = (np.asarray(a, dtype=float) for a in (time, lower, upper))
    starts = envelope_indices(lower.size, max_points)
    if starts.size == lower.size:
        return time, lower, upper
    return time[starts], np.minimum.reduceat(lower, starts), np.maximum.reduceat(upper, starts)


def envelope(time, values, max_points: int = ENVELOPE_POINTS) -> tuple[np.ndarray, np.ndarray]:
    """Points that draw a signal as its envelope: per bin of samples its minimum and its maximum, in time order.

    Drawn as one line, each bin becomes a stroke between its minimum and its
    maximum, taken at their own times and in the order they occur, so the
    picture shows the full range of the signal in every pixel column, keeps
    single-sample peaks and follows the signal from one bin to the next.

    Parameters
    ----------
    time : array_like
        Time [s], increasing.
    values : array_like
        Signal, same length (any unit).
    max_points : int, default :data:`ENVELOPE_POINTS`
        Upper bound of points returned; signals this short are returned whole.

    Returns
    -------
    (ndarray, ndarray)
        Times [s] and values to draw.
    """
    time = np.asarray(time, dtype=float)
    values = np.asarray(values, dtype=float)
    starts = envelope_indices(values.size, max_points)
    if starts.size == values.size:
        return time, values
    size = int(starts[1] - starts[0]) if starts.size > 1 else values.size
    bins = np.pad(values, (0, starts.size * size - values.size), mode="edge").reshape(starts.size, size)
    low = np.minimum(starts + np.argmin(bins, axis=1), values.size - 1)
    high = np.minimum(starts + np.argmax(bins, axis=1), values.size - 1)
    index = np.column_stack((np.minimum(low, high), np.maximum(low, high))).ravel()
    return time[index], values[index]


def check_window(window, time, setting: str = "window", name: str = "the log") -> tuple[float, float] | None:
    """Return the window ``(start, end)`` [s], or None; refuse one that is empty, reversed or off the log.

    Parameters
    ----------
    window : sequence of two floats or None
        The option's value.
    time : ndarray
        The log's time [s].
    setting : str, default "window"
        The setting that gave the window, named in the message (the command line spells its option).
    name : str
        The log, for the message.

    Raises
    ------
    GreyboxError
        If START or END is not finite, START >= END, or no sample lies in the window.
    """
    if window is None:
        return None
    start, end = (float(v) for v in window)
    text = (Setting(setting, assign=False), f" {start:g} {end:g}")
    if not (math.isfinite(start) and math.isfinite(end)) or start >= end:
        raise GreyboxError(*text, ": give START < END, both finite, in seconds of log time")
    first, last = float(time[0]), float(time[-1])
    if not ((time >= start) & (time <= end)).any():
        raise GreyboxError(*text, f": no sample in the window; {name} runs from {first:g} to {last:g} s")
    return start, end


def window_title(window: tuple[float, float] | None) -> str:
    """Suffix of a figure title naming a time window [s] (empty without one).

    Parameters
    ----------
    window : (float, float) or None
        Start and stop time [s] of the window, or None for the whole log.
    """
    return "" if window is None else f", {window[0]:g} to {window[1]:g} s"


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


def legend_outside(ax, handles=None, labels=None, **options):
    """Draw the legend of ``ax`` to the right of its axes, outside the data it would otherwise cover.

    The figures are drawn with the constrained layout, which makes room for it.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes whose labelled artists (or ``handles``) the legend explains.
    handles, labels : list, optional
        Artists and texts to show instead of those of ``ax`` (proxies for colours drawn without a label).
    **options
        Further :meth:`matplotlib.axes.Axes.legend` options (``ncol``, ``title``).

    Returns
    -------
    matplotlib.legend.Legend
    """
    if handles is None:
        handles, labels = ax.get_legend_handles_labels()
    options = {"fontsize": "small", **options}
    return ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, **options)


def finish_figure(figure, path: str | os.PathLike | None):
    """Return ``figure`` when ``path`` is None, else write it with :func:`save_figure` and return the path.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        Figure to return or save.
    path : path-like or None
        Target file (written atomically, the figure then closed), or None to return the figure open.
    """
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


def plot_log(log: AxisLog, path: str | os.PathLike | None = None, *, max_points: int = ENVELOPE_POINTS,
             max_map_points: int = 200_000, window: tuple[float, float] | None = None):
    """Draw position, velocity and effort over time, and effort over velocity.

    Parameters
    ----------
    log : AxisLog
        The log to draw. Velocity is drawn only when present (derive it with
        :func:`greybox.data.prepare.derive`).
    path : path-like, optional
        Write the figure there (PNG by extension) and close it.
    max_points : int, default :data:`ENVELOPE_POINTS`
        Signals over time with more samples are drawn as their envelope
        (:func:`envelope`: minimum and maximum per bin of samples).
    max_map_points : int, default 200000
        Effort over velocity: longer logs are thinned by an integer stride.
    window : (float, float), optional
        Draw only the samples with ``start <= time <= stop`` [s].

    Returns
    -------
    matplotlib.figure.Figure or pathlib.Path
        The figure, or the written file when ``path`` is given.

    Raises
    ------
    LogError
        If no sample lies in ``window``.
    """
    if window is not None:
        from ..data.prepare import trim

        log = trim(log, *window)
    plt = import_pyplot(path)
    stride = max(1, int(np.ceil(len(log) / max_map_points)))
    effort = log.effort[::stride]
    units = log.units
    effort_label = units.effort_label(log.effort_unit)
    has_velocity = log.velocity is not None

    figure = plt.figure(figsize=(11, 8), layout="constrained")
    grid = figure.add_gridspec(3, 2, width_ratios=(2.2, 1))
    ax_pos = figure.add_subplot(grid[0, 0])
    ax_vel = figure.add_subplot(grid[1, 0], sharex=ax_pos)
    ax_eff = figure.add_subplot(grid[2, 0], sharex=ax_pos)
    ax_map = figure.add_subplot(grid[:, 1])

    ax_pos.plot(*envelope(log.time, log.position, max_points), lw=0.8)
    ax_pos.set_ylabel(f"position [{units.length}]")
    if has_velocity:
        ax_vel.plot(*envelope(log.time, log.velocity, max_points), lw=0.8)
    else:
        ax_vel.text(0.5, 0.5, "velocity not logged", ha="center", va="center", transform=ax_vel.transAxes)
    ax_vel.set_ylabel(f"velocity [{units.velocity_unit}]")
    ax_eff.plot(*envelope(log.time, log.effort, max_points), lw=0.5)
    ax_eff.set_ylabel(effort_label)
    ax_eff.set_xlabel("time [s]")
    for ax in (ax_pos, ax_vel):
        ax.tick_params(labelbottom=False)

    if has_velocity:
        ax_map.plot(log.velocity[::stride], effort, ".", ms=1, alpha=0.3)
        ax_map.set_xlabel(f"velocity [{units.velocity_unit}]")
    else:
        ax_map.text(0.5, 0.5, "velocity not logged", ha="center", va="center", transform=ax_map.transAxes)
    ax_map.set_ylabel(effort_label)
    ax_map.set_title("effort over velocity")
    for ax in (ax_pos, ax_vel, ax_eff, ax_map):
        ax.grid(True, alpha=0.3)

    name = " / ".join(p for p in (log.axis and f"axis {log.axis}", log.dataset and f"dataset {log.dataset}") if p)
    title = (name or "axis log") + window_title(window)
    if log.source:
        title += f"  ({Path(log.source).name})"
    figure.suptitle(title)
    return finish_figure(figure, path)
