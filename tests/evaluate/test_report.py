"""Tests of the report files: metric records, tables, HTML page, figures."""

from __future__ import annotations

import base64
import csv
import json
import math

import numpy as np
import pytest

from greybox.data.log import AxisLog
from greybox.errors import GreyboxError
from greybox.evaluate.figures import error_boxplot, residual_vs_position, time_comparison
from greybox.evaluate.html import render_html, write_html
from greybox.evaluate.records import metric_record
from greybox.evaluate.report import (
    CSV_COLUMNS,
    PAPER_RE,
    RE_NOTE,
    check_output_dir,
    experiment_table,
    hyperparameter_table,
    noise_floor_ratios,
    records_json,
    report_tables,
    svr_generalisation,
    svr_generalisation_table,
    write_metrics,
    write_report,
)
from greybox.evaluate.table import Table

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def record(experiment, axis, model, dataset, rmse, re, logs="C", per_log=None):
    entry = {"experiment": experiment, "axis": axis, "model": model, "dataset": dataset, "rmse": rmse, "re": re,
             "logs": logs, "n": 100, "nmse": 1.0, "max_error": 0.5}
    if per_log is not None:
        entry["per_log"] = per_log
    return entry


def reversing_log(n=2000, seed=0, name="C"):
    """A prepared log moving back and forth (sine position) with a noisy current."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.002
    omega = 2 * np.pi * 0.5
    position = -250 + 10 * np.sin(omega * t)
    velocity = 10 * omega * np.cos(omega * t)
    acceleration = -10 * omega**2 * np.sin(omega * t)
    effort = np.sign(velocity) + 0.01 * velocity + rng.normal(0, 0.05, n)
    return AxisLog(time=t, position=position, effort=effort, velocity=velocity, acceleration=acceleration,
                   axis="X", dataset=name)


# ---------------------------------------------------------------- records
def test_metric_record_matches_the_definitions():
    rng = np.random.default_rng(1)
    y = rng.normal(0, 1, 500)
    y_hat = y + rng.normal(0, 0.1, 500)
    r = metric_record(2, "Y", "gms", "test", y, y_hat, ["C", "D"],
                      {"C": (y[:200], y_hat[:200]), "D": (y[200:], y_hat[200:])})
    rmse = math.sqrt(np.mean((y_hat - y) ** 2))
    assert r["rmse"] == pytest.approx(rmse)
    assert r["re"] == pytest.approx(100 * rmse / np.mean(np.abs(y)))
    assert r["logs"] == "C+D" and r["n"] == 500
    assert {k: r[k] for k in ("experiment", "axis", "model", "dataset")} == {
        "experiment": 2, "axis": "Y", "model": "gms", "dataset": "test"}
    assert r["per_log"]["C"]["n"] == 200
    assert r["per_log"]["D"]["rmse"] == pytest.approx(math.sqrt(np.mean((y_hat[200:] - y[200:]) ** 2)))
    # The pooled mean square is the sample-weighted mean of the per-log mean squares.
    pooled = (200 * r["per_log"]["C"]["rmse"] ** 2 + 300 * r["per_log"]["D"]["rmse"] ** 2) / 500
    assert r["rmse"] == pytest.approx(math.sqrt(pooled))


def test_metrics_json_and_csv(tmp_path):
    records = [record(1, "X", "gms", "train", 0.07, 7.0, per_log={"A": {"n": 100, "rmse": 0.07, "re": 7.0}}),
               record(1, "X", "gms", "test", float("nan"), 8.0)]
    json_path, csv_path = write_metrics(records, tmp_path)
    loaded = json.loads(json_path.read_text())
    assert loaded[0]["per_log"]["A"]["re"] == 7.0
    assert loaded[1]["rmse"] is None  # strict JSON: NaN becomes null
    with open(csv_path, newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert tuple(rows[0]) == CSV_COLUMNS
    assert [row["dataset"] for row in rows] == ["train", "test"]
    assert float(rows[0]["re"]) == 7.0 and rows[1]["rmse"] == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["metrics.csv", "metrics.json"]  # no temporary files


def test_records_json_is_strict():
    text = records_json([{"re": float("inf"), "x": np.float64(2.5), "n": np.int64(3)}])
    assert json.loads(text) == [{"re": None, "x": 2.5, "n": 3}]


# ---------------------------------------------------------------- tables
def test_experiment_table_layout_and_paper_column():
    records = []
    for axis in ("X", "Y"):
        for model, re in (("stribeck", 30.0), ("gmssvr", 8.0), ("noise_floor", 6.0)):
            records.append(record(2, axis, model, "train", re / 100, re, logs="A+B"))
            records.append(record(2, axis, model, "test", re / 50, 2 * re, logs="C+D"))
    table = experiment_table(records, 2, training={"gmssvr": "GMS on A, SVR on B"})
    assert table.header[0] == "model"
    assert len(table.header) == 1 + 2 * 5
    assert [row[0] for row in table.rows] == ["Stribeck", "GMS+SVR", "noise floor (noise-free current)"]
    gmssvr = table.rows[1]
    assert gmssvr[1:5] == ["0.0800", "8.00", "0.1600", "16.00"]
    assert gmssvr[5] == f"{PAPER_RE[(2, 'X', 'gmssvr')]:.1f}" and gmssvr[10] == f"{PAPER_RE[(2, 'Y', 'gmssvr')]:.1f}"
    assert table.rows[0][5] == "10.1" and table.rows[0][10] == "25.3"  # the paper's Table 4, Stribeck
    assert table.rows[2][5] == "–"  # a row the paper does not have: blank, not invented
    assert RE_NOTE in table.notes
    assert any("GMS on A, SVR on B" in note for note in table.notes)
    assert "C+D" in table.title


def test_table_markdown_is_a_pipe_table():
    text = Table("T", ["a", "b"], [["1", "2"], ["3", "4"]], ["note"]).to_markdown()
    lines = text.splitlines()
    assert lines[0] == "### T"
    assert lines[2:6] == ["| a | b |", "|---|---|", "| 1 | 2 |", "| 3 | 4 |"]
    assert lines[-1] == "note"


def test_svr_generalisation_flags_only_logs_worse_than_training():
    per_log = {"C": {"n": 10, "rmse": 0.1, "re": 8.0}, "D": {"n": 10, "rmse": 0.3, "re": 25.0}}
    records = [record(2, "X", "svr", "train", 0.1, 10.0, logs="A+B"),
               record(2, "X", "svr", "test", 0.2, 18.0, logs="C+D", per_log=per_log),
               record(1, "X", "svr", "train", 0.1, 10.0, logs="A"),
               record(1, "X", "svr", "test", 0.09, 9.0, logs="C")]
    result = {entry["experiment"]: entry for entry in svr_generalisation(records)}
    assert result[2]["loses_accuracy_on"] == ["D"]
    assert result[2]["change"] == {"C": pytest.approx(0.8), "D": pytest.approx(2.5)}
    assert result[1]["loses_accuracy_on"] == []  # no per_log: the pooled test record counts
    table = svr_generalisation_table(records)
    assert [row[3] for row in table.rows] == ["C", "D", "C"]
    assert [row[-1] for row in table.rows] == ["no", "yes", "no"]


def test_noise_floor_ratio():
    records = [record(1, "X", "gmssvr", "test", 0.1, 9.0), record(1, "X", "noise_floor", "test", 0.06, 6.0),
               record(1, "Y", "gmssvr", "test", 0.1, 9.0)]  # no floor on Y: no ratio
    (entry,) = noise_floor_ratios(records)
    assert entry["ratio"] == pytest.approx(1.5) and entry["axis"] == "X"


def test_hyperparameter_table_like_table_2():
    row = {"experiment": 1, "axis": "X", "model": "gmssvr", "kernel": "rbf", "epsilon": 0.01234, "C": 5.0,
           "gamma": 0.5, "n_support": 321, "n_train": 1000, "optimised": ["epsilon", "C", "gamma"], "cv_rmse": 0.08}
    sole = {**row, "model": "svr", "velocity_weight": 312.5}
    table = hyperparameter_table([row, sole])
    assert table.header[3:8] == ["kernel", "epsilon [A]", "C [A]", "gamma", "velocity weight"]
    assert table.rows[0][3:8] == ["Gaussian (RBF)", "0.01234", "5", "0.5", "–"]
    assert table.rows[1][7] == "312.5"


def test_report_tables_and_files(tmp_path):
    records = [record(1, "X", "svr", "train", 0.1, 10.0, logs="A"), record(1, "X", "svr", "test", 0.2, 20.0),
               record(1, "X", "gmssvr", "test", 0.07, 7.0), record(1, "X", "noise_floor", "test", 0.06, 6.0)]
    tables = report_tables(records, timings=[{"experiment": 1, "axis": "X", "model": "svr", "trained_on": "A",
                                              "fit_seconds": 1.5}])
    titles = [t.title for t in tables]
    assert titles[0].startswith("Experiment 1")
    assert any("noise floor" in t for t in titles) and any("Sole SVR" in t for t in titles)
    png = tmp_path / "f.png"
    png.write_bytes(PNG_MAGIC + b"payload")
    files = write_report(tmp_path, records, tables, [("a figure", png)], title="T")
    assert "### Experiment 1" in files["tables"].read_text()
    assert files["html"].read_text().count("<table>") == len(tables)


def test_check_output_dir(tmp_path):
    assert check_output_dir(tmp_path / "new") == tmp_path / "new"
    check_output_dir(tmp_path)  # empty
    (tmp_path / "x").write_text("x")
    with pytest.raises(GreyboxError, match="not empty"):
        check_output_dir(tmp_path)
    check_output_dir(tmp_path, force=True)
    with pytest.raises(GreyboxError, match="is a file"):
        check_output_dir(tmp_path / "x", force=True)
    with pytest.raises(GreyboxError, match="does not exist"):
        check_output_dir(tmp_path / "no" / "deeper")


# ---------------------------------------------------------------- HTML
def test_html_embeds_images_and_escapes_text(tmp_path):
    png = tmp_path / "fig.png"
    png.write_bytes(PNG_MAGIC + b"\x00\x01")
    page = render_html(title="a < b", tables=[Table("t&t", ["x"], [["<1>"]])], figures=[("cap", png)])
    assert "<title>a &lt; b</title>" in page and "<td>&lt;1&gt;</td>" in page and "t&amp;t" in page
    encoded = page.split('src="data:image/png;base64,')[1].split('"')[0]
    assert base64.b64decode(encoded) == png.read_bytes()


def test_html_can_link_images_relative_to_the_page(tmp_path):
    (tmp_path / "figs").mkdir()
    png = tmp_path / "figs" / "fig.png"
    png.write_bytes(PNG_MAGIC)
    path = write_html(tmp_path / "page.html", title="t", figures=[("cap", png)], embed=False)
    assert 'src="figs/fig.png"' in path.read_text()


# ---------------------------------------------------------------- figures
def test_figures_are_written(tmp_path):
    runs = [reversing_log(1500, 0, "C"), reversing_log(1000, 1, "D")]
    measured = np.concatenate([r.effort for r in runs])
    predictions = {"gms": measured + 0.05, "stribeck": [r.effort - 0.1 for r in runs]}
    paths = [
        error_boxplot([("X", runs, predictions), ("Y", runs, predictions)], tmp_path / "box.png"),
        time_comparison(runs, predictions, tmp_path / "time.png"),
        residual_vs_position(runs, predictions, tmp_path / "res.png"),
    ]
    for path in paths:
        assert path.read_bytes()[:8] == PNG_MAGIC


