"""The check's HTML page: the tables of the parts and stretches, one interactive chart per figured part."""

from __future__ import annotations

import json
import re

import numpy as np
from process_parts import good_parts, make_part

from greybox.process.check import check_part
from greybox.process.envelope import Envelope
from greybox.process.html import part_chart_html, write_html_report


def test_the_page_lists_the_parts_flagged_first_and_charts_the_broken_part(tmp_path):
    envelope = Envelope().fit(good_parts(8, seed=9), unit="A", signal={"kind": "raw"})
    checks = [check_part(envelope, part) for part in good_parts(2, seed=10)]
    broken = check_part(envelope, make_part(3, np.random.default_rng(0), break_at_s=4.0))
    checks.append(broken)
    page = write_html_report(envelope, checks, [broken], tmp_path / "report.html").read_text()
    rows = re.findall(r"<tr><td>series\.csv</td><td>(\d+)</td><td>(yes|no)</td>", page)
    assert rows[0] == ("3", "yes") and {row[0] for row in rows} == {"1", "2", "3"}
    assert page.count('id="part-0"') == 1 and 'id="part-1"' not in page
    assert page.count("Plotly.newPlot") == 1 and "missing cut" in page


def test_a_chart_draws_the_band_the_centre_the_part_and_each_stretch():
    envelope = Envelope().fit(good_parts(8, seed=9), unit="A", signal={"kind": "raw"})
    broken = check_part(envelope, make_part(3, np.random.default_rng(0), break_at_s=4.0))
    chart = part_chart_html(envelope, broken, "chart")
    spec = json.loads(re.search(r"Plotly\.newPlot\(\s*\"chart\",\s*(\[.*?\]),\s*\{", chart, re.S).group(1))
    assert [trace["name"] for trace in spec] == ["envelope", "taught centre", "part 3"]
    step = max(1, envelope.width_ // 10)
    assert len(spec[1]["y"]) == len(range(0, envelope.centre_.size, step))
    shapes = re.findall(r'"type":"rect"', chart)
    assert len(shapes) == len(broken.stretches) > 0
