"""``greybox discover`` on the shipped synthetic X axis, as docs/discover.md runs it.

Runs ``greybox discover --model gms --train data/X_A.mcap --test data/X_C.mcap`` with the greybox of this
Python and prints its JSON document with the noise floor of the test log (the RMS of the measured current
less the twin's noise-free current ``truth_current_A``) as one JSON object last (the record
``discover-twin`` of ``scripts/record.py``).

Usage::

    python scripts/discover_shipped.py
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from greybox.data import read_log
from studies.as_printed import reader_folder, run_greybox

ROOT = Path(__file__).resolve().parents[1]
#: The command's arguments after ``greybox discover``, without ``--json``.
ARGUMENTS = ("--model", "gms", "--train", "data/X_A.mcap", "--test", "data/X_C.mcap")


def main() -> int:
    with reader_folder("greybox-discover-") as folder:
        printed = run_greybox(folder, "discover", *ARGUMENTS, "--json", "x.json")
        document = json.loads((folder / "x.json").read_text(encoding="utf-8"))
    print("\n".join(printed))
    test = read_log(ROOT / "data" / "X_C.mcap")
    floor = float(np.sqrt(np.mean((test.effort - test.extras["truth_current_A"]) ** 2)))
    print(json.dumps({"command": "greybox discover " + " ".join(ARGUMENTS) + " --json x.json",
                      "noise_floor_A": floor, "document": document}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
