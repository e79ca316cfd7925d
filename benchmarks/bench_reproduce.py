"""Time ``greybox reproduce`` and compare the grey-box model with the noise floor.

Runs the paper's two experiments on the shipped data exactly as
``greybox reproduce`` does (the command is a thin wrapper of
:func:`greybox.reproduce.experiments.reproduce`), showing its progress on
stderr, then prints one JSON object:

- ``seconds``: wall time of the whole run (reading, fitting, testing, figures, report);
- ``cpu_seconds``: CPU time of this process and its worker processes;
- ``jobs``, ``axes``, ``quick``, ``cores`` (CPUs this process may use);
- ``noise_floor``: per experiment and axis, the GMS+SVR test RE, the noise-floor
  test RE (noise-free current against the measured one) and their ratio;
- ``targets``: ``reproduce_under_600_s`` and ``gmssvr_within_1.5x_noise_floor``
  (experiment 2, every axis), true or false;
- ``metrics`` and ``hyperparameters`` with ``--records``: every metric record of the run (``metrics.json``
  of the report) and the SVR settings found (the paper's Table 2), from which the record
  ``docs/results/reproduce.json`` renders the pages' tables (``python scripts/record.py
  reproduce``).

    python benchmarks/bench_reproduce.py --out /tmp/reproduce-bench
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

from greybox.evaluate.report import noise_floor_ratios
from greybox.json_values import jsonable
from greybox.reproduce.experiments import reproduce

#: Targets of GitHub issue 4.
MAX_SECONDS = 600.0
MAX_RATIO = 1.5


def _cpu_seconds() -> float:
    usage = [resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)]
    return sum(u.ru_utime + u.ru_stime for u in usage)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", help="report directory (default: a new temporary directory)")
    parser.add_argument("--data", default=str(Path(__file__).resolve().parents[1] / "data"),
                        help="directory of the <axis>_<dataset>.mcap logs (default: the repository's data/)")
    parser.add_argument("--axis", nargs="+", default=["X", "Y"], metavar="AXIS")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--records", action="store_true",
                        help="print every metric record and the SVR settings found too")
    args = parser.parse_args()

    out = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="greybox-reproduce-"))
    if out.exists() and any(out.iterdir()):
        parser.error(f"{out} is not empty")
    axes = list(args.axis)
    cpu = _cpu_seconds()
    started = time.perf_counter()
    result = reproduce(out, args.data, axes=axes, quick=args.quick, jobs=args.jobs,
                       progress=lambda line: print(line, file=sys.stderr, flush=True))
    seconds = time.perf_counter() - started
    ratios = noise_floor_ratios(result.records)
    second = [r for r in ratios if r["experiment"] == 2]
    figures = {
        "seconds": round(seconds, 1),
        "cpu_seconds": round(_cpu_seconds() - cpu, 1),
        "jobs": args.jobs,
        "axes": axes,
        "quick": args.quick,
        "cores": len(os.sched_getaffinity(0)),
        "report": str(out),
        "noise_floor": [{k: (round(v, 3) if isinstance(v, float) else v) for k, v in r.items()} for r in ratios],
        "targets": {
            "reproduce_under_600_s": seconds < MAX_SECONDS,
            "gmssvr_within_1.5x_noise_floor": bool(second) and all(r["ratio"] <= MAX_RATIO for r in second),
        },
    }
    if args.records:
        figures["metrics"] = jsonable(list(result.records))
        figures["hyperparameters"] = jsonable(list(result.hyperparameters))
    print(json.dumps(figures, indent=1))


if __name__ == "__main__":
    main()
