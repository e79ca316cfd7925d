"""The shapes of the fingerprint features on stable twin axes, which calibrate the change detector.

Usage::

    python scripts/stable_twin_shapes.py [--first-seed 200] [--seeds 30] [--days 393] [--cache DIR]
        [--out greybox/monitor/stable_twin_shapes.json]

Every seed's X axis writes ``--days`` daily air-move logs without drift (the day-to-day spread alone,
:func:`greybox.twin.ageing.aged_log`); each is fingerprinted (:class:`greybox.monitor.fingerprint.FrictionFingerprint`,
20 bootstrap replicates: only the point estimates are kept, which the replicates do not change). Each
feature's series is standardised by its own mean and standard deviation over all its days, the standardised
values of all seeds are pooled per feature, and :data:`N_QUANTILES` quantiles at evenly spaced levels from 0
to 1 (minimum to maximum) are written as JSON: the file :func:`greybox.monitor.detect.calibrated_threshold`
draws stable days from (``shapes="twin"``). Only development seeds (below 1000) are used: the held-out
seeds 2000 and above measure the calibrated detector, see docs/monitor.md. With ``--cache DIR`` each seed's
daily features are kept in (and read back from) ``DIR/stable_<seed>_<days>.npy``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from greybox.atomic import write_text_atomic
from greybox.data.prepare import prepare
from greybox.monitor.fingerprint import FEATURES, FrictionFingerprint
from greybox.twin.ageing import aged_log

#: Quantiles kept per feature (levels 0, 1/(N-1), ..., 1).
N_QUANTILES = 201


def stable_days(seed: int, days: int) -> np.ndarray:
    """Daily features (days x features) of one stable twin axis."""
    rows = []
    for day in range(days):
        fitted = FrictionFingerprint(n_boot=20).fit(prepare(aged_log("X", day, seed, [])))
        rows.append([fitted.values_[name] for name in FEATURES])
    return np.asarray(rows, dtype=float)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--first-seed", type=int, default=200)
    parser.add_argument("--seeds", type=int, default=30)
    parser.add_argument("--days", type=int, default=393)
    parser.add_argument("--cache", type=Path)
    parser.add_argument("--out", type=Path, default=Path("greybox/monitor/stable_twin_shapes.json"))
    args = parser.parse_args()
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    if seeds.stop > 1000:
        parser.error("the shapes come from development seeds (below 1000) only")
    series = []
    for seed in seeds:
        cached = args.cache / f"stable_{seed}_{args.days}.npy" if args.cache else None
        if cached is not None and cached.exists():
            x = np.load(cached, allow_pickle=False)
        else:
            x = stable_days(seed, args.days)
            if cached is not None:
                np.save(cached, x)
        series.append(x)
    x = np.asarray(series)  # seeds x days x features
    z = (x - np.nanmean(x, axis=1, keepdims=True)) / np.nanstd(x, axis=1, ddof=1, keepdims=True)
    levels = np.linspace(0.0, 1.0, N_QUANTILES)
    shapes = {}
    for j, name in enumerate(FEATURES):
        values = z[:, :, j].ravel()
        shapes[name] = [round(float(q), 4) for q in np.quantile(values[np.isfinite(values)], levels)]
    document = {"what": "quantiles of each fingerprint feature's daily values on stable twin axes, standardised "
                        "per axis by the mean and standard deviation of all its days",
                "source": f"scripts/stable_twin_shapes.py --first-seed {seeds.start} --seeds {len(seeds)} "
                          f"--days {args.days}",
                "seeds": [seeds.start, seeds.stop - 1], "days": args.days, "levels": len(levels), "quantiles": shapes}
    write_text_atomic(args.out, json.dumps(document, indent=1) + "\n")
    print(f"{len(seeds)} stable axes x {args.days} days -> {args.out}")
    for j, name in enumerate(FEATURES):
        values = z[:, :, j].ravel()
        values = values[np.isfinite(values)]
        print(f"{name}: skewness {np.mean(values ** 3):+.2f}, share beyond +2.5 sd {np.mean(values > 2.5):.4f}, "
              f"below -2.5 sd {np.mean(values < -2.5):.4f}, lag-1 autocorrelation "
              f"{np.nanmean([np.corrcoef(s[:-1], s[1:])[0, 1] for s in z[:, :, j]]):+.3f}")


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
