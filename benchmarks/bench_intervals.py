"""Cost and coverage of the parameter intervals (:mod:`greybox.identify.intervals`).

Usage::

    python benchmarks/bench_intervals.py time [--log data/X_A.mcap] [--model gms] [--json]
    python benchmarks/bench_intervals.py coverage [--seeds 20] [--duration 20]
    python benchmarks/bench_intervals.py compare [--replicates 30] [--duration 20] [--seed 0]

``time`` fits ``--model`` on the log as ``greybox train`` does (default settings) and then computes
the sandwich intervals; it prints both wall times, their ratio and the parameter table with the
intervals (``--json``: then the figures as one JSON object, last; the command of record
``intervals-cost``). ``coverage`` simulates a 3-element GMS axis of known parameters (forward Euler, AR(1)
noise of time constant 0.1 s on the current), fits a GMS model to each seed's run and counts how often
each scalar parameter's 95 % sandwich interval contains the truth, and how often a parameter is
flagged. A fit that ends in another local minimum than the truth's counts as a miss: the figure is the
coverage of the whole procedure, search included. ``compare`` puts the sandwich and the bootstrap
intervals of one such fit side by side. Ratios and shares, not absolutes, carry over to
other machines.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from scipy.signal import lfilter

from greybox.cli._model_text import model_lines
from greybox.data.io import read_log
from greybox.data.log import AxisLog
from greybox.data.prepare import prepare
from greybox.identify.intervals import attach_intervals
from greybox.models.friction import GMSModel
from greybox.models.friction.gms import simulate_gms
from greybox.models.registry import model_class

STEP = 0.002
#: Truth of the coverage study: alpha, k [A/mm], C [mm/s], sigma, mu [A s/mm], s_0, s_inf [mm], v_s [mm/s],
#: J [A s^2/mm].
TRUTH = {"alpha": np.array([0.1, 0.3, 0.6]), "k": np.array([30.0, 50.0, 60.0]), "slip_rate": 3.0, "sigma": 0.5,
         "viscous": 0.01, "s_0": 0.02, "s_inf": 0.015, "v_s": 5.0, "J": 2e-3}


def bench_time(log: str, kind: str, as_json: bool = False) -> None:
    runs = prepare([read_log(log)])
    model = model_class(kind)()
    started = time.perf_counter()
    model.fit(runs)
    fitted = time.perf_counter() - started
    started = time.perf_counter()
    attach_intervals(model, runs)
    intervals = time.perf_counter() - started
    record = model.parameter_intervals_
    print(f"{kind} on {log}: fit {fitted:.1f} s, sandwich intervals {intervals:.2f} s "
          f"(ratio {intervals / fitted:.3f}) over {record['n_clusters']} {record['clusters']}")
    print("\n".join(model_lines(model)))
    if as_json:
        print(json.dumps({"log": log, "model": kind, "n_samples": int(sum(run.time.size for run in runs)),
                          "fit_s": round(fitted, 2), "intervals_s": round(intervals, 3),
                          "ratio": round(intervals / fitted, 4), "n_clusters": int(record["n_clusters"]),
                          "clusters": record["clusters"]}))


def truth_run(seed: int, duration: float) -> AxisLog:
    """One run of the GMS truth: strokes with a slow ripple, dwells and small reversals, AR(1) noise."""
    t = np.arange(int(duration / STEP)) * STEP
    rng = np.random.default_rng(seed)
    velocity = 20.0 * np.sin(2 * np.pi * 0.3 * t) + 2.0 * np.sin(2 * np.pi * 2.1 * t + seed)
    acceleration = np.gradient(velocity, STEP)
    friction, _ = simulate_gms(velocity, STEP, alpha=TRUTH["alpha"], k=TRUTH["k"], C=TRUTH["slip_rate"],
                               sigma=TRUTH["sigma"], s_0=TRUTH["s_0"], s_inf=TRUTH["s_inf"], v_s=TRUTH["v_s"],
                               mu=TRUTH["viscous"])
    shocks = rng.normal(0.0, 0.01, t.size)
    shocks[0] /= np.sqrt(1.0 - 0.98**2)
    effort = TRUTH["J"] * acceleration + friction + lfilter([1.0], [1.0, -0.98], shocks)
    return AxisLog(time=t, position=np.cumsum(velocity) * STEP, effort=effort, velocity=velocity,
                   acceleration=acceleration)


def bench_coverage(n_seeds: int, duration: float) -> None:
    names = ["slip_rate", "sigma", "viscous", "s_0", "s_inf", "v_s", "J"]
    hits = dict.fromkeys(names, 0)
    flagged = dict.fromkeys(names, 0)
    missing = dict.fromkeys(names, 0)
    seconds = []
    for seed in range(n_seeds):
        run = truth_run(seed, duration)
        started = time.perf_counter()
        model = GMSModel(n_elements=3, random_state=seed).fit(run)
        fitted = time.perf_counter() - started
        started = time.perf_counter()
        rows = {row.name: row for row in attach_intervals(model, run).parameter_table()}
        seconds.append((fitted, time.perf_counter() - started))
        for name in names:
            row = rows[name]
            flagged[name] += bool(row.flag)
            missing[name] += bool(np.isnan(row.lower))
            hits[name] += bool(row.lower <= TRUTH[name] <= row.upper)
        print(f"seed {seed}: " + ", ".join(f"{name} {rows[name].value:.4g} [{rows[name].lower:.4g}, "
                                           f"{rows[name].upper:.4g}]{' ' + rows[name].flag if rows[name].flag else ''}"
                                           for name in names), flush=True)
    fit_s, interval_s = np.median(seconds, axis=0)
    print(f"coverage of the 95 % intervals over {n_seeds} seeds ({duration:g} s runs; median fit {fit_s:.1f} s, "
          f"intervals {interval_s:.2f} s):")
    for name in names:
        print(f"  {name:<10} covered {hits[name]}/{n_seeds}, of the {n_seeds - missing[name]} with an interval: "
              f"{hits[name] / max(n_seeds - missing[name], 1):.3f}; flagged {flagged[name]}/{n_seeds}")


def bench_compare(n_replicates: int, duration: float, seed: int) -> None:
    """Widths of the sandwich and of the bootstrap intervals of a GMS fit to one simulated run."""
    run = truth_run(seed, duration)
    model = GMSModel(n_elements=3, random_state=seed).fit(run)
    sandwich = {row.name: row for row in attach_intervals(model, run).parameter_table()}
    started = time.perf_counter()
    bootstrap = {row.name: row for row in attach_intervals(model, run, method="bootstrap",
                                                            n_bootstrap=n_replicates).parameter_table()}
    print(f"GMS on one simulated {duration:g} s run (seed {seed}); bootstrap of {n_replicates} refits in "
          f"{time.perf_counter() - started:.0f} s")
    print(f"  {'parameter':<10} {'truth':>10} {'value':>10} {'sandwich':>24} {'bootstrap':>24}")
    for name in ("slip_rate", "sigma", "viscous", "s_0", "s_inf", "v_s", "J"):
        a, b = sandwich[name], bootstrap[name]
        print(f"  {name:<10} {TRUTH[name]:>10.4g} {a.value:>10.4g} {a.lower:>11.4g} {a.upper:>11.4g}  "
              f"{b.lower:>11.4g} {b.upper:>11.4g}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="what", required=True)
    timing = sub.add_parser("time")
    timing.add_argument("--log", default="data/X_A.mcap")
    timing.add_argument("--model", default="gms")
    timing.add_argument("--json", action="store_true", help="print the figures as one JSON object, last")
    coverage = sub.add_parser("coverage")
    coverage.add_argument("--seeds", type=int, default=20)
    coverage.add_argument("--duration", type=float, default=20.0)
    compare = sub.add_parser("compare")
    compare.add_argument("--replicates", type=int, default=30)
    compare.add_argument("--duration", type=float, default=20.0)
    compare.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    if args.what == "time":
        bench_time(args.log, args.model, args.json)
    elif args.what == "coverage":
        bench_coverage(args.seeds, args.duration)
    else:
        bench_compare(args.replicates, args.duration, args.seed)


if __name__ == "__main__":
    main()
