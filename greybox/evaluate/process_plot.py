"""Picture of ``greybox predict``: measured, model and process current (and force) over time."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .plots import finish_figure, import_pyplot
from .process import ProcessResult

__all__ = ["envelope_indices", "moving_mean", "plot_process"]


def envelope_indices(n_samples: int, max_points: int) -> np.ndarray:
    """Indices that thin a long signal for drawing while keeping its peaks: the first sample of each bin.

    The samples are split into about ``max_points / 2`` bins; callers draw the
    minimum and maximum of each bin (see :func:`plot_process`). Short signals
    are kept whole.

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


def moving_mean(values, window: int) -> np.ndarray:
    """Centred moving mean over ``window`` samples, the window shortened at both ends of the signal.

    Parameters
    ----------
    values : array_like
        Signal.
    window : int
        Window length [samples], at least 1 (1 returns the signal).

    Returns
    -------
    ndarray
        Same length as ``values``; sample ``i`` is the mean of the samples of
        the window centred on ``i`` that lie inside the signal.
    """
    values = np.asarray(values, dtype=float)
    if window < 1:
        raise ValueError(f"the window must hold at least one sample, got {window}")
    sums = np.concatenate(([0.0], np.cumsum(values)))
    index = np.arange(values.size)
    start = np.clip(index - window // 2, 0, values.size)
    stop = np.clip(index - window // 2 + window, 0, values.size)
    return (sums[stop] - sums[start]) / (stop - start)


def _min_max(time: np.ndarray, values: np.ndarray, starts: np.ndarray):
    """Per bin the minimum and the maximum, in time order (exact when every bin holds one sample)."""
    if starts.size == values.size:
        return time, values
    low = np.minimum.reduceat(values, starts)
    high = np.maximum.reduceat(values, starts)
    t = np.repeat(time[starts], 2)
    return t, np.column_stack((low, high)).ravel()


def plot_process(result: ProcessResult, path: str | os.PathLike | None = None, *, max_points: int = 100_000,
                 mean_s: float = 0.1):
    """Draw velocity, measured and model current, and the process current over time.

    The process panel has a second scale in N when the force is known (the
    force is proportional to the process current), and draws the moving mean
    of the process current over ``mean_s`` on top of the sample values: the
    level of the cutting force, without the tooth-passing ripple and the
    current noise.

    Parameters
    ----------
    result : ProcessResult
        Output of :func:`greybox.evaluate.process.predict_process`.
    path : path-like, optional
        Write the figure there (PNG, SVG or PDF by extension) and close it.
    max_points : int, default 100000
        Longer logs are drawn as the minimum and maximum of bins of samples.
    mean_s : float, default 0.1
        Window [s] of the moving mean of the process current; 0 draws none.

    Returns
    -------
    matplotlib.figure.Figure or pathlib.Path
        The figure, or the written file when ``path`` is given.
    """
    plt = import_pyplot(path)
    unit = result.effort_unit
    noun = "current" if unit == "A" else "force"
    starts = envelope_indices(result.time.size, max_points)

    def line(ax, values, **style):
        ax.plot(*_min_max(result.time, values, starts), **style)

    figure, (ax_v, ax_i, ax_p) = plt.subplots(3, 1, sharex=True, figsize=(11, 8), layout="constrained",
                                              height_ratios=(1, 2, 2))
    line(ax_v, result.velocity, lw=0.8, color="tab:gray")
    ax_v.set_ylabel("velocity [mm/s]")
    line(ax_i, result.measured, lw=0.5, color="tab:gray", label=f"measured {noun}")
    line(ax_i, result.model, lw=0.8, color="tab:blue", label=f"model {noun} (inertia + friction)")
    ax_i.set_ylabel(f"{noun} [{unit}]")
    ax_i.legend(loc="upper right", fontsize="small")
    line(ax_p, result.process, lw=0.6, color="tab:red", label=f"process {noun} = measured - model")
    if mean_s > 0 and result.time.size > 1:
        window = max(1, int(round(mean_s / float(np.median(np.diff(result.time))))))
        line(ax_p, moving_mean(result.process, window), lw=1.2, color="darkred",
             label=f"moving mean over {mean_s:g} s")
    ax_p.axhline(0.0, color="black", lw=0.5)
    ax_p.set_ylabel(f"process {noun} [{unit}]")
    ax_p.set_xlabel("time [s]")
    ax_p.legend(loc="upper right", fontsize="small")
    factor = result.force_constant_N_per_A
    if unit == "A" and factor:
        right = ax_p.secondary_yaxis("right", functions=(lambda i: i * factor, lambda f: f / factor))
        right.set_ylabel("process force [N]")
    for ax in (ax_v, ax_i, ax_p):
        ax.grid(True, alpha=0.3)
    title = f"axis {result.axis}" if result.axis else "axis log"
    if result.source:
        title += f"  ({Path(result.source).name})"
    model = result.attrs.get("model_kind")
    if model:
        title += f", {model} model"
    figure.suptitle(title)
    return finish_figure(figure, path)
