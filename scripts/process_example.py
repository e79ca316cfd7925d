"""The example of docs/process.md, run as printed: a GMS model, a twin part series whose tool breaks, teach, check.

Trains ``gms_x.gbm`` on the shipped air cuts X_A and X_C, makes the twin's 12-part series (seed 5, the tool
broken in part 12 at 33.4 s), teaches a re-levelled force envelope on parts 1-10 and checks the series, each
with the greybox of this Python in a temporary folder holding links to ``data/`` and ``examples/`` (so what it
prints names the files as the page does). Prints the teach-in's and the check's console lines, the truth of the
series and the check's table of the parts as one JSON object last (the record ``process-example`` of
``scripts/record.py``); ``--figures DIR`` copies the check's picture of part 12 there as
``process-part-breakage.png`` (the page's figure).

Usage::

    python scripts/process_example.py [--figures docs/figures]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from greybox.atomic import write_bytes_atomic
from studies.as_printed import reader_folder, run_greybox

#: The page's commands, after ``greybox``.
COMMANDS = (
    ("train", "--model", "gms", "--train", "data/X_A.mcap", "data/X_C.mcap", "--out", "gms_x.gbm"),
    ("synth", "--parts", "12", "--out", "series", "--seed", "5", "--breakage", "12:33.4", "--truth", "essential"),
    ("process", "teach", "gms_x.gbm", *(f"series/X_part{n:03d}.mcap" for n in range(1, 11)),
     "--axis-config", "examples/axis_x.toml", "--relevel", "--out", "force.json"),
    ("process", "check", "force.json", "series/X_series.mcap", "--out", "report", "--figures", "1"),
)


def process_example(folder: Path) -> dict:
    """Run the example in ``folder`` (:func:`studies.as_printed.reader_folder`); the lines and figures quoted."""
    printed = [run_greybox(folder, *args) for args in COMMANDS]
    truth = json.loads((folder / "series" / "X_parts.json").read_text(encoding="utf-8"))
    parts = pd.read_csv(folder / "report" / "parts.csv")
    stretches = pd.read_csv(folder / "report" / "stretches.csv")
    return {
        "teach_lines": printed[2],
        "check_lines": printed[3],
        "parts": parts.to_dict(orient="records"),
        "stretches": stretches.to_dict(orient="records"),
        "truth_parts": truth["parts"],
        "truth_events": truth["events"],
        "warm_up": truth["warm_up"],
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figures", type=Path, help="copy the check's picture of part 12 here as "
                        "process-part-breakage.png (the page's figure)")
    args = parser.parse_args(argv)
    with reader_folder("greybox-process-example-") as folder:
        figures = process_example(folder)
        if args.figures:
            picture = folder / "report" / "part_X_series_012.png"
            write_bytes_atomic(args.figures / "process-part-breakage.png", picture.read_bytes())
    print("\n".join(figures["teach_lines"] + figures["check_lines"]))
    print(json.dumps(figures, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
