"""The head-to-head protocol breaks the tool inside a cut, whatever the part's random wait."""

from __future__ import annotations

import numpy as np
import pytest

from greybox.twin.cutting import cut_segments
from greybox.twin.part_series import PartSeriesSpec, make_part_series
from studies.process_head_to_head import breakage_time


def test_the_breakage_falls_inside_the_fourth_cut_of_a_part_with_any_wait():
    at = breakage_time()
    for wait in (0.0, 0.2):
        logs, _ = make_part_series(PartSeriesSpec(parts=1, jitter_s=0.0, loading_s=5.0 + wait), 1)
        a, b = cut_segments(logs[0].extras["truth_process_A"])[3]
        assert logs[0].time[a] + 0.5 < at < logs[0].time[b - 1] - 0.5
        assert np.abs(logs[0].extras["truth_process_A"][np.searchsorted(logs[0].time, at)]) > 0.05


def test_the_false_alarm_summary_extrapolates_the_rate_of_part_maxima_drawn_from_the_model():
    import math

    from scipy.stats import t as student

    from studies.process_head_to_head import TEACH, false_alarm_summary

    rng = np.random.default_rng(0)
    scale, dof, count, factor = math.sqrt(1 + 1 / TEACH), 5 * (TEACH - 1), 300, 4.0
    maxima = scale * np.abs(rng.standard_t(dof, size=(2000, count))).max(axis=1)
    rows = [{"false_alarms": int(np.sum(half > factor)), "good_parts": half.size, "band_factor": factor,
             "maxima": half.tolist(), "mean_ratios": (0.25 * rng.standard_normal(half.size)).tolist()}
            for half in (maxima[:1000], maxima[1000:])]
    summary = false_alarm_summary(rows)
    truth = 1 - (1 - 2 * student.sf(factor / scale, dof)) ** count
    assert summary["good_parts"] == 2000 and summary["false_alarms"] == sum(r["false_alarms"] for r in rows)
    assert summary["band_count"] == pytest.approx(count, rel=0.1)
    assert summary["band_rate_ci"][0] < truth < summary["band_rate_ci"][1]
    assert summary["counted_ci"][0] < summary["false_alarms"] / 2000 < summary["counted_ci"][1]
    assert summary["mean_rate"] == pytest.approx(2 * student.sf(4.0, 1e9), rel=0.5)  # |D| / limit sd 0.25


def test_no_false_alarm_in_n_parts_bounds_the_rate_by_about_three_over_n():
    from studies.process_head_to_head import false_alarm_summary

    row = {"false_alarms": 0, "good_parts": 600, "band_factor": 6.0, "maxima": [4.0] * 600,
           "mean_ratios": [0.1] * 600}
    low, high = false_alarm_summary([row])["counted_ci"]
    assert low == 0.0 and high == pytest.approx(3.69 / 600, rel=0.05)


def test_targets_follow_the_issues_bounds():
    from studies.process_head_to_head import false_alarm_table, head_to_head_table, targets

    def row(wear, located, force=None):
        out = {"false_alarms": 0, "good_parts": 38, "missing_blank": True, "oversized_blank": True,
               "wear_flagged_part": wear, "wear_crossing_part": 65, "breakage_flagged": located is not None,
               "breakage_location_error_s": located}
        if force is not None:
            out["cut_force_error_pct"] = {"mean_abs": 1.0, "max_abs": force, "mean": 0.5}
        return out

    summary = {"false_alarms": 0, "good_parts": 38, "counted_ci": [0.0, 0.09], "band_count": 100.0,
               "band_count_ci": [80.0, 120.0], "rate": 5e-4, "rate_ci": [2e-4, 9e-4]}
    names = ("raw", "raw, re-levelled", "force", "force, re-levelled")
    good = {"series": {"1": {name: row(70, 0.2, 1.9 if "force" in name else None) for name in names}},
            "false_alarms": {name: summary for name in names}}
    assert targets(good, "force, re-levelled") == {"wear": True, "breakage": True, "rate": True, "cut_force": True}
    assert targets(good, "raw")["cut_force"] is None
    bad = {"series": {"1": {name: row(71, 0.21, 2.1) for name in names}},
           "false_alarms": {name: {**summary, "rate_ci": [2e-3, 5e-3]} for name in names}}
    assert targets(bad, "force") == {"wear": False, "breakage": False, "rate": False, "cut_force": False}
    assert "| force, re-levelled | 0 / 38 | 1 / 1 | 1 / 1 | 70 (65) | 0.20 s | 1.00 / 1.90 % |" in \
        head_to_head_table(good["series"])
    assert "| raw | 0 / 38 | 0.0000-0.0900 | 100 (80-120) | 5.0e-04 (2.0e-04-9.0e-04) |" in \
        false_alarm_table(good["false_alarms"])
