"""The head-to-head protocol breaks the tool inside a cut, whatever the part's random wait."""

from __future__ import annotations

import numpy as np

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
