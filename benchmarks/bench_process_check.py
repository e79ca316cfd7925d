"""Checking a 100-part series of one-minute parts against a force envelope, against real time, on one core.

Usage::

    python benchmarks/bench_process_check.py [--model gms_x.gbm] [--parts 100] [--json]

Steps: without ``--model`` the model is trained first (``greybox train --model gms --train data/X_A.mcap
data/X_C.mcap``; not timed); the twin writes a series of ``--parts`` parts of the default part program (about
61 s each, one long
MCAP log with a part counter; not timed); an envelope of the process force is taught on its first 10 parts
(``--relevel``); then ``greybox process check`` runs in a fresh process pinned to one core (``taskset -c 0``
where present, and one thread for BLAS and numba): reading, the model's force of every part, the check and the
report. Printed: the log's length, the check's wall time, and their ratio (the issue asks for at least 10x
real time). The machine's load (``os.getloadavg``) is printed beside it: absolutes do not carry over.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from greybox.process.run import teach_logs
from greybox.twin.datasets import ESSENTIAL_TRUTH_CHANNELS
from greybox.twin.part_series import PartSeriesSpec, synthesize_part_series

ROOT = Path(__file__).resolve().parents[1]
#: How the model is trained when none is given.
TRAIN = ("train", "--model", "gms", "--train", "data/X_A.mcap", "data/X_C.mcap")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--model", help="model file (default: train it with greybox " + " ".join(TRAIN) + ")")
    parser.add_argument("--parts", type=int, default=100)
    parser.add_argument("--seed", type=int, default=31)
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = parser.parse_args(argv)
    axis = str(ROOT / "examples" / "axis_x.toml")
    with tempfile.TemporaryDirectory() as scratch:
        root = Path(scratch)
        model = args.model
        if model is None:
            model = str(root / "gms_x.gbm")
            subprocess.run([sys.executable, "-m", "greybox", *TRAIN, "--out", model], cwd=ROOT, check=True,
                           stdout=subprocess.DEVNULL)
        synthesize_part_series(PartSeriesSpec(parts=args.parts), args.seed, root / "parts", layout="both",
                               truth_channels=ESSENTIAL_TRUTH_CHANNELS)
        teach = sorted(str(p) for p in (root / "parts").glob("X_part*.mcap"))[:10]
        teach_logs(teach, root / "env.json", model=model, axis_config=axis, relevel=True)
        env = {**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
               "NUMBA_NUM_THREADS": "1"}
        pin = ["taskset", "-c", "0"] if shutil.which("taskset") else []
        command = [*pin, sys.executable, "-m", "greybox", "process", "check", str(root / "env.json"),
                   str(root / "parts" / "X_series.mcap"), "--out", str(root / "report"), "--figures", "1"]
        load = os.getloadavg()
        started = time.perf_counter()
        done = subprocess.run(command, env=env, capture_output=True, text=True)
        elapsed = time.perf_counter() - started
        if done.returncode != 0:
            print(done.stderr, file=sys.stderr)
            return 1
        rows = json.loads((root / "report" / "report.json").read_text())
        summary = [line for line in done.stdout.splitlines() if "parts checked" in line][-1]
        log_s = float(summary.split("(")[1].split(" s of log")[0])
    figures = {"parts": args.parts, "log_s": log_s, "wall_s": elapsed, "real_time_ratio": log_s / elapsed,
               "one_core": bool(pin), "load_before": load, "load_after": os.getloadavg(),
               "flagged": rows["parts_flagged"], "model": args.model or "greybox " + " ".join(TRAIN),
               "seed": args.seed, "target_ratio": 10.0}
    if args.json:
        print(json.dumps(figures, indent=1))
    else:
        print(f"{args.parts} parts, {log_s:.0f} s of log checked in {elapsed:.1f} s on "
              f"{'one core' if pin else 'unpinned'}: {log_s / elapsed:.1f} x real time "
              f"(load {load[0]:.1f} before, {os.getloadavg()[0]:.1f} after; {rows['parts_flagged']} flagged)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
