"""The checks of the paper's pattern (greybox.evaluate.pattern) on the paper's figures and on mutated records."""

from __future__ import annotations

import pytest

from greybox.evaluate.paper import PAPER_RE, PAPER_TEST_RMSE, PAPER_TRAIN_RE
from greybox.evaluate.pattern import (
    PATTERN_LIMITS,
    paper_pattern,
    paper_pattern_table,
    sole_svr_beside_paper,
    sole_svr_table,
)
from greybox.evaluate.report import report_tables


def paper_records(changes=None):
    """Metric records holding the paper's Tables 3 and 4; ``changes`` maps (experiment, axis, model, side) to RE."""
    changes = changes or {}
    records = []
    for key, re in PAPER_RE.items():
        experiment, axis, model = key
        test = changes.get((*key, "test"), re)
        train = changes.get((*key, "train"), PAPER_TRAIN_RE[key])
        rmse = PAPER_TEST_RMSE[key] * test / re
        records.append({"experiment": experiment, "axis": axis, "model": model, "dataset": "test", "re": test,
                        "rmse": rmse})
        records.append({"experiment": experiment, "axis": axis, "model": model, "dataset": "train", "re": train,
                        "rmse": rmse})
    return records


def by_check(results):
    return {(r["check"], r["axis"]): r for r in results}


def test_the_papers_own_figures_meet_every_check_and_fill_the_paper_column():
    results = paper_pattern(paper_records())
    assert len(results) == 4  # lowest test RE on X and on Y, the position effect of Stribeck and of GMS
    assert all(r["met"] for r in results)
    assert all(r["paper"] == r["ours"] for r in results)


def test_no_check_is_about_the_sole_svr():
    """The sole SVR's figures depend on the paper's undisclosed SVR training: shown, never checked."""
    worse = {(e, axis, "svr", side): 500.0 for e in (1, 2) for axis in "XY" for side in ("test", "train")}
    assert all(r["met"] for r in paper_pattern(paper_records(worse)))  # the lowest is still gmssvr
    assert all("SVR," not in r["check"] and "SVR test" not in r["check"] for r in paper_pattern(paper_records()))


def test_the_sole_svr_is_shown_beside_the_paper_without_a_target():
    records = paper_records({(1, "X", "svr", "test"): 19.0, (2, "Y", "svr", "train"): PAPER_RE[(2, "Y", "svr")] / 1.5})
    figures = {(f["figure"], f["axis"]): f for f in sole_svr_beside_paper(records)}
    assert len(figures) == 6 and all(set(f) == {"figure", "axis", "paper", "ours"} for f in figures.values())
    re = figures[("Table 3: sole SVR test RE [%]", "X")]
    assert float(re["ours"]) == pytest.approx(19.0) and float(re["paper"]) == pytest.approx(PAPER_RE[(1, "X", "svr")])
    rmse = figures[("Table 3: sole SVR test RMSE [A]", "X")]
    assert float(rmse["ours"]) == pytest.approx(PAPER_TEST_RMSE[(1, "X", "svr")] * 19.0 / PAPER_RE[(1, "X", "svr")],
                                                abs=5e-4)
    overfit = figures[("Table 4: sole SVR test RE / training RE", "Y")]
    assert float(overfit["ours"]) == pytest.approx(1.5)
    assert float(overfit["paper"]) == pytest.approx(PAPER_RE[(2, "Y", "svr")] / PAPER_TRAIN_RE[(2, "Y", "svr")],
                                                    abs=0.005)
    unchanged = figures[("Table 4: sole SVR test RE / training RE", "X")]
    assert unchanged["ours"] == unchanged["paper"]


def test_the_lowest_model_and_the_position_effect_are_read_from_the_records():
    records = paper_records({(2, "X", "gmssvr", "test"): 20.0, (2, "Y", "stribeck", "test"): 12.0})
    results = by_check(paper_pattern(records))
    lowest = results[("Table 4: lowest test RE", "X")]
    assert lowest["ours"] == "stribeck" and not lowest["met"]
    ratio = results[("Table 4: stribeck test RE, Y / X (position effect)", "X, Y")]
    assert float(ratio["ours"]) == pytest.approx(12.0 / PAPER_RE[(2, "X", "stribeck")], abs=0.005)
    assert not ratio["met"] and float(ratio["paper"]) >= PATTERN_LIMITS["position_y_over_x"]
    assert results[("Table 4: gms test RE, Y / X (position effect)", "X, Y")]["met"]


def test_checks_and_figures_without_their_figures_are_left_out():
    records = [r for r in paper_records() if r["axis"] == "X" and r["experiment"] == 1]
    assert paper_pattern(records) == []
    assert {f["figure"] for f in sole_svr_beside_paper(records)} == {"Table 3: sole SVR test RE [%]",
                                                                     "Table 3: sole SVR test RMSE [A]"}
    records = [r for r in paper_records() if r["axis"] == "X"]
    assert {r["check"] for r in paper_pattern(records)} == {"Table 4: lowest test RE"}  # Y / X needs both axes


def test_the_report_carries_the_pattern_and_the_sole_svr_tables():
    tables = report_tables(paper_records())
    table = next(t for t in tables if t.title == paper_pattern_table(paper_records()).title)
    assert len(table.rows) == 4 and {row[-1] for row in table.rows} == {"yes"}
    svr = next(t for t in tables if t.title == sole_svr_table(paper_records()).title)
    assert len(svr.rows) == 6 and svr.header == ["figure", "axis", "paper", "greybox"]  # no pass/fail column
