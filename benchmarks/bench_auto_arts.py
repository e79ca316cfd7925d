"""``--model auto`` on the ARTS harmonic tests, and its choice on the fastest held-out test (docs/model-choice.md).

The ARTS harmonic row of the table "The choice against ``coulomb:offset`` on the fastest held-out run": the
model ``--model auto`` chooses (:func:`greybox.train.candidates.choose_model`, in this process: ``greybox``
reads no ``.npy`` file) on the three 0.25 Hz tests ``test1``, ``test6``, ``test10`` (the split of
docs/arts-benchmark.md: zero acceleration, ``J = 0`` as ``--load-side``), and ``coulomb:offset`` fitted on the
same files, both scored on the fastest of the ten other files (highest 99th percentile of ``|v|``), beside
that file's floor (the RE of its force above 20 Hz, :func:`studies.arts.band_split`: what no model of the
motion predicts) and ``coulomb:offset``'s standard error over the folds (None when it was raced out).

The record ``auto-arts`` (``python scripts/record.py auto-arts``) runs it; run it alone under ``nice -n 10``
and give the load beside its time (docs/defaults.md says what keeps the width search of a GMS behind a backlash
short). The data folder is ``$GREYBOX_REAL_DATA/ARTS_friction_damper``, else
``../shared/data/real/ARTS_friction_damper``.

Usage::

    python benchmarks/bench_auto_arts.py            # a line per fold fit, then the result
    python benchmarks/bench_auto_arts.py --json     # one JSON line
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # studies/ is beside greybox/, not installed

from greybox.metrics import relative_error  # noqa: E402
from greybox.train.candidates import build_candidate, choose_model  # noqa: E402
from studies.arts import band_split, benchmark_log  # noqa: E402

#: The folder of the ARTS files.
DATA = Path(os.environ.get("GREYBOX_REAL_DATA") or ROOT.parent / "shared" / "data" / "real") / "ARTS_friction_damper"
#: The training files: the 0.25 Hz test of each amplitude (docs/arts-benchmark.md).
TRAIN = ("test1.npy", "test6.npy", "test10.npy")


def measure(workers: int | None = None, progress=None) -> dict:
    """Choose by ``--model auto`` on :data:`TRAIN`, fit ``coulomb:offset``, score both on the fastest other file.

    Parameters
    ----------
    workers : int, optional
        Processes fitting the candidates (default one per core).
    progress : callable, optional
        Called with one line per finished fold fit.

    Returns
    -------
    dict
        ``auto_seconds`` (wall time of the choice and its refit) [s], ``cores``, ``workers``, ``chosen``,
        ``folds``, ``notes``, ``candidates`` (label -> ``fold_re`` [%], ``error``), ``fastest`` (file stem),
        ``fastest_speed`` (its 99th percentile of ``|v|``) [mm/s], ``fastest_re`` (``auto``,
        ``coulomb_offset``, ``coulomb_offset_se``, ``floor``) [%].
    """
    workers = workers or os.cpu_count() or 1
    runs = [benchmark_log(DATA / name) for name in TRAIN]
    others = sorted(path for path in DATA.glob("test*.npy") if path.name not in TRAIN)
    speeds = {path: float(np.percentile(np.abs(benchmark_log(path).velocity), 99)) for path in others}
    fastest = max(speeds, key=speeds.get)
    started = time.perf_counter()
    chosen = choose_model(runs, [run.source for run in runs], inertia=0.0, workers=workers, progress=progress)
    seconds = time.perf_counter() - started
    coulomb = build_candidate("coulomb:offset", inertia=0.0).fit(runs)
    test = benchmark_log(fastest)
    predicted = chosen.predict(test)
    selection = chosen.selection_
    reference = next(c for c in selection["candidates"] if c["label"] == "coulomb:offset")
    return {"auto_seconds": seconds, "cores": os.cpu_count(), "workers": workers, "chosen": selection["chosen"],
            "folds": selection["folds"], "notes": selection["notes"],
            "candidates": {c["label"]: {"fold_re": c["fold_re"], "error": c["error"]} for c in selection["candidates"]},
            "fastest": fastest.stem, "fastest_speed": speeds[fastest],
            "fastest_re": {"auto": relative_error(test.effort, predicted),
                           "coulomb_offset": relative_error(test.effort, coulomb.predict(test)),
                           "coulomb_offset_se": reference["re_se"],
                           "floor": band_split([test], [predicted])["floor"]}}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, help="processes fitting the candidates (default one per core)")
    parser.add_argument("--json", action="store_true", help="print one JSON line")
    args = parser.parse_args(argv)
    result = measure(args.workers, progress=None if args.json else print)
    if args.json:
        print(json.dumps(result))
        return 0
    re = result["fastest_re"]
    print(f"chose {result['chosen']} in {result['auto_seconds']:.0f} s; on {result['fastest']}: chosen RE "
          f"{re['auto']:.2f} %, coulomb:offset {re['coulomb_offset']:.2f} %, floor {re['floor']:.2f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
