"""Throughput of fleet runs: ``greybox predict MODEL LOGS... --out DIR`` (or ``greybox train --per-machine``)
on 1 and on 2 Dask workers.

Usage::

    python benchmarks/bench_fleet.py [--json] [--logs 4] [--duration 3600] [--model gms] [--out DIR] [--train]

Synthesises ``--logs`` cutting logs of the twin's X axis (dataset A of ``--duration`` seconds each, MCAP,
different seeds) in two machine folders, trains ``--model`` on a short air cut, and runs the fleet
command (the library call behind it, :func:`greybox.fleet.predict.run_fleet`) twice from scratch: a local
cluster of 1 worker, then of 2. With ``--train`` the fleet trains instead a ``--model`` per machine on
its logs (:func:`greybox.fleet.train.run_training`, two tasks; short logs, ``--duration 60``, keep it
quick). Printed, measured in one run on this machine (its cores stated):

- ``samples_per_s``: samples predicted and written (trained on) per second of wall time, cluster start
  included;
- ``scaling_efficiency``: (throughput with 2 workers) / (2 x throughput with 1 worker);
- ``peak_rss_mb_per_worker``: the largest peak resident memory a worker process reported.

Ratios, not absolutes, carry over to other machines.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import tempfile
import time
from pathlib import Path

from greybox.data.io import write_log
from greybox.data.prepare import prepare
from greybox.fleet import expand_logs
from greybox.fleet.predict import fleet_jobs, run_fleet
from greybox.fleet.train import run_training, train_jobs
from greybox.models.files import save_model
from greybox.models.registry import model_class
from greybox.twin import make_dataset


def build(root: Path, n_logs: int, duration_s: float, kind: str) -> Path:
    """The logs (two machine folders) and the model file under ``root``; return the model file."""
    for k in range(n_logs):
        folder = root / "plant" / f"mill{k % 2 + 1}"
        folder.mkdir(parents=True, exist_ok=True)
        write_log(make_dataset("X", "A", 100 + k, duration_s=duration_s, cutting=True), folder / f"log{k}.mcap")
    model = model_class(kind)().fit(prepare([make_dataset("X", "A", 1, duration_s=60)]))
    save_model(model, root / "model.gbm")
    return root / "model.gbm"


def measure(model: Path, root: Path, workers: int, kind: str | None = None) -> dict:
    """One fleet run from scratch on a local cluster of ``workers`` processes: prediction with ``model``,
    or with ``kind`` training a model of that kind per machine."""
    out = root / f"out{workers}"
    shutil.rmtree(out, ignore_errors=True)
    logs = expand_logs([str(root / "plant")])
    started = time.perf_counter()
    if kind is None:
        manifest, items = run_fleet(fleet_jobs(logs, str(model), str(out)), workers=workers), "logs"
    else:
        manifest, items = run_training(train_jobs(logs, model_class(kind)(), str(out)), workers=workers), "models"
    seconds = time.perf_counter() - started
    samples = sum(entry.get("samples", 0) for entry in manifest[items])
    peaks = [entry["peak_rss_mb"] for entry in manifest[items] if entry.get("peak_rss_mb") is not None]
    return {"workers": workers, "seconds": seconds, "samples": samples, "samples_per_s": samples / seconds,
            "failed": manifest["counts"]["failed"], "peak_rss_mb_per_worker": max(peaks) if peaks else None}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--logs", type=int, default=4, help="number of logs (default 4)")
    parser.add_argument("--duration", type=float, default=3600.0, help="length of each log [s] (default 3600)")
    parser.add_argument("--model", default="gms", help="model kind (default gms)")
    parser.add_argument("--out", help="keep the logs and outputs in this directory (default: a temporary one)")
    parser.add_argument("--train", action="store_true", help="time fleet training (a model per machine) instead")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args()
    root = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="bench_fleet_"))
    root.mkdir(parents=True, exist_ok=True)
    try:
        model = build(root, args.logs, args.duration, args.model)
        kind = args.model if args.train else None
        one, two = measure(model, root, 1, kind), measure(model, root, 2, kind)
    finally:
        if not args.out:
            shutil.rmtree(root, ignore_errors=True)
    result = {"cores": os.cpu_count(), "logs": args.logs, "duration_s": args.duration, "model": args.model,
              "task": "train" if args.train else "predict",
              "runs": [one, two], "scaling_efficiency": two["samples_per_s"] / (2.0 * one["samples_per_s"])}
    if args.json:
        print(json.dumps(result))
        return
    print(f"{result['task']}: {args.logs} logs of {args.duration:g} s, {args.model} model, {result['cores']} cores")
    for run in result["runs"]:
        print(f"  {run['workers']} worker(s): {run['samples']} samples in {run['seconds']:.1f} s, "
              f"{run['samples_per_s'] / 1e3:.0f} k samples/s, peak {run['peak_rss_mb_per_worker']:.0f} MB per worker")
    print(f"  scaling efficiency 2 workers: {result['scaling_efficiency']:.2f}")


if __name__ == "__main__":
    main()
