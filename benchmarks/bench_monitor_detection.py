"""Detection of the ageing twin's drifts by ``greybox monitor``'s fingerprint and CUSUM detector.

Usage::

    python benchmarks/bench_monitor_detection.py [--seeds 5] [--days 56] [--start 35] [--rate 0.01] [--json]

For each seed (1000, 1001, ...: apart from the tests' seeds) and each drift kind (lubrication, preload at
``--rate`` per day from day ``--start``; none) the twin's X axis writes ``--days`` daily air-move logs
(in memory, :func:`greybox.twin.ageing.aged_log`), each is fingerprinted
(:class:`greybox.monitor.fingerprint.FrictionFingerprint`, defaults) and the history is run through
:class:`greybox.monitor.detect.ChangeDetector` (defaults: 28 baseline days, threshold calibrated for one
false alarm per axis-year). Printed per drift kind: the days from the onset to the first alarm of each
seed, the feature and direction it named, and the alarms of the stable axes (with the axis-days watched
after the baseline).
"""

from __future__ import annotations

import argparse
import datetime as dt
import json

import numpy as np
import pyarrow as pa

from greybox.data.prepare import prepare
from greybox.monitor.detect import ChangeDetector
from greybox.monitor.fingerprint import FEATURES, FrictionFingerprint
from greybox.monitor.history import SCHEMA, SCHEMA_VERSION
from greybox.twin.ageing import Drift, aged_log

DAY0 = dt.date(2026, 1, 1)


def history_table(seed: int, days: int, drifts) -> pa.Table:
    rows = {name: [] for name in SCHEMA.names}
    for day in range(days):
        fitted = FrictionFingerprint().fit(prepare(aged_log("X", day, seed, drifts)))
        key = {"schema_version": SCHEMA_VERSION, "machine": f"twin{seed}", "axis": "X",
               "date": DAY0 + dt.timedelta(days=day), "log_sha256": f"{day:064x}", "source": "",
               "n_samples": fitted.n_samples_}
        for name, value in key.items():
            rows[name].append(value)
        for name in FEATURES:
            rows[name].append(fitted.values_[name])
            rows[f"{name}_lo"].append(fitted.lower_[name])
            rows[f"{name}_hi"].append(fitted.upper_[name])
    return pa.Table.from_pydict(rows, schema=SCHEMA)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--days", type=int, default=56)
    parser.add_argument("--start", type=int, default=35)
    parser.add_argument("--rate", type=float, default=0.01)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    results = {}
    for kind in ("lubrication", "preload", "none"):
        delays, named, false_alarms = [], [], 0
        for seed in range(1000, 1000 + args.seeds):
            drifts = [] if kind == "none" else [Drift(kind, args.start, args.rate)]
            detector = ChangeDetector().fit(history_table(seed, args.days, drifts))
            alarms = detector.alarms_
            if kind == "none":
                false_alarms += len(alarms)
                continue
            after = [a for a in alarms if a.detected >= DAY0 + dt.timedelta(days=args.start)]
            early = len(alarms) - len(after)
            false_alarms += early
            if after:
                first = min(after, key=lambda a: a.detected)
                delays.append((first.detected - DAY0).days - args.start)
                named.append(f"{first.feature} {first.direction}")
            else:
                delays.append(None)
                named.append("not detected")
        watched = args.seeds * (args.days - 28) if kind == "none" else args.seeds * (args.start - 28)
        results[kind] = {"delays_days": delays, "first_named": named, "false_alarms": false_alarms,
                         "axis_days_watched_stable": watched}
    if args.json:
        print(json.dumps(results, indent=2))
        return
    for kind, r in results.items():
        print(f"{kind}: delays {r['delays_days']} days, first alarm {r['first_named']}, false alarms "
              f"{r['false_alarms']} in {r['axis_days_watched_stable']} stable axis-days after the baseline")
    print(f"(seeds 1000-{999 + args.seeds}, {args.days} days, drift from day {args.start} at {args.rate} per day; "
          f"the feature arrays: {', '.join(FEATURES)})")


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
