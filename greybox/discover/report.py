"""Reports of a discovery run: the JSON document and residual plots before and after.

:func:`write_json` writes :meth:`DiscoveryResult.to_dict` (strict JSON:
non-finite numbers become null); :func:`write_report` writes it with the
figures

``residual_train.png``, ``residual_test.png``
    Residual before (base model alone) and after (with the named effects):
    over time, binned along the position per direction, over the velocity,
    over the time since the start of the run and since the last change of
    motion, and the RMSE per regime.
``evidence.png``
    Every step's candidates: explained fraction of the residual against the
    fraction at which each would pass, and the period scans of the periodic
    effects at the first step that named one (else at the first step).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from ..atomic import write_text_atomic
from ..evaluate.plots import import_pyplot, legend_outside, save_figure
from ..json_values import jsonable
from .workflow import DiscoveryResult

__all__ = ["REPORT_FILES", "jsonable", "write_json", "plot_residuals", "plot_evidence", "write_report"]

#: Files :func:`write_report` writes into its directory.
REPORT_FILES = ("discovery.json", "residual_train.png", "residual_test.png", "evidence.png")

#: Most points drawn of a residual over time.
_MAX_POINTS = 20_000


def write_json(document: dict, path: str | os.PathLike) -> Path:
    """Write ``document`` as indented strict JSON, atomically; return the path.

    Parameters
    ----------
    document : dict
        Content to write, passed through :func:`jsonable` first.
    path : str or os.PathLike
        Target file.
    """
    return write_text_atomic(path, json.dumps(jsonable(document), indent=1, allow_nan=False) + "\n")


def _profile(ax, before: dict, after: dict, xlabel: str, title: str, log_x: bool = False) -> None:
    for profile, label, style in ((before, "before", "-"), (after, "after", "-")):
        keep = profile["n"] > 0
        ax.plot(profile["centre"][keep], profile["mean"][keep], style, lw=1.2, label=label)
    ax.axhline(0.0, color="k", lw=0.5)
    if log_x:
        ax.set_xscale("log")
    ax.set_xlabel(xlabel)
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)


def plot_residuals(result: DiscoveryResult, which: str, path) -> Path:
    """Residual figure of the training (``which="train"``) or test (``"test"``) runs; return the path.

    Parameters
    ----------
    result : DiscoveryResult
        Outcome of a discovery run, holding the residuals before and after.
    which : {"train", "test"}
        Which runs' residuals to draw; must be a key of ``result.residuals``.
    path : path-like
        Image file to write; the format follows its extension.
    """
    plt = import_pyplot(path)
    data = result.residuals[which]
    gap = result.train if which == "train" else result.test
    unit = result.unit
    figure, axes = plt.subplots(2, 3, figsize=(15, 8), layout="constrained")
    stride = max(1, int(np.ceil(data["time"].size / _MAX_POINTS)))
    ax = axes[0, 0]
    ax.plot(data["time"][::stride], data["before"][::stride], lw=0.4, alpha=0.7,
            label=f"before: RMSE {gap['rmse_before']:.4g} {unit}")
    ax.plot(data["time"][::stride], data["after"][::stride], lw=0.4, alpha=0.7,
            label=f"after: RMSE {gap['rmse_after']:.4g} {unit}")
    ax.set_xlabel("time [s] (runs one after the other)")
    ax.set_ylabel(f"residual [{unit}]")
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    before, after = data["profiles_before"], data["profiles_after"]
    ax = axes[0, 1]
    for name, colour in (("position_positive", "C0"), ("position_negative", "C1")):
        for profile, style, label in ((before[name], "-", "before"), (after[name], "--", "after")):
            keep = profile["n"] > 0
            ax.plot(profile["centre"][keep], profile["mean"][keep], style, color=colour, lw=1.0,
                    label=f"{label}, {name.split('_')[1]} motion")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel(result.units.relabel("position [mm]"))
    ax.set_title("mean residual along the position", fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    _profile(axes[0, 2], before["velocity"], after["velocity"], result.units.relabel("velocity [mm/s]"),
             "mean residual over velocity")
    _profile(axes[1, 0], before["time"], after["time"], "time since the start of the run [s]",
             "mean residual over time")
    _profile(axes[1, 1], before["after_reversal"], after["after_reversal"],
             "time since the motion started or reversed [s]", "mean residual x direction after a change",
             log_x=True)
    axes[1, 1].legend(fontsize=8)
    ax = axes[1, 2]
    names = [name for name, row in gap["regimes"].items() if row["n"] > 0]
    positions = np.arange(len(names))
    ax.bar(positions - 0.2, [gap["regimes"][n]["rmse_before"] for n in names], 0.4, label="before")
    ax.bar(positions + 0.2, [gap["regimes"][n]["rmse_after"] for n in names], 0.4, label="after")
    ax.set_xticks(positions, names, rotation=30, ha="right", fontsize=8)
    ax.set_ylabel(f"RMSE [{unit}]")
    ax.set_title("RMSE per regime", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(True, axis="y", alpha=0.3)
    named = ", ".join(e["name"] for e in result.effects) or "none"
    figure.suptitle(f"{which} logs: residual of the base model (before) and with the named effects "
                    f"(after: {named}); verdict {result.verdict}")
    return save_figure(figure, path)


def plot_evidence(result: DiscoveryResult, path) -> Path:
    """Evidence figure: candidates of every step against their thresholds, and period scans.

    Parameters
    ----------
    result : DiscoveryResult
        Outcome of a discovery run, with its steps' candidate scores.
    path : path-like
        Image file to write; the format follows its extension.
    """
    plt = import_pyplot(path)
    from matplotlib.patches import Patch

    n_steps = len(result.steps)
    figure, axes = plt.subplots(1, n_steps + 1, figsize=(4.5 * (n_steps + 1), 5), layout="constrained",
                                squeeze=False)
    for index, step in enumerate(result.steps):
        ax = axes[0, index]
        scores = list(step.candidates.values()) + [step.structure]
        names = [s.name for s in scores]
        positions = np.arange(len(scores))
        explained = [max(s.explained_fraction, 1e-8) for s in scores]
        colours = ["C2" if s.name == step.winner else ("C1" if s.passes else "C0") for s in scores]
        ax.barh(positions, explained, color=colours)
        thresholds = [s.threshold_fraction if np.isfinite(s.threshold_fraction) else np.nan for s in scores]
        ax.plot(thresholds, positions, "k|", ms=14, mew=2, label="passes beyond")
        ax.set_yticks(positions, names, fontsize=8)
        ax.set_xscale("log")
        ax.set_xlabel("explained fraction of the residual")
        ax.set_title(f"step {index + 1}: " + (f"adds {step.winner}" if step.winner else "nothing passes"),
                     fontsize=10)
        ax.grid(True, axis="x", alpha=0.3)
    marks, _ = axes[0, 0].get_legend_handles_labels()  # the same colours and marks in every step: one legend
    figure.legend(handles=[Patch(color="C2", label="added in this step"), Patch(color="C1", label="passes, not added"),
                           Patch(color="C0", label="does not pass"), *marks],
                  fontsize=8, loc="outside lower center", ncol=4)  # below every axis label, in the layout
    ax = axes[0, -1]
    shown = next((i for i, step in enumerate(result.steps)
                  if step.winner and step.candidates[step.winner].shape_name == "period_mm"), 0)
    for score in result.steps[shown].candidates.values():
        if score.scan is not None and score.shape_name == "period_mm":
            line, = ax.plot(score.scan["shape"], score.scan["explained_fraction"], lw=0.8, label=score.name)
            ax.axhline(score.threshold_fraction, color=line.get_color(), ls="--", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlabel(result.units.relabel("period [mm]"))
    ax.set_ylabel("explained fraction of the residual")
    ax.set_title(f"step {shown + 1}: period scans (dashed: pass level)", fontsize=10)
    if ax.get_legend_handles_labels()[0]:
        legend_outside(ax, fontsize=7)  # right of the curves, clear of the axis labels
    ax.grid(True, alpha=0.3)
    return save_figure(figure, path)


def write_report(result: DiscoveryResult, directory, document: dict | None = None) -> list[Path]:
    """Write ``discovery.json`` and the figures into ``directory`` (created if missing); return the paths.

    ``document`` replaces :meth:`DiscoveryResult.to_dict` as the JSON content if given.

    Parameters
    ----------
    result : DiscoveryResult
        Outcome of a discovery run.
    directory : path-like
        Folder to write :data:`REPORT_FILES` into (``residual_test.png`` only when there are test runs).
    document : dict, optional
        JSON content to write instead of ``result.to_dict()``.
    """
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    written = [write_json(document if document is not None else result.to_dict(), directory / "discovery.json")]
    for which in ("train", "test"):
        if which in result.residuals:
            written.append(plot_residuals(result, which, directory / f"residual_{which}.png"))
    written.append(plot_evidence(result, directory / "evidence.png"))
    return written
