"""Metric records of fitted models tested on logs, and the report of ``greybox evaluate``.

A *metric record* (:func:`metric_record`) holds the errors of one model on
one side (``train`` or ``test``) of an experiment or evaluation: RMSE [A], RE
[%], NMSE [%], largest error [A], and the errors per run. The tables and files
of :mod:`greybox.evaluate.report` are built from such records, those of the
paper's experiments (:mod:`greybox.reproduce.experiments`) as those of
:func:`evaluate_models`.

When the logs carry the noise-free current (the extra channel
:data:`TRUTH_CHANNEL` of the synthetic axis), a :data:`NOISE_FLOOR` record
gives the error of that truth against the measured current: the best any
model can do.
"""

from __future__ import annotations

import os
import textwrap
import warnings
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from ..data.log import split_runs
from ..metrics import metrics_table
from ..models.estimator import EXTRAPOLATION_WARNING_SHARE, extrapolates, outside_any
from ..models.registry import model_kind
from .figures import effort_name, error_boxplot, residual_vs_position, time_comparison
from .regimes import metrics_by_regime
from .report import evaluation_table, per_log_table, regime_table, training_region_table, write_report

__all__ = ["NOISE_FLOOR", "TRUTH_CHANNEL", "metric_record", "evaluate_models", "training_region",
           "write_evaluation_report"]

#: Model name of the records that compare the noise-free current with the measured one.
NOISE_FLOOR = "noise_floor"
#: Extra channel of a log holding the noise-free current [A] (synthetic axis).
TRUTH_CHANNEL = "truth_current_A"


def metric_record(experiment: int | None, axis: str, model: str, dataset: str, measured, modelled,
                  logs: Sequence[str], per_log: Mapping[str, tuple] | None = None) -> dict:
    """One record of ``metrics.json``.

    Parameters
    ----------
    experiment : int or None
        Experiment number (None outside the paper's experiments).
    axis, model : str
        Axis and model name.
    dataset : {"train", "test"}
        Which side of the experiment the record describes.
    measured, modelled : array_like
        Measured and modelled current [A], the runs concatenated.
    logs : sequence of str
        Names of the runs (datasets) concatenated.
    per_log : dict, optional
        ``{name: (measured, modelled)}`` of every run, for the per-run errors.

    Returns
    -------
    dict
        ``experiment``, ``axis``, ``model``, ``dataset``, ``rmse`` [A],
        ``re`` [%] (RMSE over mean absolute current), plus ``logs`` (e.g.
        ``"C+D"``), ``n``, ``nmse`` [%], ``max_error`` [A] and ``per_log``
        (``{name: {"n", "rmse", "re", "nmse"}}``).
    """
    table = metrics_table(measured, modelled)
    record = {"experiment": experiment, "axis": axis, "model": model, "dataset": dataset,
              "rmse": table["rmse"], "re": table["re"], "logs": "+".join(logs), "n": table["n"],
              "nmse": table["nmse"], "max_error": table["max_error"]}
    if per_log:
        record["per_log"] = {}
        for name, (y, y_hat) in per_log.items():
            part = metrics_table(y, y_hat)
            record["per_log"][name] = {"n": part["n"], "rmse": part["rmse"], "re": part["re"],
                                       "nmse": part["nmse"]}
    return record


def evaluate_models(models: dict, runs, run_names) -> tuple[list[dict], dict]:
    """Metric records (with per-regime metrics) of every model on the runs, and the predictions.

    Parameters
    ----------
    models : dict
        ``{name: fitted model}``.
    runs : list of AxisLog
        Prepared test runs.
    run_names : list of str
        Their names in the records.

    Returns
    -------
    records : list of dict
        One ``test`` record per model (see
        :func:`metric_record`) with ``kind``, ``regimes``,
        ``training_region`` (:func:`training_region`) and
        ``effort_unit`` (the unit of RMSE and largest error: "A", or "N"
        for force logs) added, plus a ``noise_floor`` record when every run
        carries the noise-free current. The ``regimes`` of a model that
        records its training region add ``inside_training`` and
        ``outside_training`` (:data:`~greybox.evaluate.regimes.TRAINING_REGION_NAMES`).
    predictions : dict
        ``{name: predicted current [A] (or force [N]), runs concatenated}``.

    Raises
    ------
    ValueError
        If the runs carry different effort units.

    Warns
    -----
    UserWarning
        Per model and test run where more than
        :data:`~greybox.models.estimator.EXTRAPOLATION_WARNING_SHARE` of the samples lie outside the
        model's training region (with the RMSE there and inside); once per model whose file has no
        record of that region.
    """
    _, unit = effort_name(runs)
    axis = "/".join(dict.fromkeys(run.axis for run in runs if run.axis))
    measured = np.concatenate([run.effort for run in runs])
    predictions = {name: model.predict(runs) for name, model in models.items()}
    if all(TRUTH_CHANNEL in run.extras for run in runs):
        predictions[NOISE_FLOOR] = np.concatenate([run.extras[TRUTH_CHANNEL] for run in runs])
    records = []
    for name, prediction in predictions.items():
        parts = split_runs(runs, prediction)
        per_log = {n: (run.effort, p) for n, run, p in zip(run_names, runs, parts)}
        record = metric_record(None, axis, name, "test", measured, prediction, run_names, per_log)
        record["kind"] = model_kind(models[name]) if name in models else NOISE_FLOOR
        flags = [models[name].outside_training(run) for run in runs] if name in models else None
        outside = None if not flags or not all(flags) else [outside_any(f) for f in flags]
        record["regimes"] = metrics_by_regime(runs, prediction, outside=outside)
        record["effort_unit"] = unit
        if flags is not None:
            record["training_region"] = training_region(name, runs, run_names, parts, flags)
        records.append(record)
    return records, predictions


