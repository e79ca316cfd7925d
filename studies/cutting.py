"""Validation of ``greybox predict`` on the synthetic axis: recovery of a known cutting-force current.

Protocol:

1. every model kind is fitted with its default settings (as ``greybox train
   --model KIND`` does) on the shipped air cuts ``data/X_A.mcap`` and
   ``data/X_B.mcap``;
2. cutting logs come from :func:`greybox.twin.make_dataset` with a
   :class:`greybox.twin.cutting.CuttingSpec` (100 Hz tooth ripple, cutting on
   negative feed over the central 60 % of the travelled range) on trajectories
   not used in training: dataset C (random steps and sines, a new draw in the
   measurement window) and D (1200 mm/min over the whole travel, a speed not
   in training), with a seed other than the shipped data's. The cut strength
   (mean process current at 1000 mm/min, full engagement) is swept over
   ``--strengths``; ``--strength`` is the one of the detailed table;
3. :func:`greybox.predict.process.predict_process` gives the process current
   and force (axis metadata ``examples/axis_x.toml``); it is compared with
   the log's ``truth_process_A`` (and the force this truth implies);
4. the air-cut test RMSE is the model's RMSE on the shipped air cut of the
   same dataset (``data/X_C.mcap``, ``data/X_D.mcap``: seed 2024), the figure
   an ordinary evaluation of the model gives;
5. the correlation ceiling is the correlation of the true process current
   with itself plus the log's current noise (``truth_noise_A``): what a
   perfect model would reach;
6. the cut strength (and mean cut force) from which each model reaches the
   correlation target ``--target`` follows from the recovery error, which
   does not depend on the strength (:mod:`studies.cut_recovery`);
   the swept logs check this.

In the twin the cut changes neither the motion nor the noise, so the error of
the recovered process current equals the model's residual on the same
trajectory without the cut up to the 1 mA current resolution; the study
checks this (``air_identity_A``, the largest difference over all strengths).
On a machine the cut also changes the following error and the load on the
screw, so expect the process error to exceed the air-cut error there.

:func:`cutting_validation` runs the whole protocol and writes its files;
``scripts/cutting_validation.py`` is its command::

    python scripts/cutting_validation.py --markdown validation.md --json validation.json --plot-dir figures
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from greybox.atomic import check_output_path, write_text_atomic
from greybox.data.axis_config import read_axis_config
from greybox.data.io import read_log
from greybox.data.prepare import prepare
from greybox.errors import GreyboxError
from greybox.evaluate.plots import finish_figure, import_pyplot
from greybox.evaluate.report import MODEL_LABELS as LABELS
from greybox.metrics import rmse
from greybox.models.chunked import predict_chunked
from greybox.models.registry import MODEL_CLASSES
from greybox.predict.process import predict_process
from greybox.provenance import provenance, provenance_line
from greybox.twin import make_dataset
from greybox.twin.cutting import CuttingSpec
from studies.cut_recovery import correlation_at_strength, recovery_metrics, strength_for_correlation

__all__ = ["TRAIN_FILES", "TEST_DATASETS", "KINDS", "DEFAULT_STRENGTHS", "CuttingCase", "evaluate_model",
           "detail_table", "case_summary", "sweep_table", "plot_correlation_vs_force", "CuttingValidation",
           "cutting_validation"]

#: The shipped air cuts the models are fitted on.
TRAIN_FILES = ("X_A.mcap", "X_B.mcap")
#: Trajectories of the cutting logs.
TEST_DATASETS = ("C", "D")
#: Model kinds validated by default.
KINDS = ("coulomb", "stribeck", "lugre", "gms", "svr", "gmssvr")
#: Cut strengths swept by default [A at 1000 mm/min, full engagement].
DEFAULT_STRENGTHS = (0.25, 0.5, 1.0, 2.0)


class CuttingCase:
    """The cutting logs of one trajectory at every swept strength, and its air cut.

    Parameters
    ----------
    dataset : str
        Dataset id (C or D).
    seed : int
        Seed of the synthetic logs.
    strengths : sequence of float
        Cut strengths [A at the reference feed].
    data : Path
        Folder of the shipped air cuts.
    """

    def __init__(self, dataset: str, seed: int, strengths, data: Path):
        self.dataset = dataset
        self.name = f"X_{dataset} seed {seed}"
        self.strengths = tuple(strengths)
        logs = [make_dataset("X", dataset, seed=seed, cutting=CuttingSpec(strength_A=s)) for s in self.strengths]
        *self.cuts, self.air = prepare(logs + [make_dataset("X", dataset, seed=seed)])
        self.shipped = prepare([read_log(data / f"X_{dataset}.mcap")])[0]
        first = self.cuts[0]
        self.unit_truth = first.extras["truth_process_A"] / self.strengths[0]
        self.noise = first.extras["truth_noise_A"]
        self.cutting = self.unit_truth != 0.0

    def mean_cut_force_N(self, strength: float, factor: float) -> float:
        """Mean force [N] of the cut at ``strength`` (magnitude), over the samples in the cut.

        Parameters
        ----------
        strength : float
            Cut strength [A at 1000 mm/min, full engagement].
        factor : float
            Load constant turning the process current into force [N/A].
        """
        return float(abs(strength * factor * np.mean(self.unit_truth[self.cutting])))


def evaluate_model(kind: str, model, case: CuttingCase, config, detail_strength: float, target: float,
                   chunk_s: float) -> tuple[dict, object]:
    """All figures of one fitted model on one cutting case, and its result at the detailed strength.

    Parameters
    ----------
    kind : str
        Model kind (a key of :data:`greybox.models.registry.MODEL_CLASSES`), reported in the row.
    model : CurrentModel
        The model fitted on the air cuts.
    case : CuttingCase
        Cutting logs of one trajectory and its air cuts.
    config : AxisConfig
        Axis metadata; its driving load constant [N/A] turns current into force.
    detail_strength : float
        Cut strength of the detailed figures [A]; must be one of ``case.strengths``.
    target : float
        Correlation target of recovered and true process current.
    chunk_s : float
        Chunk length of the prediction [s].

    Raises
    ------
    ValueError
        If ``detail_strength`` is not one of ``case.strengths`` (before any prediction).
    """
    if not np.any(np.isclose(case.strengths, detail_strength)):
        raise ValueError(f"detail_strength {detail_strength:g} A is not one of the case's cut strengths "
                         f"({', '.join(f'{s:g}' for s in case.strengths)} A)")
    factor = config.load_constants[0]  # the cuts oppose the motion: driving
    air_residual = case.air.current - predict_chunked(model, case.air, chunk_s=chunk_s)
    air_test = rmse(case.shipped.current, predict_chunked(model, case.shipped, chunk_s=chunk_s))
    identity = 0.0
    by_strength = {}
    detail = None
    for strength, cut in zip(case.strengths, case.cuts):
        truth = cut.extras["truth_process_A"]
        result = predict_process(model, cut, axis_config=config, chunk_s=chunk_s)
        identity = max(identity, float(np.max(np.abs(result.process - truth - air_residual))))
        metrics = recovery_metrics(truth, result.process, cut.extras["truth_noise_A"], factor)
        by_strength[f"{strength:g}"] = {"strength_A": strength, **metrics}
        if np.isclose(strength, detail_strength):
            detail = (metrics, result)
    error = -air_residual
    needed = strength_for_correlation(case.unit_truth, error, target)
    row = {
        "model": kind,
        "test": case.name,
        "air_test_rmse_A": air_test,
        "air_same_trajectory_rmse_A": float(np.sqrt(np.mean(air_residual**2))),
        "air_identity_A": identity,
        **detail[0],
        "by_strength": by_strength,
        "target": target,
        "strength_for_target_A": float(needed) if np.isfinite(needed) else None,
        "mean_cut_force_for_target_N": case.mean_cut_force_N(needed, factor) if np.isfinite(needed) else None,
    }
    return row, detail[1]


def detail_table(rows: list[dict]) -> str:
    """The detailed figures at one strength as a Markdown table.

    Parameters
    ----------
    rows : list of dict
        One per model and cutting log: the row :func:`evaluate_model` returns first.
    """
    lines = [
        "| model | cutting log | air-cut test RMSE [A] | process RMSE [A] | correlation (ceiling) "
        "| process RMSE in cut [A] | force RMSE [N] | mean cut force true / estimated [N] |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for row in rows:
        lines.append(
            f"| {LABELS[row['model']]} | {row['test']} | {row['air_test_rmse_A']:.4f} | {row['process_rmse_A']:.4f} "
            f"| {row['correlation']:.3f} ({row['correlation_ceiling']:.3f}) | {row['process_rmse_in_cut_A']:.4f} "
            f"| {row['force_rmse_N']:.1f} "
            f"| {row['mean_cut_force_true_N']:.1f} / {row['mean_cut_force_estimated_N']:.1f} |"
        )
    return "\n".join(lines) + "\n"


def case_summary(case: CuttingCase, factor: float, target: float) -> dict:
    """What a perfect model reaches on one cutting case, and the case's cut forces, as plain numbers.

    Parameters
    ----------
    case : CuttingCase
        Cutting logs of one trajectory.
    factor : float
        Driving load constant of the axis [N/A], turning process current into cut force.
    target : float
        Correlation target of recovered and true process current.

    Returns
    -------
    dict
        ``name``, ``strengths_A``, ``mean_cut_force_N`` and ``ceiling`` (the correlation of a perfect model)
        per strength, ``strength_for_target_A`` and ``mean_cut_force_for_target_N`` of a perfect model (None
        when not reached), ``noise_rms_A`` (RMS of the log's current noise [A]).
    """
    needed = strength_for_correlation(case.unit_truth, case.noise, target)
    reached = bool(np.isfinite(needed))
    return {"name": case.name, "strengths_A": list(case.strengths),
            "mean_cut_force_N": [case.mean_cut_force_N(s, factor) for s in case.strengths],
            "ceiling": [float(correlation_at_strength(case.unit_truth, case.noise, s)) for s in case.strengths],
            "strength_for_target_A": float(needed) if reached else None,
            "mean_cut_force_for_target_N": case.mean_cut_force_N(needed, factor) if reached else None,
            "noise_rms_A": float(np.sqrt(np.mean(case.noise ** 2)))}


def sweep_table(rows: list[dict], cases: list[dict], target: float) -> str:
    """Correlation per cut strength and the mean cut force needed for the target, as a Markdown table.

    Parameters
    ----------
    rows : list of dict
        One per model and cutting log: the row :func:`evaluate_model` returns first.
    cases : list of dict
        One per cutting log, as :func:`case_summary` gives them; the swept strengths are those of the first.
    target : float
        Correlation target of recovered and true process current.
    """
    strengths = cases[0]["strengths_A"]
    header = " | ".join(f"r at {s:g} A" for s in strengths)
    lines = [f"| model | cutting log | {header} | r >= {target:g} from a cut of [A] / mean force [N] |",
             "|---|---|" + "---:|" * len(strengths) + "---:|"]
    for case in cases:
        name = case["name"]
        forces = ", ".join(f"{s:g} A: {force:.0f} N" for s, force in zip(strengths, case["mean_cut_force_N"]))
        lines.append(f"| perfect model (noise only) | {name} ({forces}) | "
                     + " | ".join(f"{r:.3f}" for r in case["ceiling"])
                     + f" | {_needed(case['strength_for_target_A'], case['mean_cut_force_for_target_N'])} |")
        for row in rows:
            if row["test"] != name:
                continue
            cells = " | ".join(f"{row['by_strength'][f'{s:g}']['correlation']:.3f}" for s in strengths)
            lines.append(f"| {LABELS[row['model']]} | {name} | {cells} "
                         f"| {_needed(row['strength_for_target_A'], row['mean_cut_force_for_target_N'])} |")
    return "\n".join(lines) + "\n"


def _needed(strength: float | None, force: float | None) -> str:
    if strength is None or not np.isfinite(strength):
        return "not reached"
    return f"{strength:.2f} / {force:.0f}"


def plot_correlation_vs_force(rows: list[dict], cases: dict, factor: float, target: float, path: Path):
    """Correlation of recovered and true process current against the mean cut force, one panel per log.

    Parameters
    ----------
    rows : list of dict
        One per model and cutting log: the row :func:`evaluate_model` returns first.
    cases : dict
        ``{name: CuttingCase}``, one panel each.
    factor : float
        Driving load constant of the axis [N/A], turning process current into cut force.
    target : float
        Correlation target of recovered and true process current.
    path : Path or None
        Image file to write; None returns the figure instead of the path.
    """
    plt = import_pyplot(path)
    figure, axes = plt.subplots(1, len(cases), figsize=(5.5 * len(cases), 4.5), layout="constrained",
                                sharey=True, squeeze=False)
    for ax, (name, case) in zip(axes[0], cases.items()):
        strengths = np.geomspace(0.05, 5.0, 60)
        force = [case.mean_cut_force_N(s, factor) for s in strengths]
        ceiling = [correlation_at_strength(case.unit_truth, case.noise, s) for s in strengths]
        ax.plot(force, ceiling, color="black", lw=1.5, ls="--", label="perfect model (noise only)")
        for row in rows:
            if row["test"] != name:
                continue
            swept = sorted(row["by_strength"].values(), key=lambda item: item["strength_A"])
            ax.plot([case.mean_cut_force_N(item["strength_A"], factor) for item in swept],
                    [item["correlation"] for item in swept], marker="o", lw=1.2, label=LABELS[row["model"]])
        ax.axhline(target, color="tab:red", lw=0.8, label=f"target r = {target:g}")
        ax.set_xscale("log")
        ax.set_xlabel("mean cut force [N]")
        ax.set_title(name)
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].set_ylabel("correlation of recovered and true process current")
    axes[0][0].set_ylim(0.0, 1.0)
    axes[0][-1].legend(loc="lower right", fontsize="small")
    return finish_figure(figure, path)


@dataclass
class CuttingValidation:
    """What :func:`cutting_validation` measured and wrote.

    Attributes
    ----------
    rows : list of dict
        One per model and cutting log: the figures of :func:`evaluate_model`
        and ``fit_s``, the model's fit time [s].
    cases : dict
        ``{name: CuttingCase}``.
    force_constant_N_per_A : float
        Of the axis metadata.
    tables : str
        The detailed and the sweep table (Markdown).
    noise_rms_A : dict
        ``{case name: RMS of the log's current noise [A]}``, the noise floor.
    summaries : list of dict
        One per cutting log, as :func:`case_summary` gives them.
    figure : pathlib.Path or None
        The correlation figure, when drawn.
    """

    rows: list[dict]
    cases: dict
    force_constant_N_per_A: float
    tables: str
    noise_rms_A: dict
    summaries: list
    figure: Path | None = None


def cutting_validation(data: str | os.PathLike, axis_config: str | os.PathLike, *, seed: int = 7,
                       kinds=KINDS, strengths=DEFAULT_STRENGTHS, strength: float = CuttingSpec().strength_A,
                       target: float = 0.95, chunk_s: float = 60.0, markdown_path=None, json_path=None,
                       plot_dir=None, progress=None, force: bool = False) -> CuttingValidation:
    """Run the protocol: fit every kind on the air cuts, recover the cut of every log, write the outputs.

    Parameters
    ----------
    data : path-like
        Folder of the shipped air cuts ``X_A.mcap`` ... ``X_D.mcap``.
    axis_config : path-like
        Axis metadata (TOML) giving the force constant.
    seed : int, default 7
        Seed of the cutting logs (the shipped data use 2024).
    kinds : sequence of str, default :data:`KINDS`
        Model kinds of :data:`greybox.models.registry.MODEL_CLASSES`, fitted with their defaults.
    strengths : sequence of float, default :data:`DEFAULT_STRENGTHS`
        Cut strengths swept [A at 1000 mm/min, full engagement].
    strength : float
        Cut strength of the detailed table [A], one of ``strengths``.
    target : float, default 0.95
        Correlation target.
    chunk_s : float, default 60.0
        Chunk length of the prediction [s].
    markdown_path, json_path : path-like, optional
        Write the tables, and all figures as JSON, there.
    plot_dir : path-like, optional
        Folder (created) of the correlation figure and of one picture per
        model and cutting log at the detailed strength.
    progress : callable, optional
        Receives one line of text at the start and per model and log.
    force : bool, default False
        Overwrite existing output files and write into a non-empty ``plot_dir``.

    Returns
    -------
    CuttingValidation

    Raises
    ------
    GreyboxError
        If a kind is not registered, ``strength`` is not one of ``strengths``,
        or an output exists without ``force`` or is an input (before any
        work), or a log cannot be read.
    """
    say = progress or (lambda line: None)
    strengths = tuple(strengths)
    unknown = sorted(set(kinds) - set(MODEL_CLASSES))
    if unknown:
        raise GreyboxError(f"unknown model kind(s) {unknown}; known: {sorted(MODEL_CLASSES)}")
    if not any(np.isclose(strength, s) for s in strengths):
        raise GreyboxError(f"strength {strength:g} is not one of the swept strengths {strengths}")
    data, axis_config = Path(data), Path(axis_config)
    inputs = [data / name for name in TRAIN_FILES] + [axis_config]
    for out in (markdown_path, json_path):
        if out:
            check_output_path(out, overwrite=force, protect=inputs, inputs_name="one of the inputs")
    if plot_dir and Path(plot_dir).is_dir() and any(Path(plot_dir).iterdir()) and not force:
        raise GreyboxError(f"{plot_dir}: directory is not empty; nothing was written (pass --force to write into it)")
    config = read_axis_config(axis_config)
    factor = config.load_constants[0]  # the cuts oppose the motion: driving
    train = prepare([read_log(data / name) for name in TRAIN_FILES])
    cases = {case.name: case for case in (CuttingCase(d, seed, strengths, data) for d in TEST_DATASETS)}
    say(f"training on {', '.join(TRAIN_FILES)} ({sum(len(r) for r in train)} samples); "
        f"force constant {factor:.1f} N/A from {axis_config.name}; cut strengths "
        f"{', '.join(f'{s:g}' for s in strengths)} A")
    if plot_dir:
        plot_dir = Path(plot_dir)
        plot_dir.mkdir(parents=True, exist_ok=True)

    rows = []
    for kind in kinds:
        started = time.perf_counter()
        model = MODEL_CLASSES[kind]().fit(train)
        fit_s = time.perf_counter() - started
        for name, case in cases.items():
            row, result = evaluate_model(kind, model, case, config, strength, target, chunk_s)
            rows.append({**row, "fit_s": fit_s})
            swept = "  ".join(f"{s:g} A: {row['by_strength'][f'{s:g}']['correlation']:.3f}" for s in strengths)
            say(f"{kind:<9} {name:<14} fit {fit_s:6.1f} s  air-cut test RMSE {row['air_test_rmse_A']:.4f} A  "
                f"process RMSE {row['process_rmse_A']:.4f} A  r {swept}  "
                f"|process error - air residual| <= {row['air_identity_A'] * 1e3:.2f} mA")
            if plot_dir:
                from greybox.predict.plot import plot_process

                plot_process(result, plot_dir / f"predict_{kind}_X_{case.dataset}.png")

    summaries = [case_summary(case, factor, target) for case in cases.values()]
    tables = (f"Cut strength {strength:g} A at 1000 mm/min:\n\n" + detail_table(rows)
              + "\nCorrelation by cut strength:\n\n" + sweep_table(rows, summaries, target))
    noise = {summary["name"]: summary["noise_rms_A"] for summary in summaries}
    machine = provenance()
    if markdown_path:
        write_text_atomic(markdown_path, f"{tables}\nMeasured with {provenance_line(machine)}.\n")
    if json_path:
        write_text_atomic(json_path, json.dumps({
            "seed": seed, "train": list(TRAIN_FILES), "axis_config": str(axis_config),
            "force_constant_N_per_A": factor, "strengths_A": list(strengths), "detail_strength_A": strength,
            "target": target, "provenance": machine, "rows": rows, "cases": summaries}, indent=2) + "\n")
    figure = None
    if plot_dir:
        figure = plot_correlation_vs_force(rows, cases, factor, target, plot_dir / "correlation_vs_cut_force.png")
    return CuttingValidation(rows, cases, factor, tables, noise, summaries, figure)
