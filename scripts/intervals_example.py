"""The example of docs/intervals.md, run as printed: a GMS model on the shipped X_A and its parameter intervals.

Runs ``greybox train --model gms --train data/X_A.mcap --out x.gbm`` and ``greybox info --json x.gbm`` with the
greybox of this Python in a temporary folder holding a link to ``data/``, and prints the training's interval
lines and the parameters with their intervals and flags as one JSON object last (the record
``intervals-example`` of ``scripts/record.py``).

Usage::

    python scripts/intervals_example.py
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: The page's command, after ``greybox``.
TRAIN = ("train", "--model", "gms", "--train", "data/X_A.mcap", "--out", "x.gbm")


def _greybox(folder: Path, *args: str) -> str:
    """Run one greybox command in ``folder``; its standard output."""
    done = subprocess.run([sys.executable, "-m", "greybox", *args], cwd=folder, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"error: greybox {' '.join(args)} failed ({done.returncode}): {done.stderr.strip()}")
    return done.stdout


def interval_lines(printed: str) -> list[str]:
    """The lines of ``greybox train``'s output from the intervals' header to the end of the parameters."""
    lines = printed.splitlines()
    start = next(n for n, line in enumerate(lines) if line.startswith("95 % intervals"))
    end = next((n for n, line in enumerate(lines[start:], start) if line.startswith("fit:")), len(lines))
    return [line for line in lines[start:end] if line.strip()]


def main() -> int:
    with tempfile.TemporaryDirectory(prefix="greybox-intervals-") as folder:
        (Path(folder) / "data").symlink_to(ROOT / "data", target_is_directory=True)
        printed = _greybox(Path(folder), *TRAIN)
        info = json.loads(_greybox(Path(folder), "info", "--json", "x.gbm"))
    lines = interval_lines(printed)
    print("\n".join(lines))
    print(json.dumps({"command": "greybox " + " ".join(TRAIN), "lines": lines, "parameters": info["parameters"]},
                     indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
