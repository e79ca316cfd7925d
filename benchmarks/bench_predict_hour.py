"""GMS+SVR against GMS alone on a one-hour log: prediction, kernel sums and training, in one run.

Usage::

    python benchmarks/bench_predict_hour.py [--json] [--duration 3600] [--out DIR]

Steps, all on this machine in one run (its cores stated; ratios carry over, absolutes do not):

1. a one-hour 500 Hz cutting log of the twin's X axis (dataset A, seed 21), written as MCAP and as Parquet;
   reading each with :func:`greybox.data.read_log` [samples/s, median of 5 reads], and the MCAP file
   again with its JSON parsed by pyarrow's general reader (greybox's reader before the compiled one);
2. GMS and GMS+SVR trained as ``greybox train --model gms|gmssvr`` trains them (with an offset) on the
   shipped ``data/X_A`` + ``X_B``:
   the GMS stage's time, the SVR stage's time and the ratio of the whole GMS+SVR training to the GMS stage;
   then the GMS+SVR training again with the kernel sums of the code before this benchmark was written
   (every support vector for every sample, one matrix product per block, :func:`dense_expansion` below),
   with its time and the test RE of both on ``data/X_C``;
3. ``greybox predict MODEL LOG --out OUT.parquet`` in a fresh process for each model and each log format
   (both read, predicted and written block by block): wall time and peak resident memory (``VmHWM`` of
   that process), and the ratio GMS+SVR / GMS;
4. the same GMS+SVR prediction on a Parquet log ``--long`` times as long: its peak memory against the hour's;
5. the kernel sums of the hour's SVR inputs by :func:`greybox.models.kernel.rbf.rbf_expansion` (1 and all
   threads) and by :func:`dense_expansion`, with the largest difference.
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
from unittest import mock

import numpy as np

from greybox.data import mcap_io
from greybox.data.io import read_log, write_log
from greybox.data.prepare import prepare
from greybox.metrics import relative_error
from greybox.models.files import save_model
from greybox.models.friction.gms import GMSModel
from greybox.models.gmssvr import GMSSVRModel
from greybox.models.kernel import expansion as kernel_engine
from greybox.models.kernel.rbf import rbf_expansion
from greybox.twin import make_dataset

DATA = Path(__file__).resolve().parents[1] / "data"


def dense_expansion(X, support_vectors, dual_coef, intercept=0.0, gamma=1.0, *, chunk_elements=1 << 16):
    """The kernel sums as greybox computed them before the compiled kernel: all terms, matrix products.

    Kept here as the baseline of this benchmark only.
    """
    X = np.asarray(X, dtype=np.float64)
    sv = np.asarray(support_vectors, dtype=np.float64)
    alpha = np.asarray(dual_coef, dtype=np.float64).ravel()
    n_samples, n_features = X.shape
    out = np.full(n_samples, float(intercept))
    if not sv.shape[0] or not n_samples:
        return out
    centre = sv.mean(axis=0)
    sv_c = sv - centre
    right = np.empty((sv.shape[0], n_features + 2))
    right[:, :n_features] = (2.0 * gamma) * sv_c
    right[:, n_features] = 1.0
    right[:, n_features + 1] = -gamma * np.einsum("ij,ij->i", sv_c, sv_c)
    right_t = np.ascontiguousarray(right.T)
    rows = max(1, chunk_elements // sv.shape[0])
    left = np.empty((min(rows, n_samples), n_features + 2))
    left[:, n_features + 1] = 1.0
    for start in range(0, n_samples, rows):
        stop = min(start + rows, n_samples)
        m = stop - start
        x_c = left[:m, :n_features]
        np.subtract(X[start:stop], centre, out=x_c)
        left[:m, n_features] = -gamma * np.einsum("ij,ij->i", x_c, x_c)
        k = np.minimum(left[:m] @ right_t, 0.0)
        out[start:stop] += np.exp(k) @ alpha
    return out


def timed(function, *args, **kwargs):
    """``(result, seconds)`` of one call."""
    started = time.perf_counter()
    result = function(*args, **kwargs)
    return result, time.perf_counter() - started


def read_rates(root: Path, duration_s: float, reads: int = 5) -> dict:
    """Write the hour as MCAP and Parquet; samples per second read whole by :func:`read_log` (median of ``reads``).

    The MCAP file is also read with its messages parsed by the general JSON reader (pyarrow), as greybox read
    them before the compiled parser (:mod:`greybox.data.json_numbers`).
    """
    log = make_dataset("X", "A", 21, duration_s=duration_s, cutting=True)
    rates = {}
    for suffix in ("mcap", "parquet"):
        path = root / f"hour.{suffix}"
        write_log(log, path)
        rates[suffix] = _read_rate(path, reads)
    with mock.patch.object(mcap_io, "parse_flat_objects", lambda *args, **kwargs: None):
        rates["mcap, general JSON reader"] = _read_rate(root / "hour.mcap", reads)
    return rates


def _read_rate(path: Path, reads: int) -> dict:
    read_log(path)  # imports and compiled readers warm
    seconds = []
    for _ in range(reads):
        read, elapsed = timed(read_log, path)
        seconds.append(elapsed)
    median = float(np.median(seconds))
    return {"samples": len(read), "seconds": median, "min_s": min(seconds), "max_s": max(seconds),
            "samples_per_s": len(read) / median}


def _readme_gms() -> GMSModel:
    """The GMS of ``greybox train --model gms`` (and the GMS stage of ``--model gmssvr``): with an offset."""
    return GMSModel(fit_offset=True)


def train(root: Path) -> dict:
    """GMS and GMS+SVR with their defaults on X_A + X_B, then GMS+SVR again with the former kernel sums."""
    runs = prepare([read_log(DATA / "X_A.mcap"), read_log(DATA / "X_B.mcap")])
    (test,) = prepare([read_log(DATA / "X_C.mcap")])
    gms, gms_s = timed(_readme_gms().fit, runs)
    model = GMSSVRModel(gms=_readme_gms())
    _, stage1_s = timed(model.fit_gms, runs)
    _, stage2_s = timed(model.fit_svr, runs)
    save_model(gms, root / "gms.gbm")
    save_model(model, root / "gmssvr.gbm")
    former = GMSSVRModel(gms=_readme_gms())
    former.fit_gms(runs)
    with mock.patch.object(kernel_engine, "rbf_expansion", dense_expansion):  # the search's held-out sums
        _, former_stage2_s = timed(former.fit_svr, runs)
    return {
        "gms_fit_s": gms_s, "gmssvr_gms_stage_s": stage1_s, "gmssvr_svr_stage_s": stage2_s,
        "gmssvr_over_gms_stage": (stage1_s + stage2_s) / stage1_s,
        "former_svr_stage_s": former_stage2_s, "svr_stage_speedup": former_stage2_s / stage2_s,
        "n_support": int(model.dual_coef_.size),
        "test_re_percent": relative_error(test.effort, model.predict(test)),
        "former_test_re_percent": relative_error(test.effort, former.predict(test)),
    }


#: Runs ``greybox`` in the child and writes its peak resident memory [kB] (``VmHWM``, Linux) to argv[1] at exit;
#: the ``ru_maxrss`` of a child counts the memory of the parent it was forked from.
_CHILD = r"""
import runpy, sys
report = sys.argv.pop(1)
try:
    runpy.run_module("greybox", run_name="__main__", alter_sys=True)
