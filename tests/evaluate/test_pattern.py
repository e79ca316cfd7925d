"""The checks of the paper's pattern (greybox.evaluate.pattern) on the paper's figures and on mutated records."""

from __future__ import annotations

import pytest

from greybox.evaluate.paper import PAPER_RE, PAPER_TEST_RMSE, PAPER_TRAIN_RE
from greybox.evaluate.pattern import PATTERN_LIMITS, paper_pattern, paper_pattern_table
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
    assert len(results) == 10
    assert all(r["met"] for r in results)
    assert all(r["paper"] == r["ours"] for r in results)


def test_static_models_five_times_worse_than_gms_break_the_table3_spread():
    records = paper_records({(1, "X", "stribeck", "test"): 5.0 * PAPER_RE[(1, "X", "gms")]})
    results = by_check(paper_pattern(records))
    spread = results[("Table 3: test RE of Stribeck, SVR, GMS, largest / smallest", "X")]
    assert not spread["met"] and float(spread["ours"]) == pytest.approx(5.0)
    assert spread["paper"] == "1.11"
    assert results[("Table 3: test RE of Stribeck, SVR, GMS, largest / smallest", "Y")]["met"]
    assert not results[("Table 3: test RMSE of Stribeck, SVR, GMS [A]", "X")]["met"]


def test_an_svr_that_generalises_is_not_the_papers_overfitting():
    records = paper_records({(2, "Y", "svr", "train"): PAPER_RE[(2, "Y", "svr")] / 1.5})
    result = by_check(paper_pattern(records))[("Table 4: SVR test RE / training RE", "Y")]
    assert not result["met"] and float(result["ours"]) == pytest.approx(1.5)
    assert float(result["paper"]) >= PATTERN_LIMITS["svr_overfit"]


def test_the_lowest_model_and_the_position_effect_are_read_from_the_records():
    records = paper_records({(2, "X", "gmssvr", "test"): 20.0, (2, "Y", "stribeck", "test"): 12.0})
    results = by_check(paper_pattern(records))
    lowest = results[("Table 4: lowest test RE", "X")]
    assert lowest["ours"] == "stribeck" and not lowest["met"]
    ratio = results[("Table 4: stribeck test RE, Y / X (position effect)", "X, Y")]
    assert float(ratio["ours"]) == pytest.approx(12.0 / PAPER_RE[(2, "X", "stribeck")], abs=0.005)
    assert not ratio["met"]
    assert results[("Table 4: gms test RE, Y / X (position effect)", "X, Y")]["met"]


def test_checks_without_their_figures_are_left_out():
    records = [r for r in paper_records() if r["axis"] == "X" and r["experiment"] == 1]
    checks = {r["check"] for r in paper_pattern(records)}
    assert checks == {"Table 3: test RE of Stribeck, SVR, GMS, largest / smallest",
                      "Table 3: test RMSE of Stribeck, SVR, GMS [A]"}


def test_the_report_carries_the_pattern_table():
    tables = report_tables(paper_records())
    table = next(t for t in tables if t.title == paper_pattern_table(paper_records()).title)
    assert len(table.rows) == 10 and {row[-1] for row in table.rows} == {"yes"}
