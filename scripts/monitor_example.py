"""The example of docs/monitor.md, run as a reader would run it.

Writes 45 days of the ageing twin's X axis with a local defect from day 35 (``greybox synth --history``),
fingerprints them into a history and writes the dashboard (``greybox monitor``), in a temporary folder, with
the greybox of this Python. Prints the console output of both commands and the figures the page quotes (with
the backlash feature's range over the days before the onset), as one JSON object last (the record
``monitor-example`` of ``scripts/record.py``); with ``--figures DIR`` the dashboard's first two pictures (the
axis' features over the days, its friction along the travel) are copied there as ``monitor-twin-X.png`` and
``monitor-twin-X-travel.png``.

Usage::

    python scripts/monitor_example.py [--figures docs/figures]
"""

from __future__ import annotations

import argparse
import base64
import json
import re
import sys
from datetime import date
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from greybox.atomic import write_bytes_atomic
from greybox.data import read_log
from greybox.monitor.history import read_history
from studies.as_printed import reader_folder, run_greybox

#: The page's synth command after ``greybox``.
SYNTH = ("synth", "--history", "45", "--axis", "X", "--seed", "7", "--drift", "defect:35:0.03", "--truth",
         "essential", "--out", "logs/")
#: The day the drift starts (the ``START`` of ``--drift``).
ONSET_DAY = 35
#: The pictures the dashboard embeds, in the order it draws them for one axis, and the page's names for them.
PICTURES = ("monitor-twin-X.png", "monitor-twin-X-travel.png")
_EMBEDDED_PNG = re.compile(r"data:image/png;base64,([A-Za-z0-9+/=]+)")


def monitor_example(folder: Path) -> tuple[dict, list[bytes]]:
    """Run the page's two commands in ``folder``; the lines and figures the page quotes, and the pictures."""
    run_greybox(folder, *SYNTH)
    logs = sorted(str(path.relative_to(folder)) for path in (folder / "logs").glob("*.mcap"))
    lines = run_greybox(folder, "monitor", *logs, "--history", "history/", "--out", "report/")
    onset = next(path for path in (folder / "logs").glob("*.mcap")
                 if int(read_log(path).attrs.get("day", -1)) == ONSET_DAY)
    onset_date = date.fromisoformat(str(read_log(onset).attrs["date"])[:10])
    history = read_history(folder / "history").to_pandas()
    before = history[pd.to_datetime(history["date"].astype(str)) < pd.Timestamp(onset_date)]
    page = (folder / "report" / "index.html").read_text(encoding="utf-8")
    pictures = [base64.b64decode(found) for found in _EMBEDDED_PNG.findall(page)[:len(PICTURES)]]
    return {
        "synth_command": "greybox " + " ".join(SYNTH),
        "monitor_lines": lines,
        "logs": len(logs),
        "onset_day": ONSET_DAY,
        "onset_date": onset_date.isoformat(),
        "days_before_onset": len(before),
        "backlash_before_onset_um": [1e3 * float(before["backlash"].min()), 1e3 * float(before["backlash"].max())],
        "dashboard_mb": (folder / "report" / "index.html").stat().st_size / 1e6,
    }, pictures


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figures", type=Path, help="copy the dashboard's two pictures of the axis here "
                        "(the page's figures)")
    args = parser.parse_args(argv)
    with reader_folder("greybox-monitor-example-") as folder:
        figures, pictures = monitor_example(folder)
    if args.figures:
        if len(pictures) < len(PICTURES):
            raise SystemExit(f"error: the dashboard embeds {len(pictures)} pictures, not {len(PICTURES)}")
        for name, picture in zip(PICTURES, pictures):
            write_bytes_atomic(args.figures / name, picture)
    print("\n".join(figures["monitor_lines"]))
    print(json.dumps(figures, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
