"""The block size of the backlash width search on the development sets (``greybox.identify.coarse``).

For each set of training runs, the pre-sliding deflection ``delta`` [mm], the travel per sample at the 99th
percentile of ``|v|`` (``v99 T`` [mm]) and the block size ``m`` of :func:`greybox.identify.coarse.coarse_block`:
the twin's X_A + X_B (read as ``greybox train`` reads them), the three ``axis_dev`` air cuts, the three
0.25 Hz ARTS tests (read as ``benchmarks/bench_auto_arts.py`` reads them) and the ARTS lead fold of
``--model auto`` (test1 + test6). It computes, it fits nothing: a few seconds.

The record ``coarse-block`` (``python scripts/record.py coarse-block``) runs it; docs/defaults.md renders it.

Usage::

    python benchmarks/bench_coarse_block.py          # a line per set
    python benchmarks/bench_coarse_block.py --json   # one JSON line
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from greybox.identify.coarse import SAMPLES_PER_DEFLECTION, coarse_block  # noqa: E402
from greybox.identify.initial import presliding_deflection, static_initial_guess  # noqa: E402
from greybox.train.logs import read_training_logs  # noqa: E402
from studies.arts import benchmark_log  # noqa: E402

SHARED = ROOT.parent / "shared" / "data"
ARTS = SHARED / "real" / "ARTS_friction_damper"
AXIS_DEV = SHARED / "independent" / "axis_dev"

#: The development sets: name -> how their runs are read.
SETS = {
    "twin X_A + X_B (500 Hz)": lambda: read_training_logs([ROOT / "data" / "X_A.mcap", ROOT / "data" / "X_B.mcap"])[0],
    "`axis_dev` air cuts A, B, C (500 Hz)": lambda: read_training_logs(
        [AXIS_DEV / f"aircut_{name}.csv" for name in "ABC"])[0],
    "ARTS test1 + test6 + test10 (1024 Hz)": lambda: [benchmark_log(ARTS / f"test{k}.npy") for k in (1, 6, 10)],
    "ARTS lead fold, test1 + test6 (1024 Hz)": lambda: [benchmark_log(ARTS / f"test{k}.npy") for k in (1, 6)],
}


def measure() -> dict:
    """``delta``, ``v99 T`` and ``m`` of every development set in order, JSON-ready."""
    sets = []
    for name, read in SETS.items():
        runs = read()
        delta = presliding_deflection(runs, static_initial_guess(runs, fit_offset=True))
        v99 = float(np.percentile(np.abs(np.concatenate([run.velocity for run in runs])), 99))
        step = max(run.sample_time for run in runs)
        sets.append({"set": name, "runs": len(runs), "samples": int(sum(len(run) for run in runs)),
                      "delta_mm": None if delta is None else float(delta), "v99_mm_s": v99, "sample_time_s": step,
                      "travel_per_sample_mm": v99 * step, "m": coarse_block(runs)})
    return {"samples_per_deflection": SAMPLES_PER_DEFLECTION, "sets": sets}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print one JSON line")
    args = parser.parse_args(argv)
    result = measure()
    if args.json:
        print(json.dumps(result))
        return 0
    for row in result["sets"]:
        print(f"{row['set']}: delta {row['delta_mm']} mm, v99 T {row['travel_per_sample_mm']:.4g} mm, m = {row['m']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
