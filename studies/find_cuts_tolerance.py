"""How ``--find-cuts`` keeps a production log's uncut samples at four tolerances (docs/monitor.md, issue 40).

Usage::

    python studies/find_cuts_tolerance.py [--data DIR] [--json]

On every fourth day of the four machines of the independent simulator's production histories (development
split, ``DIR`` default ``../shared/data/independent/histories_dev``) each run's samples are judged by
:func:`greybox.monitor.cutting.uncut_samples` at the tolerances 0.05, 0.1, 0.2 and 0.3 of the sliding level,
and compared with what the logs' spindle-load column keeps (:func:`greybox.monitor.fingerprint.
spindle_idle_samples`, the monitor's ``--spindle-load``): the samples kept, and the cutting samples (spindle
load above 30 %) kept. On the ageing twin's air-move days (no process load) the share of the moving samples
kept at the default tolerance. Prints one line per tolerance, then the figures as one JSON object.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from greybox.data import read_log  # noqa: E402
from greybox.data.prepare import prepare  # noqa: E402
from greybox.monitor.cutting import uncut_samples  # noqa: E402
from greybox.monitor.fingerprint import spindle_idle_samples  # noqa: E402
from greybox.twin.ageing import aged_log  # noqa: E402

#: Default data: the development split beside the repository.
DEFAULT_DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "independent" / "histories_dev"
#: The spindle-load column of the independent histories.
SPINDLE_COLUMN = "spindle_load_pct"
#: The tolerances compared (shares of the direction's sliding level); 0.1 is the default.
TOLERANCES = (0.05, 0.1, 0.2, 0.3)
#: A sample is cutting where the spindle load is above this [%].
CUTTING_LOAD_PCT = 30.0
#: Every this many days of each machine.
EVERY_DAYS = 4
#: The twin's air-move days looked at: (day, seed).
TWIN_DAYS = ((0, 0), (0, 1), (40, 0), (40, 1))


def production_days(data: Path) -> list[dict]:
    """Per machine and looked-at day: samples kept by the spindle-load column and by each tolerance."""
    truth = json.loads((data / "truth.json").read_text(encoding="utf-8"))["machines"]
    days = []
    for machine in sorted(truth):
        onset = truth[machine].get("onset")
        for day, path in list(enumerate(sorted((data / machine).glob("*.parquet"))))[::EVERY_DAYS]:
            runs = prepare(read_log(path))
            load = [run.extras[SPINDLE_COLUMN] for run in runs]
            idle = sum(int(np.count_nonzero(spindle_idle_samples(values))) for values in load)
            kept, cutting = {}, {}
            for tolerance in TOLERANCES:
                masks = [uncut_samples(run.velocity, run.acceleration, run.effort, tolerance=tolerance)
                         for run in runs]
                kept[str(tolerance)] = sum(int(np.count_nonzero(mask)) for mask in masks)
                cutting[str(tolerance)] = sum(int(np.count_nonzero(mask & (values > CUTTING_LOAD_PCT)))
                                              for mask, values in zip(masks, load))
            days.append({"machine": machine, "kind": truth[machine]["kind"], "day": day, "onset": onset,
                         "after_onset": onset is not None and day >= onset, "spindle_kept": idle, "kept": kept,
                         "cutting_kept": cutting})
    return days


def twin_air_days() -> list[dict]:
    """Per twin air-move day: the share of its moving samples kept at the default tolerance [%]."""
    out = []
    for day, seed in TWIN_DAYS:
        runs = prepare(aged_log("X", day, seed))
        moving = sum(int(np.count_nonzero(run.velocity != 0.0)) for run in runs)
        kept = sum(int(np.count_nonzero(uncut_samples(run.velocity, run.acceleration, run.effort)
                                        & (run.velocity != 0.0))) for run in runs)
        out.append({"day": day, "seed": seed, "kept_percent": 100.0 * kept / moving})
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA, help="the histories (default: %(default)s)")
    parser.add_argument("--json", action="store_true", help="print the figures as one JSON object last")
    args = parser.parse_args(argv)
    if not (args.data / "truth.json").is_file():
        print(f"error: {args.data}: no truth.json (the independent histories)", file=sys.stderr)
        return 2
    days = production_days(args.data)
    for tolerance in map(str, TOLERANCES):
        ratio = [100.0 * (d["kept"][tolerance] / d["spindle_kept"] - 1.0) for d in days]
        print(f"tolerance {tolerance}: {sum(d['cutting_kept'][tolerance] for d in days)} cutting samples kept over "
              f"{len(days)} days; kept against the spindle-load column {min(ratio):+.1f} to {max(ratio):+.1f} %")
    figures = {"tolerances": list(TOLERANCES), "default": 0.1, "cutting_load_pct": CUTTING_LOAD_PCT,
               "every_days": EVERY_DAYS, "days": days, "twin_air_days": twin_air_days()}
    if args.json:
        print(json.dumps(figures, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
