"""The check's report: its tables match the checks, a figure of a part over its envelope."""

from __future__ import annotations

import csv
import json

import numpy as np
from process_parts import good_parts, make_part

from greybox.process.check import check_part
from greybox.process.envelope import Envelope
from greybox.process.report import PART_FIELDS, write_report


def test_report_tables_and_figure(tmp_path):
    envelope = Envelope().fit(good_parts(8, seed=9), unit="A", signal={"kind": "raw"})
    checks = [check_part(envelope, part) for part in good_parts(3, seed=10)]
    checks.append(check_part(envelope, make_part(4, np.random.default_rng(0), break_at_s=4.0)))
    written = write_report(envelope, checks, tmp_path / "report", figures=2)
    names = sorted(path.name for path in written)
    assert names == ["part_series_004.png", "parts.csv", "report.html", "report.json", "stretches.csv"]
    rows = list(csv.DictReader((tmp_path / "report" / "parts.csv").open()))
    assert tuple(rows[0]) == PART_FIELDS and len(rows) == 4
    assert [row["flagged"] for row in rows] == [str(c.flagged) for c in checks]
    assert "missing cut" in rows[3]["kinds"]
    stretches = list(csv.DictReader((tmp_path / "report" / "stretches.csv").open()))
    assert len(stretches) == sum(len(c.stretches) for c in checks)
    summary = json.loads((tmp_path / "report" / "report.json").read_text())
    assert summary["parts_checked"] == 4 and summary["parts_flagged"] == sum(c.flagged for c in checks)
    assert (tmp_path / "report" / "part_series_004.png").read_bytes()[:4] == b"\x89PNG"
