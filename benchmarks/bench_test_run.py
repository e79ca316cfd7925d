"""Time the default test run (the README's ``pytest -q -n 2``) and count its tests.

Runs ``python -m pytest -q -n 2`` (the fast tests on two pytest-xdist processes) from the repository's root
in a subprocess (the test session the README's command runs), then prints one JSON object:

- ``passed``, ``skipped``, ``failed``, ``errors``: the counts of pytest's summary line;
- ``seconds``: wall time of the whole session, as pytest reports it;
- ``cores``: CPUs this process may use.

A run with a failed test exits with status 1 after printing, so that no record is made of it.

    python benchmarks/bench_test_run.py
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: The README's test command after ``pytest`` (the fast tests on two processes).
TEST_COMMAND = ("-q", "-n", "2")

#: One count of pytest's summary line, e.g. ``2141 passed``.
COUNT = re.compile(r"(\d+) (passed|skipped|failed|errors?|xfailed|xpassed|deselected)")
#: The duration at the end of that line, e.g. ``in 137.21s (0:02:17)``.
DURATION = re.compile(r" in (\d+(?:\.\d+)?)s")


def summary(text: str) -> dict:
    """The counts and the duration of pytest's last summary line.

    Parameters
    ----------
    text : str
        pytest's standard output.

    Returns
    -------
    dict
        ``passed``, ``skipped``, ``failed``, ``errors`` (0 when absent) and ``seconds`` [s].

    Raises
    ------
    ValueError
        When the output holds no summary line.
    """
    lines = [line for line in text.splitlines() if DURATION.search(line) and COUNT.search(line)]
    if not lines:
        raise ValueError("pytest printed no summary line")
    counts = {kind.rstrip("s") if kind.startswith("error") else kind: int(n) for n, kind in COUNT.findall(lines[-1])}
    return {"passed": counts.get("passed", 0), "skipped": counts.get("skipped", 0),
            "failed": counts.get("failed", 0), "errors": counts.get("error", 0),
            "seconds": float(DURATION.search(lines[-1]).group(1))}


def main() -> int:
    result = subprocess.run([sys.executable, "-m", "pytest", *TEST_COMMAND], cwd=ROOT,
                            stdout=subprocess.PIPE, text=True)
    figures = {**summary(result.stdout), "cores": len(os.sched_getaffinity(0))}
    print(json.dumps(figures, indent=1))
    return 0 if result.returncode == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
