"""The example of docs/intervals.md, run as printed: a GMS model on the shipped X_A and its parameter intervals.

Runs ``greybox train --model gms --train data/X_A.mcap --out x.gbm`` and ``greybox info --json x.gbm`` with the
greybox of this Python in a temporary folder holding links to ``data/`` and ``examples/``, and prints the
training's interval lines and the parameters with their intervals and flags as one JSON object last (the record
``intervals-example`` of ``scripts/record.py``).

Usage::

    python scripts/intervals_example.py
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from studies.as_printed import reader_folder, run_greybox

#: The page's command, after ``greybox``.
TRAIN = ("train", "--model", "gms", "--train", "data/X_A.mcap", "--out", "x.gbm")


def interval_lines(lines: list) -> list[str]:
    """The lines of ``greybox train``'s output from the intervals' header to the end of the parameters."""
    start = next(n for n, line in enumerate(lines) if line.startswith("95 % intervals"))
    end = next((n for n, line in enumerate(lines[start:], start) if line.startswith("fit:")), len(lines))
    return [line for line in lines[start:end] if line.strip()]


def main() -> int:
    with reader_folder("greybox-intervals-") as folder:
        printed = run_greybox(folder, *TRAIN)
        info = "\n".join(run_greybox(folder, "info", "--json", "x.gbm"))
    info = json.loads(info[info.index("{"):])  # past any note: line
    lines = interval_lines(printed)
    print("\n".join(lines))
    print(json.dumps({"command": "greybox " + " ".join(TRAIN), "lines": lines, "parameters": info["parameters"]},
                     indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
