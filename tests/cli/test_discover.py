"""``greybox discover`` prints its wall time from the start of its process (issue 31, item 8)."""

from __future__ import annotations

import re
import time

import pytest

from greybox.cli import build_parser
from greybox.data.io import write_log
from greybox.studies.discovery import StudyCase, case_logs

#: A discovery run takes about half a minute: left out of the default run.
pytestmark = pytest.mark.slow


def test_the_printed_wall_time_counts_from_the_start_of_the_process(tmp_path, capsys):
    train, test, _ = case_logs(StudyCase("position_periodic_friction", 1.5, 3, "coulomb", 15.0))
    paths = []
    for name, log in (("train.csv", train), ("test.csv", test)):
        write_log(log.replace(acceleration=None, extras={}, attrs={}), tmp_path / name)
        paths.append(str(tmp_path / name))
    args = build_parser().parse_args(["discover", "--model", "coulomb", "--train", paths[0], "--test", paths[1],
                                      "--json", str(tmp_path / "found.json"), "--quiet", "--max-effects", "1"])
    args.started_s = time.perf_counter() - 100.0  # as main sets it: the process started 100 s ago
    args.startup_counted = True
    assert args.run(args) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    match = re.fullmatch(r"done in (\d+\.\d) s wall, start-up included", last)
    assert match and float(match.group(1)) >= 100.0