finally:
    with open("/proc/self/status") as status:
        peak = next(int(line.split()[1]) for line in status if line.startswith("VmHWM:"))
    with open(report, "w") as stream:
        stream.write(str(peak))
"""


def predict_cli(model: Path, log: Path, out: Path) -> dict:
    """``greybox predict MODEL LOG --out OUT --quiet`` in a fresh process: wall time and peak memory."""
    out.unlink(missing_ok=True)
    report = out.with_suffix(".peak")
    started = time.perf_counter()
    status = subprocess.run([sys.executable, "-c", _CHILD, str(report), "predict", str(model), str(log), "--out",
                             str(out), "--quiet"], stdout=subprocess.DEVNULL).returncode
    seconds = time.perf_counter() - started
    if status:
        raise SystemExit(f"greybox predict {model.name} {log.name} failed with status {status}")
    return {"seconds": seconds, "peak_rss_mb": int(report.read_text()) / 1024}


def kernel_sums(root: Path) -> dict:
    """The hour's SVR inputs summed by the compiled kernel (1 and all threads) and by the former code."""
    from greybox.models.files import load_model

    model = load_model(root / "gmssvr.gbm")
    (log,) = prepare([read_log(root / "hour.parquet")])
    X, _ = model._inputs_chunk(log, model.region_state(), log.sample_time)
    scaled = (X - model.input_mean_) / model.input_scale_
    args = (scaled, model.support_vectors_, model.dual_coef_, model.intercept_, model.gamma_)
    rbf_expansion(*(a[:1000] if i == 0 else a for i, a in enumerate(args)))  # compile
    one, one_s = timed(rbf_expansion, *args, threads=1)
    threaded, threaded_s = timed(rbf_expansion, *args)
    former, former_s = timed(dense_expansion, *args)
    return {"samples": len(scaled), "n_support": int(model.dual_coef_.size), "former_s": former_s,
            "compiled_1_thread_s": one_s, "compiled_threads_s": threaded_s,
            "speedup_1_thread": former_s / one_s, "speedup_threads": former_s / threaded_s,
            "max_abs_difference_A": float(max(np.max(np.abs(one - former)), np.max(np.abs(threaded - former))))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=3600.0, help="length of the predicted log [s]")
    parser.add_argument("--out", help="keep the log, models and outputs in this directory (default: temporary)")
    parser.add_argument("--long", type=float, default=3.0, help="length of the long log, in --duration (default 3)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args()
    root = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="bench_predict_"))
    root.mkdir(parents=True, exist_ok=True)
    try:
        reading = read_rates(root, args.duration)
        training = train(root)
        predicting = {fmt: {kind: predict_cli(root / f"{kind}.gbm", root / f"hour.{fmt}", root / f"{kind}.parquet")
                            for kind in ("gms", "gmssvr")} for fmt in ("mcap", "parquet")}
        for runs in predicting.values():
            runs["ratio"] = runs["gmssvr"]["seconds"] / runs["gms"]["seconds"]
        write_log(make_dataset("X", "A", 22, duration_s=args.long * args.duration, cutting=True), root / "long.parquet")
        longer = predict_cli(root / "gmssvr.gbm", root / "long.parquet", root / "long_out.parquet")
        longer["memory_ratio"] = longer["peak_rss_mb"] / predicting["parquet"]["gmssvr"]["peak_rss_mb"]
        kernel = kernel_sums(root)
    finally:
        if not args.out:
            shutil.rmtree(root, ignore_errors=True)
    result = {"cores": len(os.sched_getaffinity(0)), "duration_s": args.duration, "read": reading,
              "train": training, "predict": predicting, "long": longer, "kernel": kernel}
    if args.json:
        print(json.dumps(result))
        return
    print(f"one log of {args.duration:g} s, {result['cores']} cores")
    for fmt, rate in reading.items():
        print(f"  read {fmt}: {rate['samples']} samples in {rate['seconds']:.2f} s (median; "
              f"{rate['min_s']:.2f}-{rate['max_s']:.2f} s), {rate['samples_per_s'] / 1e6:.2f} M samples/s")
    t = training
    print(f"  train GMS {t['gms_fit_s']:.1f} s; GMS+SVR: GMS stage {t['gmssvr_gms_stage_s']:.1f} s + SVR stage "
          f"{t['gmssvr_svr_stage_s']:.1f} s = {t['gmssvr_over_gms_stage']:.2f}x the GMS stage "
          f"({t['n_support']} support vectors); SVR stage with the former kernel sums {t['former_svr_stage_s']:.1f} s "
          f"({t['svr_stage_speedup']:.2f}x); test RE on X_C {t['test_re_percent']:.2f} % "
          f"(former {t['former_test_re_percent']:.2f} %)")
    for fmt, runs in predicting.items():
        for kind in ("gms", "gmssvr"):
            p = runs[kind]
            print(f"  greybox predict {kind}, {fmt} -> Parquet: {p['seconds']:.2f} s wall, "
                  f"peak {p['peak_rss_mb']:.0f} MB")
        print(f"  ratio GMS+SVR / GMS ({fmt}): {runs['ratio']:.2f}")
    print(f"  greybox predict gmssvr, Parquet {args.long:g}x as long: {longer['seconds']:.2f} s wall, peak "
          f"{longer['peak_rss_mb']:.0f} MB ({longer['memory_ratio']:.2f}x the hour's)")
    k = kernel
    print(f"  kernel sums, {k['samples']} samples x {k['n_support']} support vectors: former {k['former_s']:.2f} s, "
          f"compiled {k['compiled_1_thread_s']:.2f} s on 1 thread ({k['speedup_1_thread']:.2f}x), "
          f"{k['compiled_threads_s']:.2f} s on all ({k['speedup_threads']:.2f}x); largest difference "
          f"{k['max_abs_difference_A']:.2g} A")


if __name__ == "__main__":
    main()
