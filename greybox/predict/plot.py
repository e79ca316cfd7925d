"""Picture of ``greybox predict``: measured, model and process current (and force) over time."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..evaluate.plots import (
    ENVELOPE_POINTS,
    band_envelope,
    envelope,
    envelope_indices,
    finish_figure,
    import_pyplot,
    legend_outside,
    window_title,
)
from .process import ProcessResult
from .relevel import moving_mean

__all__ = ["envelope_indices", "moving_mean", "plot_machine_process", "plot_process"]


def _shown(time: np.ndarray, window) -> slice:
    """The samples of ``time`` [s] inside ``window`` (all without one); ValueError if none lies in it."""
    if window is None:
        return slice(None)
    shown = slice(np.searchsorted(time, window[0], "left"), np.searchsorted(time, window[1], "right"))
    if shown.start >= shown.stop:
        raise ValueError(f"no samples between {window[0]:g} s and {window[1]:g} s")
    return shown


def _mark_outside(ax, time, outside, max_points: int, label: str, color: str = "tab:orange") -> None:
    """Shade the time spans (thinned to bins, :func:`envelope_indices`) where the log leaves the training region."""
    starts = envelope_indices(outside.size, max_points)
    flags = np.logical_or.reduceat(outside, starts) if starts.size < outside.size else outside
    ax.fill_between(time[starts], 0, 1, where=flags, step="post", transform=ax.get_xaxis_transform(),
                    color=color, alpha=0.15, lw=0, label=label)
    legend_outside(ax)


def plot_process(result: ProcessResult, path: str | os.PathLike | None = None, *,
                 max_points: int = ENVELOPE_POINTS, mean_s: float = 0.1,
                 window: tuple[float, float] | None = None):
    """Draw velocity, measured and model current, and the process current over time.

    The process panel has a second scale in N (Nm for a rotary axis) when the
    load is known and proportional to the process current (one efficiency), a
    panel of its own when the two efficiencies differ, and draws the moving mean
    of the process current over ``mean_s`` on top of the sample values: the
    level of the cutting force, without the tooth-passing ripple and the
    current noise.

    Parameters
    ----------
    result : ProcessResult
        Output of :func:`greybox.predict.process.predict_process`.
    path : path-like, optional
        Write the figure there (PNG, SVG or PDF by extension) and close it.
    max_points : int, default :data:`~greybox.evaluate.plots.ENVELOPE_POINTS`
        Longer logs are drawn as their envelope, the minimum and maximum of
        bins of samples (:func:`~greybox.evaluate.plots.envelope`).
    mean_s : float, default 0.1
        Window [s] of the moving mean of the process current; 0 draws none.
    window : (float, float), optional
        Draw only the samples with ``start <= time <= stop`` [s] (the moving
        mean is taken over the whole log first).

    Returns
    -------
    matplotlib.figure.Figure or pathlib.Path
        The figure, or the written file when ``path`` is given.

    Raises
    ------
    ValueError
        If no sample lies in ``window``.
    """
    shown = _shown(result.time, window)
    plt = import_pyplot(path)
    unit = result.shown_unit
    units = result.units
    noun = result.quantity
    load_label = f"process {units.load} [{units.load_unit}]"

    def line(ax, values, **style):
        ax.plot(*envelope(result.time[shown], values[shown], max_points), **style)

    factors = result.load_constants
    force_panel = result.effort_unit == "A" and factors is not None and factors[0] != factors[1]
    figure, axes = plt.subplots(4 if force_panel else 3, 1, sharex=True, figsize=(11, 10 if force_panel else 8),
                                layout="constrained", height_ratios=(1, 2, 2, 2) if force_panel else (1, 2, 2))
    ax_v, ax_i, ax_p = axes[:3]
    line(ax_v, result.velocity, lw=0.8, color="tab:gray")
    ax_v.set_ylabel(f"velocity [{units.velocity_unit}]")
    line(ax_i, result.measured, lw=0.5, color="tab:gray", label=f"measured {noun}")
    line(ax_i, result.model, lw=0.8, color="tab:blue", label=f"model {noun} (inertia + friction)")
    ax_i.set_ylabel(f"{noun} [{unit}]")
    legend_outside(ax_i)
    coverage = result.attrs.get("interval", {}).get("coverage")
    band_label = f"{100 * coverage:g} % interval" if coverage else "interval"
    mean_samples = (max(1, int(round(mean_s / float(np.median(np.diff(result.time))))))
                    if mean_s > 0 and result.time.size > 1 else 0)

    def process_panel(ax, values, bounds, what, color, dark):
        if bounds is not None:
            ax.fill_between(*band_envelope(result.time[shown], bounds[0][shown], bounds[1][shown], max_points),
                            color=color, alpha=0.25, lw=0, step="post", label=band_label)
        line(ax, values, lw=0.6, color=color, label=what)
        if mean_samples:
            line(ax, moving_mean(values, mean_samples), lw=1.2, color=dark, label=f"moving mean over {mean_s:g} s")
        ax.axhline(0.0, color="black", lw=0.5)
        legend_outside(ax)

    process_panel(ax_p, result.process, result.process_bounds, f"process {noun} = measured - model",
                  "tab:red", "darkred")
    ax_p.set_ylabel(f"process {noun} [{unit}]")
    if result.effort_unit == "A" and factors and not force_panel:
        factor = factors[0]
        right = ax_p.secondary_yaxis("right", functions=(lambda i: i * factor, lambda f: f / factor))
        right.set_ylabel(load_label)
    if force_panel:  # two efficiencies: no single scale, the load gets a panel of its own
        process_panel(axes[3], result.load, result.load_bounds,
                      f"process {units.load} (driving: eta_d K_0 I, back-driven: K_0 I / eta_b)", "tab:green",
                      "darkgreen")
        axes[3].set_ylabel(load_label)
    standing = np.zeros(result.time.size, bool) if result.standstill is None else result.standstill
    beyond = None if result.outside is None else result.outside & ~standing
    for flags, label, color in ((beyond, "outside the training region", "tab:orange"),
                                (standing, "standstill: friction held unknown to the model, no process figure",
                                 "tab:purple")):
        if flags is not None and np.any(flags[shown]):
            for ax in axes[2:]:
                _mark_outside(ax, result.time[shown], flags[shown], max_points,
                              f"{label} ({100.0 * float(np.mean(flags)):.1f} % of the log)", color)
    axes[-1].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    title = " / ".join(part for part in (result.axis and f"axis {result.axis}",
                                         result.dataset and f"dataset {result.dataset}") if part) or "axis log"
    title += window_title(window)
    if result.source:
        title += f"  ({Path(result.source).name})"
    model = result.attrs.get("model_kind")
    if model:
        title += f", {model} model"
    figure.suptitle(title)
    return finish_figure(figure, path)


def plot_machine_process(result, path: str | os.PathLike | None = None, *,
                         max_points: int = ENVELOPE_POINTS, mean_s: float = 0.1,
                         window: tuple[float, float] | None = None):
    """Draw the process load of every axis of a machine, and the resultant force of its linear axes.

    One panel per axis: its process force [N] or torque [Nm] where the machine file gives the
    axis's mechanics, else its process current [A], with the moving mean over ``mean_s``; a last
    panel with the resultant process force when two or more linear axes have force.

    Parameters
    ----------
    result : MachineProcessResult
        Output of :func:`greybox.predict.machine.predict_machine`.
    path : path-like, optional
        Write the figure there (PNG, SVG or PDF by extension) and close it.
    max_points : int, default :data:`~greybox.evaluate.plots.ENVELOPE_POINTS`
        Longer logs are drawn as their envelope.
    mean_s : float, default 0.1
        Window [s] of the moving means; 0 draws none.
    window : (float, float), optional
        Draw only the samples with ``start <= time <= stop`` [s].

    Returns
    -------
    matplotlib.figure.Figure or pathlib.Path
        The figure, or the written file when ``path`` is given.

    Raises
    ------
    ValueError
        If no sample lies in ``window``.
    """
    time = result.time
    shown = _shown(time, window)
    columns = result.columns()
    panels = []
    for axis, axis_result in result.results.items():
        units = axis_result.units
        if axis_result.load is not None:
            column, what, unit = f"{axis}_{units.load}_process_{units.load_unit}", units.load, units.load_unit
        else:
            what, unit = axis_result.quantity, axis_result.shown_unit
            column = f"{axis}_{what.replace(' ', '_')}_process_{unit}"
        panels.append((columns[column], f"axis {axis}: process {what} [{unit}]"))
    resultant = result.resultant()
    if resultant is not None:
        panels.append((resultant, f"resultant process force |F| of {', '.join(result.forces())} [N]"))
    plt = import_pyplot(path)
    figure, axes = plt.subplots(len(panels), 1, sharex=True, figsize=(11, 2.4 * len(panels) + 1),
                                layout="constrained", squeeze=False)
    step = float(np.median(np.diff(time))) if time.size > 1 else 0.0
    mean_samples = max(1, int(round(mean_s / step))) if mean_s > 0 and step > 0 else 0
    for ax, (values, label) in zip(axes[:, 0], panels):
        ax.plot(*envelope(time[shown], values[shown], max_points), lw=0.6, color="tab:red", label="per sample")
        if mean_samples:
            ax.plot(*envelope(time[shown], moving_mean(values, mean_samples)[shown], max_points), lw=1.2,
                    color="darkred", label=f"moving mean over {mean_s:g} s")
        ax.axhline(0.0, color="black", lw=0.5)
        ax.set_ylabel(label, fontsize="small")
        ax.grid(True, alpha=0.3)
        legend_outside(ax)
    axes[-1, 0].set_xlabel("time [s]")
    title = (f"machine {result.name}" if result.name else "machine") + f": axes {', '.join(result.results)}"
    figure.suptitle(title + window_title(window))
    return finish_figure(figure, path)
