"""Friction feed-forward on the twin's X axis: ``greybox compensate`` with every model kind, as JSON.

Runs the command of docs/compensate.md into a temporary directory and prints the report's JSON document
(``compensation.json``: the settings and one row per reference and feed-forward) as the last thing on its
standard output, with the command's wall time (the command of record ``compensate-twin``,
``scripts/record.py``)::

    python scripts/compensate_twin.py
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

from greybox.cli import main as greybox

#: The command of the page, but for the output directory.
COMMAND = ("compensate", "--plant", "twin-X", "--model", "coulomb", "stribeck", "lugre", "gms", "gmssvr")


def main() -> int:
    with tempfile.TemporaryDirectory() as scratch:
        started = time.perf_counter()
        status = greybox([*COMMAND, "--out", scratch, "--quiet"])
        seconds = time.perf_counter() - started
        if status != 0:
            return status
        document = json.loads((Path(scratch) / "compensation.json").read_text(encoding="utf-8"))
    figures = {"command": "greybox " + " ".join(COMMAND) + " --out DIR", "seconds": round(seconds, 1),
               "settings": document["settings"], "rows": document["rows"]}
    print(json.dumps(figures))
    return 0


if __name__ == "__main__":
    sys.exit(main())
