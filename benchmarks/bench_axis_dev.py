"""Issue 40's ``axis_dev`` targets on the independent development split, each step a ``greybox`` process.

``--part force`` (the record ``axis-dev``):

1. ``greybox train --model gmssvr --train aircut_A.csv aircut_B.csv aircut_C.csv`` (the docs' recommended
   training; its wall and CPU time [s]), then ``greybox predict MODEL cut_D.csv --axis-config axis.toml``: the
   mean predicted process force over the samples where ``cut_D_truth.csv``'s ``F_cut_true_N != 0`` against the
   truth's mean there [N], and their difference in % of the truth (target: within 1 %);
2. ``greybox train --model gms --train aircut_X.csv`` for each air cut alone, then ``greybox evaluate`` on all
   three: the RMSE on each other air cut over the RMSE on its own [-] (target: at most 3), or the one line a
   refused fit printed.

``--part speed`` (the record ``axis-dev-speed``): the carry to speed. ``greybox train --model auto`` on the two
slower air cuts (A and C, 99th percentile of ``|v|`` about 40 mm/s) and ``greybox train --model coulomb`` on the
same, both evaluated on the fastest, ``aircut_B`` (about 100 mm/s): their RE [%] there
(target: the choice no worse than ``coulomb:offset``; the noise floor is None: the files hold no noise-free
current); and the cut force of the choice on ``cut_D``, as in 1.

The data lie beside the repository (``../shared/data/independent/axis_dev``). Run it alone or under ``nice`` and
give the load beside the times.

Usage::

    python benchmarks/bench_axis_dev.py --part force --json
    python benchmarks/bench_axis_dev.py --part speed --json
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data" / "independent" / "axis_dev"
AIR_CUTS = ("aircut_A", "aircut_B", "aircut_C")
#: The air cut held out to test the carry to speed (the fastest), and the two slower ones trained on.
FASTEST = "aircut_B"
SLOWER = ("aircut_A", "aircut_C")


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _greybox(*args: str, check: bool = True) -> tuple[float, float, subprocess.CompletedProcess]:
    """Run ``greybox ARGS`` from the repository's root: wall time, CPU time (workers included) [s], the process."""
    cpu, started = _children_cpu(), time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "greybox", *args], cwd=ROOT, capture_output=True, text=True)
    if check and done.returncode != 0:
        raise RuntimeError(f"greybox {' '.join(args)} exited with status {done.returncode}: {done.stderr.strip()}")
    return time.perf_counter() - started, _children_cpu() - cpu, done


def _csv(name: str) -> str:
    return str(DATA / f"{name}.csv")


def cut_force(model: Path, directory: Path) -> dict:
    """Mean predicted process force on ``cut_D`` where the truth's cutting force is not zero, against the truth.

    Returns ``predicted_N``, ``truth_N``, ``error_percent`` (100 (predicted - truth) / truth) and ``samples``.
    """
    out = directory / f"{model.stem}_cut.csv"
    _greybox("predict", str(model), _csv("cut_D"), "--axis-config", str(DATA / "axis.toml"), "--out", str(out))
    predicted = pd.read_csv(out)["force_process_N"].to_numpy()
    truth = pd.read_csv(DATA / "cut_D_truth.csv")["F_cut_true_N"].to_numpy()
    if predicted.size != truth.size:
        raise RuntimeError(f"{out}: {predicted.size} samples predicted for {truth.size} of the truth")
    cutting = truth != 0.0
    mean_predicted, mean_truth = float(predicted[cutting].mean()), float(truth[cutting].mean())
    return {"predicted_N": mean_predicted, "truth_N": mean_truth, "samples": int(cutting.sum()),
            "error_percent": 100.0 * (mean_predicted - mean_truth) / mean_truth}


def _per_log(metrics: Path) -> dict[str, dict]:
    """``{model: {air cut: {"rmse", "re"}}}`` of a ``greybox evaluate --json`` file."""
    out = {}
    for entry in json.loads(metrics.read_text()):
        logs = {}
        for name, part in entry["per_log"].items():
            stem = next(cut for cut in (*AIR_CUTS, "cut_D") if cut in name)
            logs[stem] = {"rmse": part["rmse"], "re": part["re"]}
        out[entry["model"]] = {"logs": logs, "re": entry["re"], "rmse": entry["rmse"]}
    return out


