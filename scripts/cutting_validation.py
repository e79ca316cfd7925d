"""Validation of ``greybox predict`` on the synthetic axis: recovery of a known cutting-force current.

Protocol:

1. every model kind is fitted with its default settings (as ``greybox train
   --model KIND`` does) on the shipped air cuts ``data/X_A.mcap`` and
   ``data/X_B.mcap``;
2. cutting logs come from :func:`greybox.twin.make_dataset` with
   ``cutting=True`` (default :class:`greybox.twin.cutting.CuttingSpec`: 0.5 A at
   1000 mm/min, 100 Hz tooth ripple, cutting on negative feed over the central
   60 % of the travelled range) on trajectories not used in training: dataset C
   (random steps and sines, a new draw in the measurement window) and D
   (1200 mm/min over the whole travel, a speed not in training), with a seed
   other than the shipped data's;
3. :func:`greybox.evaluate.process.predict_process` gives the process current
   and force (axis metadata ``examples/axis_x.toml``); it is compared with
   the log's ``truth_process_A`` (and the force this truth implies);
4. the air-cut test RMSE is the model's RMSE on the shipped air cut of the
   same dataset (``data/X_C.mcap``, ``data/X_D.mcap``: seed 2024), the figure
   an ordinary evaluation of the model gives;
5. the correlation ceiling is the correlation of the true process current
   with itself plus the log's current noise (``truth_noise_A``): what a
   perfect model would reach.

In the twin the cut changes neither the motion nor the noise, so the error of
the recovered process current equals the model's residual on the same
trajectory without the cut up to the 1 mA current resolution; the script
checks this (``air_identity_A``, the largest difference). On a machine the cut
also changes the following error and the load on the screw, so expect the
process error to exceed the air-cut error there.

Usage::

    python scripts/cutting_validation.py --markdown validation.md --json validation.json --plot-dir figures
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from greybox.data.axis_config import read_axis_config
from greybox.data.io import read_log
from greybox.data.prepare import prepare
from greybox.evaluate.metrics import rmse
from greybox.evaluate.process import force_constant_N_per_A, predict_process
from greybox.models.chunked import predict_chunked
from greybox.models.registry import MODEL_CLASSES
from greybox.twin import make_dataset

ROOT = Path(__file__).resolve().parents[1]
TRAIN_FILES = ("X_A.mcap", "X_B.mcap")
TEST_DATASETS = ("C", "D")
KINDS = ("coulomb", "stribeck", "lugre", "gms", "svr", "gmssvr")


def _atomic_text(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as stream:
            stream.write(text)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def recovery(model, cut, air, config, chunk_s: float) -> dict:
    """Metrics of the recovered process current and force of one cutting log."""
    truth = cut.extras["truth_process_A"]
    result = predict_process(model, cut, axis_config=config, chunk_s=chunk_s)
    cutting = truth != 0.0
    factor = force_constant_N_per_A(config)
    air_residual = air.current - predict_chunked(model, air, chunk_s=chunk_s)
    return {
        "air_same_trajectory_rmse_A": float(np.sqrt(np.mean(air_residual ** 2))),
        "air_identity_A": float(np.max(np.abs(result.process - truth - air_residual))),
        "process_rmse_A": rmse(truth, result.process),
        "correlation": float(np.corrcoef(truth, result.process)[0, 1]),
        "correlation_ceiling": float(np.corrcoef(truth, truth + cut.extras["truth_noise_A"])[0, 1]),
        "process_rmse_in_cut_A": rmse(truth[cutting], result.process[cutting]),
        "force_rmse_N": rmse(factor * truth, result.force),
        "mean_cut_force_true_N": float(np.mean(factor * truth[cutting])),
        "mean_cut_force_estimated_N": float(np.mean(result.force[cutting])),
        "noise_floor_A": float(np.sqrt(np.mean(cut.extras["truth_noise_A"] ** 2))),
        "cut_share": float(np.mean(cutting)),
    }, result


def markdown_table(rows: list[dict]) -> str:
    """The results as a Markdown table."""
    lines = [
        "| model | cutting log | air-cut test RMSE [A] | process RMSE [A] | correlation (ceiling) "
        "| process RMSE in cut [A] | force RMSE [N] | mean cut force true / estimated [N] |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for row in rows:
        lines.append(
            f"| {row['model']} | {row['test']} | {row['air_test_rmse_A']:.4f} | {row['process_rmse_A']:.4f} "
            f"| {row['correlation']:.3f} ({row['correlation_ceiling']:.3f}) | {row['process_rmse_in_cut_A']:.4f} "
            f"| {row['force_rmse_N']:.1f} "
            f"| {row['mean_cut_force_true_N']:.1f} / {row['mean_cut_force_estimated_N']:.1f} |"
        )
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=ROOT / "data", help="folder of the shipped air cuts X_A...X_D")
    parser.add_argument("--axis-config", type=Path, default=ROOT / "examples" / "axis_x.toml")
    parser.add_argument("--seed", type=int, default=7, help="seed of the cutting logs (the shipped data use 2024)")
    parser.add_argument("--models", default=",".join(KINDS), help="comma-separated model kinds")
    parser.add_argument("--chunk-s", type=float, default=60.0, help="chunk length of the prediction [s]")
    parser.add_argument("--markdown", type=Path, help="write the table here")
    parser.add_argument("--json", type=Path, help="write all figures here")
    parser.add_argument("--plot-dir", type=Path, help="write one picture per model and test log here")
    args = parser.parse_args(argv)

    kinds = [k.strip() for k in args.models.split(",") if k.strip()]
    unknown = sorted(set(kinds) - set(MODEL_CLASSES))
    if unknown:
        parser.error(f"unknown model kind(s) {unknown}; known: {sorted(MODEL_CLASSES)}")
    config = read_axis_config(args.axis_config)
    train = prepare([read_log(args.data / name) for name in TRAIN_FILES])
    tests = {}
    for dataset in TEST_DATASETS:
        cut, air = prepare([make_dataset("X", dataset, seed=args.seed, cutting=True),
                            make_dataset("X", dataset, seed=args.seed)])
        shipped = prepare([read_log(args.data / f"X_{dataset}.mcap")])[0]
        tests[f"X_{dataset} seed {args.seed}"] = (dataset, cut, air, shipped)
    print(f"training on {', '.join(TRAIN_FILES)} ({sum(len(r) for r in train)} samples); "
          f"force constant {force_constant_N_per_A(config):.1f} N/A from {args.axis_config.name}", flush=True)

    rows = []
    for kind in kinds:
        started = time.perf_counter()
        model = MODEL_CLASSES[kind]().fit(train)
        fit_s = time.perf_counter() - started
        for name, (dataset, cut, air, shipped) in tests.items():
            started = time.perf_counter()
            metrics, result = recovery(model, cut, air, config, args.chunk_s)
            predict_s = time.perf_counter() - started
            air_test = rmse(shipped.current, predict_chunked(model, shipped, chunk_s=args.chunk_s))
            row = {"model": kind, "test": name, "fit_s": fit_s, "predict_s": predict_s,
                   "air_test_rmse_A": air_test, **metrics}
            rows.append(row)
            print(f"{kind:<9} {name:<14} fit {fit_s:6.1f} s  air-cut test RMSE {air_test:.4f} A  "
                  f"process RMSE {row['process_rmse_A']:.4f} A  r = {row['correlation']:.3f} "
                  f"(ceiling {row['correlation_ceiling']:.3f})  cut force {row['mean_cut_force_true_N']:.0f} / "
                  f"{row['mean_cut_force_estimated_N']:.0f} N  |process error - air residual| <= "
                  f"{row['air_identity_A'] * 1e3:.2f} mA", flush=True)
            if args.plot_dir:
                from greybox.evaluate.process_plot import plot_process

                args.plot_dir.mkdir(parents=True, exist_ok=True)
                plot_process(result, args.plot_dir / f"predict_{kind}_X_{dataset}.png")

    table = markdown_table(rows)
    print()
    print(table, end="")
    print("noise floor rms(truth_noise_A): " + ", ".join(
        f"{name} {np.sqrt(np.mean(cut.extras['truth_noise_A'] ** 2)):.4f} A" for name, (_, cut, _, _) in tests.items()))
    if args.markdown:
        _atomic_text(args.markdown, table)
    if args.json:
        _atomic_text(args.json, json.dumps({"seed": args.seed, "train": list(TRAIN_FILES),
                                            "axis_config": str(args.axis_config), "rows": rows}, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
