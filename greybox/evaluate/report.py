"""Report files of model comparisons: metric records, tables in the paper's layout.

A report is built from *metric records*, one per model, axis, experiment and
side (``train`` or ``test``), as made by
:func:`greybox.evaluate.records.metric_record`::

    {"experiment": 1, "axis": "X", "model": "gms", "dataset": "test",
     "rmse": 0.071, "re": 7.2, "logs": "C", "n": 60552, "nmse": ..., "max_error": ...,
     "per_log": {"C": {"n": ..., "rmse": ..., "re": ...}}}

with RMSE in A and RE in %. RE is ``RMSE / mean(|I|)``: the paper divides by
the mean of the current, which is close to zero for an axis that moves both
ways, so the mean *absolute* current is used (:mod:`greybox.metrics`).

Files written by :func:`write_report`:

``metrics.json``
    The list of records (NaN written as null).
``metrics.csv``
    The same records without ``per_log``, one row each.
``tables.md``
    Markdown tables (:class:`~greybox.evaluate.table.Table`): one per experiment in the layout of
    the paper's Tables 3 and 4 with the published figures beside ours, the
    checks of the paper's pattern and the sole SVR beside the paper's figures
    (:mod:`greybox.evaluate.pattern`), the SVR hyperparameters like the paper's Table 2, the noise-floor ratio of the
    grey-box model, the sole SVR's change from training to each test log, and
    the fit times.
``index.html``
    Tables and figures on one page (:mod:`greybox.evaluate.html`).
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from pathlib import Path
from typing import Iterable, Mapping, Sequence

from ..atomic import write_text_atomic
from ..data.operating import SPAN_WINDOW_S
from ..json_values import jsonable
from ..provenance import provenance, provenance_line
from .html import write_html
from .paper import PAPER_RE, PAPER_SOURCE
from .pattern import paper_pattern, paper_pattern_table, sole_svr_beside_paper, sole_svr_table
from .table import Table

__all__ = [
    "MODEL_LABELS",
    "PAPER_RE",
    "PAPER_SOURCE",
    "RE_NOTE",
    "CSV_COLUMNS",
    "check_output_dir",
    "records_json",
    "write_metrics",
    "experiment_table",
    "hyperparameter_table",
    "noise_floor_ratios",
    "noise_floor_table",
    "svr_generalisation",
    "svr_generalisation_table",
    "timing_table",
    "evaluation_table",
    "per_log_table",
    "regime_table",
    "training_region_table",
    "report_tables",
    "tables_markdown",
    "write_report",
]

#: How reports name the models.
MODEL_LABELS = {
    "coulomb": "Coulomb",
    "stribeck": "Stribeck",
    "lugre": "LuGre",
    "gms": "GMS",
    "svr": "SVR",
    "gmssvr": "GMS+SVR",
    "gmssvr_eq8": "GMS+SVR (eq. 8)",
    "noise_floor": "noise floor (noise-free current)",
}

#: The definition of RE, printed wherever RE is.
RE_NOTE = (
    "RE = RMSE / mean(|I|) in %. The paper divides by the mean of I; for a signed current of an axis "
    "moving both ways that mean is near zero, so the mean absolute current is used."
)

#: Columns of ``metrics.csv``, in order.
CSV_COLUMNS = ("experiment", "axis", "model", "dataset", "logs", "n", "rmse", "re", "nmse", "max_error")


# ---------------------------------------------------------------- writing files
def check_output_dir(out_dir: str | os.PathLike, *, force: bool = False) -> Path:
    """Refuse a report directory that is a file, or that is not empty unless ``force``.

    Called before any work, so that a long run never ends in a refusal.

    Parameters
    ----------
    out_dir : path-like
        Report directory; it need not exist, but its parent must.
    force : bool, default False
        Accept a directory that already holds files (the report then overwrites its own files there).

    Returns
    -------
    pathlib.Path

    Raises
    ------
    GreyboxError
        If ``out_dir`` is a file, its parent does not exist, or it holds files
        and ``force`` is false.
    """
    from ..errors import GreyboxError

    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise GreyboxError(f"{out_dir}: is a file, not a directory")
    if not out_dir.exists() and not out_dir.parent.is_dir():
        raise GreyboxError(f"{out_dir}: parent directory {out_dir.parent} does not exist")
    if out_dir.is_dir() and any(out_dir.iterdir()) and not force:
        raise GreyboxError(f"{out_dir}: directory is not empty; use --force to write the report into it anyway")
    return out_dir


def records_json(records: Sequence[Mapping]) -> str:
    """Metric records as strict JSON text (non-finite numbers as null), one key per line.

    Parameters
    ----------
    records : sequence of dict
        Metric records.
    """
    return json.dumps(jsonable(list(records)), indent=1, allow_nan=False) + "\n"


def write_metrics(records: Sequence[Mapping], out_dir: str | os.PathLike) -> tuple[Path, Path]:
    """Write ``metrics.json`` and ``metrics.csv`` into ``out_dir``.

    Parameters
    ----------
    records : sequence of dict
        Metric records; the CSV keeps the keys of :data:`CSV_COLUMNS` only.
    out_dir : path-like
        Existing directory.

    Returns
    -------
    (Path, Path)
        The JSON and the CSV file.
    """
    out_dir = Path(out_dir)
    json_path = write_text_atomic(out_dir / "metrics.json", records_json(records))
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=CSV_COLUMNS, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for record in records:
        writer.writerow({k: ("" if v is None else v) for k, v in jsonable(dict(record)).items()})
    csv_path = write_text_atomic(out_dir / "metrics.csv", buffer.getvalue())
    return json_path, csv_path


# ---------------------------------------------------------------- tables
def _number(value, digits: int) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    return f"{value:.{digits}f}"


def _label(model: str) -> str:
    return MODEL_LABELS.get(model, model)


def _index(records: Iterable[Mapping]) -> dict[tuple, Mapping]:
    return {(r["experiment"], r["axis"], r["model"], r["dataset"]): r for r in records}


def _ordered(values: Iterable) -> list:
    return list(dict.fromkeys(values))


def experiment_table(records: Sequence[Mapping], experiment: int, *, title: str | None = None,
                     training: Mapping[str, str] | None = None, notes: Sequence[str] = (),
                     paper: Mapping[tuple[int, str, str], float] = PAPER_RE) -> Table:
    """Train and test errors of every model of one experiment, axes side by side.

    Rows are the models in the order of the records, the noise floor last;
    per axis the columns are train RMSE [A], train RE [%], test RMSE [A],
    test RE [%] and the paper's test RE [%].

    Parameters
    ----------
    records : sequence of dict
        Metric records (any experiments; those of ``experiment`` are used).
    experiment : int
    title : str, optional
    training : dict, optional
        ``{model: text}`` saying what each model was trained on (e.g.
        ``"GMS on A, SVR on B"``); by default the ``logs`` of its train record.
    notes : sequence of str, optional
        Further sentences for under the table.
    paper : dict, default :data:`PAPER_RE`
        Published test RE [%] by (experiment, axis, model).

    Returns
    -------
    Table
    """
    mine = [r for r in records if r["experiment"] == experiment]
    axes = _ordered(r["axis"] for r in mine)
    models = _ordered(r["model"] for r in mine if r["model"] != "noise_floor")
    if any(r["model"] == "noise_floor" for r in mine):
        models.append("noise_floor")
    index = _index(mine)
    header = ["model"]
    for axis in axes:
        header += [f"{axis} train RMSE [A]", f"{axis} train RE [%]", f"{axis} test RMSE [A]",
                   f"{axis} test RE [%]", f"{axis} paper test RE [%]"]
    rows = []
    for model in models:
        row = [_label(model)]
        for axis in axes:
            train = index.get((experiment, axis, model, "train"), {})
            test = index.get((experiment, axis, model, "test"), {})
            row += [_number(train.get("rmse"), 4), _number(train.get("re"), 2),
                    _number(test.get("rmse"), 4), _number(test.get("re"), 2),
                    _number(paper.get((experiment, axis, model)), 1)]
        rows.append(row)
    test_logs = _ordered(r.get("logs", "") for r in mine if r["dataset"] == "test")
    default_title = f"Experiment {experiment}" + (f": test on {test_logs[0]}" if len(test_logs) == 1 else "")
    trained = dict(training or {})
    for r in mine:
        if r["dataset"] == "train" and r["model"] != "noise_floor":
            trained.setdefault(r["model"], r.get("logs", ""))
    notes = [*notes, RE_NOTE, PAPER_SOURCE]
    if trained:
        notes.insert(0, "Trained on: " + "; ".join(f"{_label(m)} {trained[m]}" for m in models if m in trained)
                     + ".")
    return Table(title or default_title, header, rows, notes)


def hyperparameter_table(rows: Sequence[Mapping]) -> Table:
    """The SVR settings like the paper's Table 2: kernel, epsilon, C, gamma and the sole SVR's velocity weight.

    Parameters
    ----------
    rows : sequence of dict
        ``experiment``, ``axis``, ``model`` and the keys of a model's
        ``hyperparameters_table()`` (``kernel``, ``epsilon`` [A], ``C`` [A],
        ``gamma``, ``n_support``, ``n_train``, ``optimised``, ``cv_rmse`` [A],
        and for the sole SVR ``velocity_weight``).

    Returns
    -------
    Table
    """
    header = ["experiment", "axis", "model", "kernel", "epsilon [A]", "C [A]", "gamma", "velocity weight",
              "support vectors", "training samples", "CV RMSE [A]", "optimised"]
    body = []
    for row in rows:
        body.append([str(row.get("experiment", "")), str(row.get("axis", "")), _label(row.get("model", "")),
                     "Gaussian (RBF)" if row.get("kernel") == "rbf" else str(row.get("kernel", "")),
                     f"{row['epsilon']:.4g}", f"{row['C']:.4g}", f"{row['gamma']:.4g}",
                     f"{row['velocity_weight']:.4g}" if "velocity_weight" in row else "–",
                     str(row.get("n_support", "")), str(row.get("n_train", "")),
                     _number(row.get("cv_rmse"), 4), ", ".join(row.get("optimised", [])) or "none"])
    notes = ["gamma in 1/(standardised unit)^2: every SVR input is standardised (zero mean, unit variance) "
             "over the training data. The sole SVR's kernel weighs the squared velocity distance by its velocity "
             "weight (1: isotropic). Hyperparameters chosen by Bayesian optimisation (log-uniform priors) "
             "over a time-blocked cross-validation, as the paper's Table 2 reports them."]
    return Table("SVR hyperparameters (paper's Table 2)", header, body, notes)


def noise_floor_ratios(records: Sequence[Mapping], model: str = "gmssvr") -> list[dict]:
    """Test RE of ``model`` over the test RE of the noise-free current, per experiment and axis.

    Parameters
    ----------
    records : sequence of dict
        Metric records, including the ``noise_floor`` test records.
    model : str, default "gmssvr"
        Model kind compared with the noise floor.

    Returns
    -------
    list of dict
        ``experiment``, ``axis``, ``model``, ``re`` [%], ``noise_re`` [%] and
        ``ratio`` (1 is the best possible), for every experiment and axis
        having both records.
    """
    index = _index(records)
    result = []
    for (experiment, axis, name, dataset), record in index.items():
        if name != model or dataset != "test":
            continue
        floor = index.get((experiment, axis, "noise_floor", "test"))
        if floor is None or not floor.get("re"):
            continue
        result.append({"experiment": experiment, "axis": axis, "model": model, "re": record["re"],
                       "noise_re": floor["re"], "ratio": record["re"] / floor["re"]})
    return result


def noise_floor_table(records: Sequence[Mapping], model: str = "gmssvr", target: float = 1.5) -> Table:
    """:func:`noise_floor_ratios` as a table, with the target ratio.

    Parameters
    ----------
    records : sequence of dict
        Metric records, including the ``noise_floor`` test records.
    model : str, default "gmssvr"
        Model kind compared with the noise floor.
    target : float, default 1.5
        Ratio of test RE to noise-floor RE at or below which a row is marked as within target.
    """
    rows = [[str(r["experiment"]), r["axis"], _number(r["re"], 2), _number(r["noise_re"], 2),
             _number(r["ratio"], 2), "yes" if r["ratio"] <= target else "no"]
            for r in noise_floor_ratios(records, model)]
    header = ["experiment", "axis", f"{_label(model)} test RE [%]", "noise-floor test RE [%]", "ratio",
              f"within {target:g}x"]
    notes = ["The noise floor is the error of the noise-free current of the synthetic axis against the "
             "measured (noisy) current: no model can do better on average.", RE_NOTE]
    return Table(f"{_label(model)} against the noise floor", header, rows, notes)


def svr_generalisation(records: Sequence[Mapping], model: str = "svr") -> list[dict]:
    """How the sole SVR's error changes from its training data to each test log.

    The paper found the sole SVR to lose accuracy on dataset D (the full
    travel) although it fitted its training data well: overfitting. This
    compares, per experiment and axis, the training RE with the RE on every
    test log.

    Parameters
    ----------
    records : sequence of dict
        Metric records; a test record's ``per_log`` gives the RE of each test log.
    model : str, default "svr"
        Model kind to examine.

    Returns
    -------
    list of dict
        ``experiment``, ``axis``, ``model``, ``train_re`` [%], ``test_re``
        ({log: RE [%]}), ``change`` ({log: test RE / train RE}) and
        ``loses_accuracy_on`` (logs whose RE exceeds the training RE).
    """
    index = _index(records)
    result = []
    for (experiment, axis, name, dataset), train in index.items():
        if name != model or dataset != "train":
            continue
        test = index.get((experiment, axis, model, "test"))
        if test is None:
            continue
        parts = test.get("per_log") or {test.get("logs", "test"): {"re": test["re"]}}
        test_re = {log: part["re"] for log, part in parts.items()}
        change = {log: (re / train["re"] if train["re"] else math.nan) for log, re in test_re.items()}
        result.append({"experiment": experiment, "axis": axis, "model": model, "train_re": train["re"],
                       "test_re": test_re, "change": change,
                       "loses_accuracy_on": [log for log, re in test_re.items() if re > train["re"]]})
    return result


def svr_generalisation_table(records: Sequence[Mapping], model: str = "svr") -> Table:
    """:func:`svr_generalisation` as a table: one row per experiment, axis and test log.

    Parameters
    ----------
    records : sequence of dict
        Metric records.
    model : str, default "svr"
        Model kind to examine.
    """
    rows = []
    for entry in svr_generalisation(records, model):
        for log, re in entry["test_re"].items():
            rows.append([str(entry["experiment"]), entry["axis"], _number(entry["train_re"], 2), log,
                         _number(re, 2), _number(entry["change"][log], 2),
                         "yes" if log in entry["loses_accuracy_on"] else "no"])
    header = ["experiment", "axis", "train RE [%]", "test log", "test RE [%]", "test / train",
              "loses accuracy"]
    notes = ["The paper reports the sole SVR losing accuracy from its training data to dataset D "
             "(overfitting). This table states what the synthetic data show; nothing is forced.", RE_NOTE]
    return Table(f"Sole {_label(model)}: training against test accuracy", header, rows, notes)


def timing_table(timings: Sequence[Mapping]) -> Table:
    """The fits: rows of ``experiment``, ``axis``, ``model``, ``trained_on``, ``fit_seconds`` and ``notes``.

    ``notes`` are the warnings a fit issued (e.g. a hyperparameter that ended
    at the end of its search interval).

    Parameters
    ----------
    timings : sequence of dict
        One entry per fit with those keys; ``fit_seconds`` [s] of 0 marks a fit shared with an earlier one,
        ``trained_on`` and ``notes`` are optional.
    """
    rows = [[str(t["experiment"]), t["axis"], _label(t["model"]), t.get("trained_on", ""),
             "shared with an earlier fit" if t["fit_seconds"] == 0 else f"{t['fit_seconds']:.1f}",
             " ".join(t.get("notes") or ())]
            for t in timings]
    notes = ["Wall time of each fit on this machine; a GMS+SVR time leaves out its GMS stage when that stage "
             "was already identified for the GMS row (the same model on the same data)."]
    return Table("Fits", ["experiment", "axis", "model", "trained on", "fit [s]", "notes"], rows, notes)


def evaluation_table(records: Sequence[Mapping], title: str = "Test errors", *, unit: str = "A") -> Table:
    """Errors of each evaluated model: samples, RMSE, RE [%], NMSE [%], largest error.

    Parameters
    ----------
    records : sequence of dict
        Metric records.
    title : str, default "Test errors"
    unit : str, default "A"
        Unit of the logs' effort, of RMSE and of the largest error: "A" for current, "N" for force logs.

    Returns
    -------
    Table
    """
    header = ["model", "test logs", "samples", f"RMSE [{unit}]", "RE [%]", "NMSE [%]", f"max error [{unit}]"]
    rows = [[_label(r["model"]), r.get("logs", ""), str(r.get("n", "")), _number(r.get("rmse"), 4),
             _number(r.get("re"), 2), _number(r.get("nmse"), 2), _number(r.get("max_error"), 4)] for r in records]
    notes = [RE_NOTE, "NMSE = 100 mean((I_model - I)^2) / var(I) in % (Tjahjowidodo et al. 2005)."]
    return Table(title, header, rows, notes)


def per_log_table(records: Sequence[Mapping], title: str = "Test errors per log", *, unit: str = "A") -> Table:
    """Errors of each evaluated model on each test log (records carrying ``per_log``).

    Parameters
    ----------
    records : sequence of dict
        Metric records.
    title : str, default "Test errors per log"
    unit : str, default "A"
        Unit of the logs' effort and of RMSE: "A" for current, "N" for force logs.

    Returns
    -------
    Table
        One row per model and log: samples, RMSE, RE [%], NMSE [%].
    """
    header = ["model", "test log", "samples", f"RMSE [{unit}]", "RE [%]", "NMSE [%]"]
    rows = [[_label(r["model"]), log, str(m.get("n", "")), _number(m.get("rmse"), 4), _number(m.get("re"), 2),
             _number(m.get("nmse"), 2)]
            for r in records for log, m in (r.get("per_log") or {}).items()]
    return Table(title, header, rows, [RE_NOTE])


def regime_table(records: Sequence[Mapping], title: str = "RE per operating regime [%]") -> Table:
    """RE [%] of each model in each operating regime (records carrying ``regimes``).

    The regimes are those of :mod:`greybox.evaluate.regimes`; the header
    gives each regime's share of the samples.

    Parameters
    ----------
    records : sequence of dict
        Metric records; those without ``regimes`` are left out, and the first with them gives the shares.
    title : str, default "RE per operating regime [%]"
        Table title.
    """
    from .regimes import REGIME_NAMES

    with_regimes = [r for r in records if r.get("regimes")]
    header = ["model"]
    for name in REGIME_NAMES:
        share = ""
        if with_regimes and with_regimes[0]["regimes"]["all"]["n"]:
            share = f" ({100.0 * with_regimes[0]['regimes'][name]['n'] / with_regimes[0]['regimes']['all']['n']:.0f} %)"
        header.append(name.replace("_", " ") + share)
    rows = [[_label(r["model"])] + [_number(r["regimes"][name]["re"], 2) for name in REGIME_NAMES]
            for r in with_regimes]
    notes = ["Regimes (greybox.evaluate.regimes): low/high velocity split at 10 % of the robust top speed; "
             "reversal: a window around each change of direction; constant feed; acceleration phases. "
             "A sample may belong to several regimes; the header gives each regime's share of the samples.",
             RE_NOTE]
    return Table(title, header, rows, notes)


def training_region_table(records: Sequence[Mapping], unit: str = "A",
                          title: str = "Errors inside and outside each model's training region") -> Table:
    """Samples, RMSE and RE of each model inside and outside the region its training runs covered.

    The rows are the ``inside_training`` and ``outside_training`` regimes of the records
    (:data:`greybox.evaluate.regimes.TRAINING_REGION_NAMES`); a model whose file has no record of its
    training region gets a row of dashes.

    Parameters
    ----------
    records : sequence of dict
        Metric records of :func:`greybox.evaluate.records.evaluate_models`; those without
        ``training_region`` (the noise floor) are left out.
    unit : str, default "A"
        Unit of the RMSE (the logs' effort unit).
    title : str, default "Errors inside and outside each model's training region"
        Table title.
    """
    header = ["model", "samples outside [%]", "samples inside", f"RMSE inside [{unit}]", "RE inside [%]",
              "samples outside", f"RMSE outside [{unit}]", "RE outside [%]"]
    rows = []
    for record in records:
        if "training_region" not in record:
            continue
        regimes = record.get("regimes") or {}
        if "outside_training" not in regimes:
            rows.append([_label(record["model"])] + ["–"] * (len(header) - 1))
            continue
        inside, outside = regimes["inside_training"], regimes["outside_training"]
        share = 100.0 * outside["n"] / (inside["n"] + outside["n"]) if inside["n"] + outside["n"] else float("nan")
        rows.append([_label(record["model"]), _number(share, 1), str(inside["n"]), _number(inside["rmse"], 4),
                     _number(inside["re"], 2), str(outside["n"]), _number(outside["rmse"], 4),
                     _number(outside["re"], 2)])
    notes = ["Outside: samples whose position, speed or acceleration lies beyond what the training runs covered, "
             f"whose motion (speed against the span of the last {SPAN_WINDOW_S:g} s) they never showed, or whose "
             "predicted effort leaves the range of the trained efforts: the same region for every kind of model "
             "trained on the same runs (older files: the model's own ranges) (the column outside_training of "
             "greybox predict); inside: the others. A dash: the model file has no record of its training region.",
             RE_NOTE]
    return Table(title, header, rows, notes)


def report_tables(records: Sequence[Mapping], hyperparameters: Sequence[Mapping] = (),
                  timings: Sequence[Mapping] = (), *, titles: Mapping[int, str] | None = None,
                  training: Mapping[int, Mapping[str, str]] | None = None,
                  notes: Mapping[int, Sequence[str]] | None = None) -> list[Table]:
    """Every table of a reproduction report, in reading order.

    Parameters
    ----------
    records : sequence of dict
        Metric records.
    hyperparameters : sequence of dict, optional
        Rows for :func:`hyperparameter_table`.
    timings : sequence of dict, optional
        Rows for :func:`timing_table`.
    titles : dict, optional
        ``{experiment: title}``.
    training : dict, optional
        ``{experiment: {model: what it was trained on}}`` (see :func:`experiment_table`).
    notes : dict, optional
        ``{experiment: sentences}`` printed under the experiment's table.

    Returns
    -------
    list of Table
    """
    titles = titles or {}
    training = training or {}
    notes = notes or {}
    experiments = [e for e in _ordered(r["experiment"] for r in records) if e is not None]
    tables = [experiment_table(records, e, title=titles.get(e), training=training.get(e), notes=notes.get(e, ()))
              for e in experiments]
    if hyperparameters:
        tables.append(hyperparameter_table(hyperparameters))
    if paper_pattern(records):
        tables.append(paper_pattern_table(records))
    if sole_svr_beside_paper(records):
        tables.append(sole_svr_table(records))
    if noise_floor_ratios(records):
        tables.append(noise_floor_table(records))
    if svr_generalisation(records):
        tables.append(svr_generalisation_table(records))
    if timings:
        tables.append(timing_table(timings))
    return tables


def tables_markdown(tables: Sequence[Table], title: str = "greybox report", intro: str = "") -> str:
    """All tables as one Markdown document.

    Parameters
    ----------
    tables : sequence of Table
        Tables in the order they appear.
    title : str, default "greybox report"
        Top-level heading.
    intro : str, default ""
        Text between the heading and the tables (left out when empty).
    """
    parts = [f"# {title}\n"]
    if intro:
        parts.append(intro.rstrip() + "\n")
    parts += [table.to_markdown() for table in tables]
    return "\n".join(parts)


def write_report(out_dir: str | os.PathLike, records: Sequence[Mapping], tables: Sequence[Table],
                 figures: Sequence[tuple[str, str | os.PathLike]] = (), *, title: str = "greybox report",
                 intro: str = "") -> dict[str, Path]:
    """Write ``metrics.json``, ``metrics.csv``, ``tables.md``, ``index.html`` and ``provenance.json`` into ``out_dir``.

    ``tables.md`` and ``index.html`` end their introduction with the versions
    and the machine the figures were measured with (:mod:`greybox.provenance`),
    which ``provenance.json`` holds in full.

    Parameters
    ----------
    out_dir : path-like
        Existing directory.
    records : sequence of dict
        Metric records.
    tables : sequence of Table
    figures : sequence of (caption, path)
        PNG files already written (inside ``out_dir``), shown in the HTML page.
    title, intro : str
        Heading and first paragraph of ``tables.md`` and ``index.html``.

    Returns
    -------
    dict
        ``{"metrics_json", "metrics_csv", "tables", "html", "provenance"}`` -> written file.
    """
    out_dir = Path(out_dir)
    machine = provenance()
    intro = "\n\n".join(part for part in (intro.rstrip(), f"Measured with {provenance_line(machine)}.") if part)
    json_path, csv_path = write_metrics(records, out_dir)
    tables_path = write_text_atomic(out_dir / "tables.md", tables_markdown(tables, title, intro))
    html_path = write_html(out_dir / "index.html", title=title, intro=intro, tables=tables, figures=figures)
    provenance_path = write_text_atomic(out_dir / "provenance.json", json.dumps(machine, indent=1) + "\n")
    return {"metrics_json": json_path, "metrics_csv": csv_path, "tables": tables_path, "html": html_path,
            "provenance": provenance_path}