def single_air_cut(name: str, directory: Path) -> dict:
    """A GMS fitted on one air cut alone: its RMSE on each air cut [A] and the others' over its own, or the refusal."""
    model = directory / f"gms_{name}.gbm"
    seconds, cpu, done = _greybox("train", "--model", "gms", "--train", _csv(name), "--out", str(model), "--quiet",
                                  check=False)
    if done.returncode != 0:
        lines = [line for line in done.stderr.splitlines() if line.strip()]
        return {"trained_on": name, "seconds": seconds, "cpu_seconds": cpu, "status": done.returncode,
                "refused": lines[-1] if lines else ""}
    metrics = directory / f"gms_{name}.json"
    _greybox("evaluate", str(model), "--test", *(_csv(cut) for cut in AIR_CUTS), "--json", str(metrics))
    logs = _per_log(metrics)[model.stem]["logs"]
    own = logs[name]["rmse"]
    return {"trained_on": name, "seconds": seconds, "cpu_seconds": cpu, "status": 0, "refused": None,
            "rmse": {cut: logs[cut]["rmse"] for cut in AIR_CUTS},
            "ratio": {cut: logs[cut]["rmse"] / own for cut in AIR_CUTS if cut != name}}


def measure_force() -> dict:
    """Part ``force``: the recommended training's cut force and the three single-air-cut GMS fits."""
    with tempfile.TemporaryDirectory() as folder:
        directory = Path(folder)
        model = directory / "gmssvr.gbm"
        seconds, cpu, _ = _greybox("train", "--model", "gmssvr", "--train", *(_csv(cut) for cut in AIR_CUTS),
                                   "--out", str(model), "--quiet")
        force = cut_force(model, directory)
        singles = [single_air_cut(name, directory) for name in AIR_CUTS]
    return {"cores": os.cpu_count(), "gmssvr": {"seconds": seconds, "cpu_seconds": cpu, "cut_force": force},
            "single": singles}


def measure_speed() -> dict:
    """Part ``speed``: ``--model auto`` and ``coulomb:offset`` on the slower air cuts, scored on the fastest."""
    with tempfile.TemporaryDirectory() as folder:
        directory = Path(folder)
        auto, coulomb, metrics = (directory / name for name in ("auto.gbm", "coulomb.gbm", "metrics.json"))
        seconds, cpu, _ = _greybox("train", "--model", "auto", "--train", *(_csv(cut) for cut in SLOWER),
                                   "--out", str(auto), "--quiet")
        _greybox("train", "--model", "coulomb", "--train", *(_csv(cut) for cut in SLOWER), "--out", str(coulomb),
                 "--quiet")
        _greybox("evaluate", str(auto), str(coulomb), "--test", _csv(FASTEST), "--json", str(metrics))
        results = _per_log(metrics)
        force = cut_force(auto, directory)
        from greybox.models.files import load_model

        selection = load_model(auto).selection_
    return {"cores": os.cpu_count(), "auto_seconds": seconds, "auto_cpu_seconds": cpu, "trained_on": list(SLOWER),
            "fastest": FASTEST, "chosen": selection["chosen"],
            "candidates": {c["label"]: {"fold_re": c["fold_re"], "error": c["error"]} for c in selection["candidates"]},
            "fastest_re": {"auto": results["auto"]["re"], "coulomb_offset": results["coulomb"]["re"],
                           "noise_floor": results["noise_floor"]["re"] if "noise_floor" in results else None},
            "cut_force": force}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--part", choices=("force", "speed"), required=True,
                        help="force: the recommended training's cut force and the single-air-cut fits; speed: "
                        "--model auto on the slower air cuts against coulomb:offset on the fastest")
    parser.add_argument("--json", action="store_true", help="print one JSON line")
    args = parser.parse_args(argv)
    if not DATA.is_dir():
        print(f"{DATA}: the independent development split is not there", file=sys.stderr)
        return 2
    result = measure_force() if args.part == "force" else measure_speed()
    print(json.dumps(result) if args.json else json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
