"""The change detector's calibrated thresholds and the shapes it calibrates on (docs/monitor.md).

Usage::

    python studies/monitor_calibration.py [--json]

Prints :func:`greybox.monitor.detect.calibrated_threshold` for ten features on the twin's stable shapes
(:func:`greybox.monitor.detect.stable_shapes`, the shipped quantiles): 28 baseline days at 0.5 and 1 false
alarm per axis-year, 14 baseline days at 0.5, and at 1 per axis-year on standard normal days; and per feature
the skewness of the shipped shape and its share beyond +-2.5 standard deviations, both read from the
quantiles (the quantile function integrated over its evenly spaced levels). Then the figures as one JSON
object.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from greybox.monitor.detect import calibrated_threshold, stable_shapes  # noqa: E402
from greybox.monitor.fingerprint import FEATURES  # noqa: E402

#: Tail beyond which the shares are counted [standard deviations].
TAIL_SD = 2.5


def shape_statistics(quantiles: np.ndarray) -> dict:
    """Skewness and tail shares of a shape given by quantiles at evenly spaced levels from 0 to 1."""
    levels = np.linspace(0.0, 1.0, quantiles.size)
    values = 0.5 * (quantiles[1:] + quantiles[:-1])  # the quantile function's mean over each step of level
    standard = (values - values.mean()) / values.std()
    return {"skewness": float(np.mean(standard ** 3)),
            "above_percent": 100.0 * float(1.0 - np.interp(TAIL_SD, quantiles, levels)),
            "below_percent": 100.0 * float(np.interp(-TAIL_SD, quantiles, levels))}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print the figures as one JSON object last")
    args = parser.parse_args(argv)
    shapes = stable_shapes()
    n = len(FEATURES)
    thresholds = {"twin_28_days_0.5": calibrated_threshold(baseline_days=28, n_features=n, shapes=shapes),
                  "twin_28_days_1": calibrated_threshold(baseline_days=28, n_features=n, shapes=shapes,
                                                         false_alarms_per_year=1.0),
                  "twin_14_days_0.5": calibrated_threshold(baseline_days=14, n_features=n, shapes=shapes),
                  "normal_28_days_1": calibrated_threshold(baseline_days=28, n_features=n,
                                                           false_alarms_per_year=1.0)}
    statistics = {name: shape_statistics(row) for name, row in zip(FEATURES, shapes)}
    for name, value in thresholds.items():
        print(f"h {name}: {value:.2f}")
    for name, stats in statistics.items():
        print(f"{name}: skewness {stats['skewness']:+.2f}, beyond +{TAIL_SD} sd {stats['above_percent']:.2f} %, "
              f"beyond -{TAIL_SD} sd {stats['below_percent']:.2f} %")
    if args.json:
        print(json.dumps({"thresholds": thresholds, "tail_sd": TAIL_SD, "shapes": statistics}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
