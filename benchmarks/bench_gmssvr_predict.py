"""Time the prediction of a GMS+SVR model on a long log (best of several repeats).

Uses only the public API, so the same script times an older checkout too:
run it in both and compare (the note of a change states both figures and the core count).

Prints one JSON line: n_samples, n_support, predict_s (best of --repeats), ns_per_sample and cpu_count.

    python benchmarks/bench_gmssvr_predict.py --duration 400 --repeats 5
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

from greybox.data.io import read_log
from greybox.data.prepare import prepare
from greybox.models.friction.gms import GMSModel
from greybox.models.gmssvr import GMSSVRModel
from greybox.twin import make_dataset

DATA = Path(__file__).resolve().parents[1] / "data"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=400.0, help="length of the predicted log [s] (2 ms step)")
    parser.add_argument("--repeats", type=int, default=5, help="timed predictions; the best is reported")
    parser.add_argument("--seed", type=int, default=11, help="seed of the synthetic log to predict")
    args = parser.parse_args()

    train = prepare([read_log(DATA / "X_A.mcap"), read_log(DATA / "X_B.mcap")])
    model = GMSSVRModel(gms=GMSModel(n_starts=1, max_iter=100), optimize=False, C=0.5, epsilon=0.02, gamma=3.0,
                        n_subset=2000).fit(train)
    (log,) = prepare([make_dataset("X", "C", args.seed, duration_s=args.duration)])
    model.predict(log)  # compile and warm up
    times = []
    for _ in range(args.repeats):
        start = time.perf_counter()
        model.predict(log)
        times.append(time.perf_counter() - start)
    best = min(times)
    print(json.dumps({
        "n_samples": len(log),
        "n_support": int(model.dual_coef_.size),
        "predict_s": round(best, 4),
        "ns_per_sample": round(1e9 * best / len(log), 1),
        "cpu_count": len(os.sched_getaffinity(0)),
    }))


if __name__ == "__main__":
    main()
