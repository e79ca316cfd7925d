"""``greybox monitor`` on the independent simulator's production histories, scored against their truth (issue 40).

Usage::

    python scripts/monitor_independent.py [--data DIR] [--variants spindle,plain,air] [--json OUT|-] [--work DIR]

For each machine of ``DIR`` (default ``../shared/data/independent/histories_dev`` beside the repository;
``DIR/truth.json`` holds per machine the drift kind and its onset date) the daily logs are run through
:func:`greybox.monitor.workflow.run_monitor` (what ``greybox monitor`` calls) in two variants:

- ``spindle``: the logs as they are, ``--spindle-load spindle_load_pct``;
- ``plain``: copies of the logs without the spindle-load column (written to the work folder), with
  ``--find-cuts`` instead: the monitor finds the stretches without process load itself;
- ``air``: the same copies without either, every log taken as an air cut (``greybox monitor``'s default, and
  its only way without a spindle-load column or a reference model until issue 40).

Printed per variant and machine: the drift kind, its onset, the first alarm (feature, direction, day
detected), the days from the onset to it, whether it names the right change (a sliding or break-away level
rising for a lubrication loss, falling for a preload loss, the local excess rising for a local defect), the
alarms detected before the onset, and every alarm of a stable machine; and the detector's threshold per
feature. The machines are filed one after the other into one history per variant (one plant) and scored on
the detector of the whole history (its thresholds from every machine's baseline days). ``--json`` writes the
same as JSON.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import sys
import tempfile
from pathlib import Path

import pyarrow.parquet as pq

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from greybox.atomic import write_text_atomic  # noqa: E402
from greybox.monitor.workflow import run_monitor  # noqa: E402

#: Default data: the development split beside the repository.
DEFAULT_DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "independent" / "histories_dev"
#: The spindle-load column of the independent histories.
SPINDLE_COLUMN = "spindle_load_pct"
#: Whether an alarm names the change of a drift kind.
RIGHT = {
    "lubrication_loss": lambda a: a.direction == "rises" and a.feature.split("_")[0] in ("sliding", "breakaway"),
    "preload_loss": lambda a: a.direction == "falls" and a.feature.split("_")[0] in ("sliding", "breakaway"),
    "local_defect": lambda a: a.direction == "rises" and a.feature == "local_excess",
}
#: Within how many days of the onset a drift must be alarmed (issue 40's target).
TARGET_DAYS = 7


def plain_copies(logs: list, folder: Path) -> list:
    """Copies of ``logs`` (Parquet) without the spindle-load column, in ``folder``, under the same names."""
    folder.mkdir(parents=True, exist_ok=True)
    copies = []
    for path in logs:
        table = pq.read_table(path)
        copy = folder / path.name
        pq.write_table(table.drop_columns([SPINDLE_COLUMN]), copy)
        copies.append(copy)
    return copies


def score_machine(name: str, truth: dict, alarms: list) -> dict:
    """The score of one machine's alarms against its truth."""
    kind = truth["kind"]
    described = [{"feature": a.feature, "direction": a.direction, "start": a.start.isoformat(),
                  "detected": a.detected.isoformat()} for a in alarms]
    result = {"machine": name, "kind": kind, "alarms": described, "n_alarms": len(alarms)}
    if kind == "none":
        result.update(ok=not alarms)
        return result
    onset = dt.date.fromisoformat(truth["onset_date"])
    before = [a for a in alarms if a.detected < onset]
    after = sorted((a for a in alarms if a.detected >= onset), key=lambda a: a.detected)
    first = after[0] if after else None
    delay = (first.detected - onset).days if first else None
    right = bool(first is not None and RIGHT[kind](first))
    result.update(onset=onset.isoformat(), alarms_before_onset=len(before), delay_days=delay,
                  first=None if first is None else f"{first.feature} {first.direction}", right_first=right,
                  ok=bool(not before and delay is not None and delay <= TARGET_DAYS and right))
    return result


def run(data: Path, work: Path, variants: list, progress=print) -> dict:
    """Run every variant on every machine of ``data``; the scores."""
    truth = json.loads((data / "truth.json").read_text())["machines"]
    results = {}
    for variant in variants:
        for name in sorted(truth):  # the plant's machines filed one after the other into one history
            logs = sorted((data / name).glob("*.parquet"))
            if variant in ("plain", "air"):
                logs = plain_copies(logs, work / "plain_logs" / name)
            column = SPINDLE_COLUMN if variant == "spindle" else None
            outcome = run_monitor(logs, work / variant / "history", work / variant / "report", machine=name,
                                  spindle_column=column, find_cuts=variant == "plain",
                                  force=True)  # the variant's one dashboard, made anew as each machine is filed
        # scored on the whole plant's history: the thresholds come from every machine's baseline days
        rows = [score_machine(name, truth[name], [a for a in outcome.detector.alarms_ if a.machine == name])
                for name in sorted(truth)]
        for row in rows:
            progress(f"{variant} {row['machine']}: {format_row(row)}")
        thresholds = outcome.detector.thresholds_
        progress(f"{variant} thresholds h: " + ", ".join(f"{f} {h:.2f}" for f, h in thresholds.items()))
        results[variant] = {"machines": rows, "thresholds": thresholds}
    return results


def format_row(row: dict) -> str:
    """One line of the table."""
    if row["kind"] == "none":
        return f"stable: {row['n_alarms']} alarms " + ", ".join(
            f"{a['feature']} {a['direction']} {a['detected']}" for a in row["alarms"])
    delay = "never" if row["delay_days"] is None else f"+{row['delay_days']} d"
    return (f"{row['kind']} from {row['onset']}: first alarm {row['first'] or '-'} {delay}, "
            f"right first {'yes' if row['right_first'] else 'no'}, {row['alarms_before_onset']} before onset "
            f"[{'met' if row['ok'] else 'NOT met'}]")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA, help="folder of machines and truth.json")
    parser.add_argument("--variants", default="spindle,plain",
                        help="comma-separated: spindle (with the spindle-load column), plain (without it, "
                             "--find-cuts), air (without it, every log an air cut)")
    parser.add_argument("--json", metavar="OUT", help="write the scores as JSON ('-': print them, last)")
    parser.add_argument("--work", type=Path, help="work folder (histories, reports, copies); default a temporary one")
    args = parser.parse_args(argv)
    variants = [v for v in args.variants.split(",") if v]
    if not args.data.is_dir() or any(v not in ("spindle", "plain", "air") for v in variants):
        print(f"error: need a data folder and variants of spindle, plain, air; got {args.data}, {args.variants}")
        return 2
    with tempfile.TemporaryDirectory() as scratch:
        results = run(args.data, args.work or Path(scratch), variants)
    met = all(row["ok"] for result in results.values() for row in result["machines"])
    print(f"targets ({TARGET_DAYS} days, right feature first, nothing before onset, stable quiet): "
          f"{'met' if met else 'NOT met'}")
    if args.json == "-":
        print(json.dumps({"variants": results, "met": met}))
    elif args.json:
        write_text_atomic(args.json, json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
