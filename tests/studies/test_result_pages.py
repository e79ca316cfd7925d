"""Every figure a page renders from a record equals its record, and every record it renders is current.

A figure typed or changed by hand inside a marked stretch makes the page differ from its rendering; a
commit to what a record measures, after the record was made, makes it stale. Either fails here, naming
the page or the record and what to run.
"""

from __future__ import annotations

import os
import shutil

import pytest

from greybox.errors import GreyboxError
from studies.records import MEASURING, RESULTS, SPECS, read_record, stale_commits
from studies.result_pages import BLOCK, PAGES, VIEWS, cited_records, render_text

TEXTS = {page: page.read_text(encoding="utf-8") for page in PAGES}
CITED = sorted(set().union(*(cited_records(text) for text in TEXTS.values())))
#: The record this run re-makes, if any (the default test run is itself a record): its old figures, or its
#: absence the first time, are what is being replaced, so they are not held against it.
REMADE = tuple(filter(None, [os.environ.get(MEASURING)]))


def _first_difference(text: str, rendered: str) -> str:
    for line, (mine, theirs) in enumerate(zip(text.splitlines(), rendered.splitlines()), start=1):
        if mine != theirs:
            return f"line {line}: {mine!r}, its record gives {theirs!r}"
    return "the pages differ in length"


@pytest.mark.parametrize("page", PAGES, ids=[page.name for page in PAGES])
def test_every_page_equals_its_rendering_from_the_records(page):
    text = TEXTS[page]
    rendered = render_text(text, where=page.name, keep=REMADE)
    assert rendered == text, (f"{page.name} differs from its records at {_first_difference(text, rendered)}; "
                              "run python scripts/render_results.py (figures are never typed)")


@pytest.mark.skipif(shutil.which("git") is None, reason="a record's age is read from the git history")
@pytest.mark.parametrize("name", CITED)
def test_every_record_a_page_renders_is_current_and_made_by_its_command(name):
    assert name in SPECS, f"record {name} has no command to re-make it in studies.records.SPECS"
    if name in REMADE:
        return
    record = read_record(name)
    assert record["depends_on"] == list(SPECS[name].depends_on), f"record {name} was made for other paths"
    assert not record["uncommitted"], f"record {name} was measured on uncommitted code: {record['uncommitted']}"
    stale = stale_commits(record)
    assert not stale, (f"record {name} (commit {record['commit'][:9]}) is older than changes to what it measures: "
                       f"{'; '.join(stale[:5])}; re-make it: python scripts/record.py {name}")


def test_every_record_file_is_cited_and_has_a_command():
    files = {path.stem for path in RESULTS.glob("*.json")}
    assert files <= set(SPECS), f"records without a command: {files - set(SPECS)}"
    assert files - set(REMADE) == set(CITED) - set(REMADE), (
        f"records no page renders: {files - set(CITED)}; records not made: {set(CITED) - files - set(REMADE)}")


def test_every_view_is_rendered_on_some_page():
    used = {match["view"] for text in TEXTS.values() for match in BLOCK.finditer(text)}
    assert set(VIEWS) == used, f"views no page renders: {sorted(set(VIEWS) - used)}"


def test_a_stretch_of_a_record_being_re_made_is_left_as_it_stands():
    text = "<!-- record reproduce-run -->\nthe figures of the run before\n<!-- end record -->\n"
    assert render_text(text, read=lambda name: {}, keep=("reproduce",)) == text


def test_a_figure_changed_by_hand_inside_a_stretch_is_put_back_and_one_outside_is_left():
    page = next(page for page in PAGES if cited_records(TEXTS[page]) and not cited_records(TEXTS[page]) & set(REMADE))
    text = TEXTS[page]
    match = next(BLOCK.finditer(text))
    body = match["body"]
    digit = next(i for i, char in enumerate(body) if char.isdigit())
    forged = body[:digit] + str((int(body[digit]) + 1) % 10) + body[digit + 1:]
    changed = text[:match.start("body")] + forged + text[match.end("body"):]
    assert changed != text and render_text(changed) == text
    outside = "A typed figure: 1.234 %\n"
    assert render_text(outside + text) == outside + text


def test_an_unknown_view_names_the_page_and_the_views():
    text = "<!-- record nothing -->\n| x |\n<!-- end record -->\n"
    with pytest.raises(GreyboxError, match="page.md: no view 'nothing'; views: reproduce-run, "):
        render_text(text, where="page.md", read=lambda name: {})


def test_features_named_equally_often_are_listed_by_name_whatever_the_hash_seed():
    record = read_record("monitor-detection")
    names = [f"feature_{letter} falls" for letter in "hgfedcba"]  # 8 ties: a hash order is alphabetical 1 in 40320
    figures = {kind: dict(results) for kind, results in record["figures"].items()}
    figures["preload"]["first_named"] = ["breakaway_pos falls"] * 9 + names
    text = VIEWS["monitor-detection"].render({**record, "figures": figures})
    row = next(line for line in text.splitlines() if line.startswith("| preload"))
    assert "breakaway_pos falls (9), " + ", ".join(f"{name} (1)" for name in sorted(names)) in row


def _example_record(stretch_start_s: float, deviations: list) -> dict:
    parts = [{"part": n, "flagged": False, "deviation": d, "deviation_limit": 9.0} for n, d in enumerate(deviations, 1)]
    parts.append({"part": len(parts) + 1, "flagged": True, "deviation": -30.0, "deviation_limit": 9.0})
    return {"command": "python scripts/process_example.py", "cores": 2, "load_before": [1.0], "load_after": [1.0],
            "commit": "0" * 40, "date": "2026-11-29T00:00:00+00:00",
            "figures": {"teach_lines": ["taught"], "check_lines": ["checked"], "parts": parts,
                        "stretches": [{"part": len(parts), "start_s": stretch_start_s + 1.0},
                                      {"part": len(parts), "start_s": stretch_start_s}],
                        "truth_parts": [{"part": len(parts), "friction_factor_end": 0.9}],
                        "truth_events": [{"part": len(parts), "time_s": 33.4}],
                        "warm_up": {"drop": 0.25, "time_constant_s": 2400.0}}}


def test_the_process_example_reads_the_breakage_delay_and_the_passed_parts_from_the_record():
    text = VIEWS["process-example"].render(_example_record(33.45, [-2.0, 1.5, 3.25]))
    assert "starts +0.05 s from the breakage" in text  # the first stretch of the broken part, not the later one
    assert "3 parts passed with `D` between -2.0 and 3.2 N (limit 9.0 N)" in text  # the flagged part left out
    assert "fallen by 10.0 %" in text and "25 % drop, 40 min time constant" in text
    later = VIEWS["process-example"].render(_example_record(34.0, [-2.0, 1.5, 3.25]))
    assert "starts +0.60 s from the breakage" in later



def test_every_picture_drawn_from_a_record_names_a_record():
    # scripts/record.py redraws these after measuring the record; a renamed record would leave the picture stale
    import sys
    from pathlib import Path

    scripts = str(Path(__file__).resolve().parents[2] / "scripts")
    sys.path.insert(0, scripts)
    try:
        from record_figures import DRAWN_FROM
    finally:
        sys.path.remove(scripts)
    assert DRAWN_FROM and set(DRAWN_FROM) <= set(SPECS)