#: Words for the quantities of ``outside_training`` in the notes of :func:`training_region`.
_REGION_WORDS = {"position": "positions", "velocity": "speeds", "acceleration": "accelerations",
                 "motion": "motion never trained on",
                 "inputs": "kernel inputs", "effort": "predicted efforts beyond the trained ones"}


def _log_label(run, name: str) -> str:
    """The test log as a note names it: its file name, or the run's name when the file was split or has none."""
    source = Path(run.source) if run.source else None
    return source.name if source is not None and source.stem == name else name


def training_region(model: str, runs, run_names: Sequence[str], predictions: Sequence[np.ndarray],
                    flags: Sequence[dict]) -> dict:
    """The errors of one model inside and outside its training region, per test run; warns where it extrapolates.

    Parameters
    ----------
    model : str
        Model name, as the notes name it.
    runs : list of AxisLog
        Prepared test runs; ``effort`` is the measured value [A or N].
    run_names : sequence of str
        Their names in the records.
    predictions : sequence of ndarray
        The model's prediction of each run, same unit.
    flags : sequence of dict
        :meth:`~greybox.models.estimator.CurrentModel.outside_training` of each run (empty dicts for a
        model file without the record).

    Returns
    -------
    dict
        ``{"share": None, "reason": str}`` without the record, else ``{"share": float, "warn_above": float,
        "per_log": {name: {"share", "by", "inside", "outside"}}}``: the share of all samples outside [-],
        and per run that share, the share per quantity (``{"position": ...}``) and the metrics
        (``n``, ``rmse``, ``re``, ``nmse``) inside and outside.

    Warns
    -----
    UserWarning
        As :func:`evaluate_models`.
    """
    if not all(flags):
        warnings.warn(f"{model}: the model file has no record of its training region (written before greybox "
                      "kept one), so there are no inside_training and outside_training rows; retrain it to get "
                      "them", UserWarning, stacklevel=3)
        return {"share": None, "reason": "the model file has no record of its training region"}
    per_log, n_outside = {}, 0
    for run, name, predicted, flagged in zip(runs, run_names, predictions, flags):
        beyond = outside_any(flagged)
        n_outside += int(np.count_nonzero(beyond))
        share = float(np.mean(beyond))
        by = {quantity: float(np.mean(f)) for quantity, f in flagged.items()}
        parts = {side: metrics_table(run.effort[mask], predicted[mask]) for side, mask in
                 (("inside", ~beyond), ("outside", beyond))}
        per_log[name] = {"share": share, "by": by, **{side: {key: table[key] for key in ("n", "rmse", "re", "nmse")}
                                                      for side, table in parts.items()}}
        if extrapolates(by, share):
            words = ", ".join(f"{_REGION_WORDS.get(q, q)} {100 * value:.1f} %" for q, value in by.items() if value)
            unit = effort_name([run])[1]
            inside = parts["inside"]["rmse"]
            against = f"{inside:.3g} {unit} inside" if parts["inside"]["n"] else "no sample inside"
            warnings.warn(f"{_log_label(run, name)}: {100 * share:.1f} % of the samples lie outside what model "
                          f"{model} was trained on ({words}); RMSE there {parts['outside']['rmse']:.3g} {unit} "
                          f"against {against}", UserWarning, stacklevel=3)
    total = sum(len(run) for run in runs)
    return {"share": n_outside / total if total else float("nan"), "warn_above": EXTRAPOLATION_WARNING_SHARE,
            "per_log": per_log}


def _report_parts(records, predictions, runs, run_names, out_dir: Path | None):
    """Figures (``(caption, path)``, or ``(caption, open figure)`` without ``out_dir``), tables, title and
    introduction of the evaluation report."""
    tests = "+".join(run_names)
    noun, unit = effort_name(runs)
    models = {name: p for name, p in predictions.items() if name != NOISE_FLOOR}

    def target(name: str):
        return None if out_dir is None else out_dir / name

    figures = [
        (f"Absolute error [{unit}] of each model on {tests} (boxes: quartiles, whiskers: 5th-95th percentile)",
         error_boxplot([(f"test on {tests}", runs, predictions)], target("error_boxplot.png"))),
        (f"Measured and modelled {noun} [{unit}] on {tests}",
         time_comparison(runs, models, target("time_comparison.png"), names=run_names)),
        (f"Measured minus modelled {noun} [{unit}] against position, by direction of motion, on {tests}",
         residual_vs_position(runs, models, target("residual_position.png"))),
    ]
    tables = [evaluation_table(records, unit=unit)]
    if len(runs) > 1:
        tables.append(per_log_table(records, unit=unit))
    tables.append(regime_table(records))
    if any("training_region" in record for record in records):
        tables.append(training_region_table(records, unit=unit))
    intro = f"Models tested on {tests}; the logs' effort is {noun} in {unit}."
    return figures, tables, "greybox: model evaluation", intro


#: Text lines per page of the PDF report, and their spacing [share of the page height] (7 pt on A4 landscape).
_PAGE_LINES = 62
_LINE_HEIGHT = 0.0138
#: Characters per line of the PDF report's text (7 pt monospace across A4 landscape).
_TEXT_WIDTH = 170


def _wrapped(text: str) -> list[tuple[str, bool]]:
    """A paragraph as lines of at most :data:`_TEXT_WIDTH` characters, none of them bold."""
    return [(line, False) for line in textwrap.wrap(text, _TEXT_WIDTH)] or [("", False)]


def write_evaluation_pdf(path: str | os.PathLike, records: Sequence[Mapping], predictions: Mapping, runs,
                         run_names: Sequence[str]) -> Path:
    """The report of ``greybox evaluate`` as one PDF file a person can send: tables, then the figures.

    Page 1 holds the title, the tables as plain text (the rows of ``tables.md``) and where the figures were measured
    (:func:`greybox.provenance.provenance_line`); each figure follows on a page of its own, its caption
    above it. Written with matplotlib's PDF backend, atomically.

    Parameters
    ----------
    path : path-like
        PDF file to write.
    records, predictions, runs, run_names
        As :func:`write_evaluation_report`.

    Returns
    -------
    pathlib.Path
    """
    from matplotlib.backends.backend_pdf import PdfPages

    from ..atomic import atomic_output
    from ..provenance import provenance_line
    from .plots import import_pyplot

    path = Path(path)
    plt = import_pyplot(path)
    figures, tables, title, intro = _report_parts(records, predictions, runs, run_names, None)
    lines = _wrapped(intro) + [("", False)]
    for table in tables:
        text = table.to_text()
        lines += [(text[0], True), *((row, False) for row in text[1:len(table.rows) + 3])]
        lines += [wrapped for note in text[len(table.rows) + 3:] for wrapped in _wrapped(note)] + [("", False)]
    lines += _wrapped(provenance_line())
    pages = []
    try:
        for start in range(0, len(lines), _PAGE_LINES):
            page = plt.figure(figsize=(11.69, 8.27))  # A4 landscape [in]
            page.text(0.04, 0.95, title if start == 0 else f"{title} (continued)", fontsize=14, weight="bold",
                      va="top")
            for k, (text, bold) in enumerate(lines[start:start + _PAGE_LINES]):
                page.text(0.04, 0.89 - k * _LINE_HEIGHT, text, family="monospace", fontsize=7, va="top",
                          weight="bold" if bold else "normal")
            pages.append(page)
        for caption, figure in figures:
            width_chars = int(figure.get_figwidth() * 72 / (0.55 * 9))  # 9 pt text, about 0.55 em a character
            figure.suptitle(textwrap.fill(caption, width_chars), fontsize=9)
            if not figure.get_layout_engine():
                figure.set_layout_engine("constrained")  # room for the caption above the axes
            pages.append(figure)
        with atomic_output(path) as temporary:
            with PdfPages(temporary, metadata={"Title": title, "Creator": "greybox evaluate"}) as document:
                for page in pages:
                    document.savefig(page)
    finally:
        for page in [*pages, *(figure for _, figure in figures if figure not in pages)]:
            plt.close(page)
    return path


def write_evaluation_report(out_dir: str | os.PathLike, records: Sequence[Mapping], predictions: Mapping,
                            runs, run_names: Sequence[str]) -> dict[str, Path]:
    """The report of ``greybox evaluate``: error and regime tables, three figures, the HTML page.

    Parameters
    ----------
    out_dir : path-like
        Report directory (created if missing).
    records : sequence of dict
        Records of :func:`evaluate_models`.
    predictions : dict
        ``{model: predicted current [A] (or force [N]), runs concatenated}``.
    runs : list of AxisLog
        Prepared test runs; tables and figures are labelled in their effort unit (A, or N for force logs).
    run_names : sequence of str
        Their names.

    Returns
    -------
    dict
        As :func:`greybox.evaluate.report.write_report`, plus ``figures``.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(exist_ok=True)
    figures, tables, title, intro = _report_parts(records, predictions, runs, run_names, out_dir)
    files = write_report(out_dir, records, tables, figures, title=title, intro=intro)
    files["figures"] = [path for _, path in figures]
    return files
