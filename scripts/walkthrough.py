"""The walk-through of docs/usage.md and docs/predict.md, run as a reader would run it.

Trains the walk-through's GMS+SVR model on the shipped air cuts X_A and X_B, makes the synthetic cutting log
(trajectory D, seed 7), predicts it with the axis file, once more with an air run of D (seed 8) as calibration,
predicts it with a Stribeck model trained on X_A alone and scores a Coulomb model trained on X_A alone on X_D
(the training-region notes). Every command runs with
the greybox of this Python in a temporary folder holding links to ``data/`` and ``examples/``, so what it
prints names the files as the pages do. Prints the console output of each command and the figures the pages
quote, as one JSON object last (the record ``walkthrough`` of ``scripts/record.py``).

Usage::

    python scripts/walkthrough.py [--figures docs/figures]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from greybox.atomic import write_bytes_atomic
from greybox.data import read_log
from studies.as_printed import reader_folder, run_greybox

#: The rows of the process table the pages show [s].
TABLE_TIMES_S = (0.0, 10.0, 20.0)
#: The stretch of the outbound stroke inside the cut whose mean the pages quote [s].
CUT_STRETCH_S = (6.0, 20.0)
#: After this time the log is an air cut (the return stroke) [s].
AIR_AFTER_S = 28.0


def walkthrough(folder: Path) -> dict:
    """Run the walk-through in ``folder`` (:func:`studies.as_printed.reader_folder`); the lines and figures quoted."""
    run_greybox(folder, "train", "--model", "gmssvr", "--train", "data/X_A.mcap", "data/X_B.mcap",
             "--out", "x_gmssvr.gbm")
    run_greybox(folder, "synth", "--axis", "X", "--datasets", "D", "--cutting", "--seed", "7", "--out", "cutting")
    predict = run_greybox(folder, "predict", "x_gmssvr.gbm", "cutting/X_D.mcap", "--out", "process.csv",
                       "--axis-config", "examples/axis_x.toml", "--plot", "process.png")
    run_greybox(folder, "synth", "--axis", "X", "--datasets", "D", "--seed", "8", "--out", "aircut")
    interval = run_greybox(folder, "predict", "x_gmssvr.gbm", "cutting/X_D.mcap", "--out", "interval.csv",
                        "--axis-config", "examples/axis_x.toml", "--calibration", "aircut/X_D.mcap",
                        "--plot", "interval.png")
    run_greybox(folder, "train", "--model", "stribeck", "--train", "data/X_A.mcap", "--out", "s_a.gbm")
    stribeck = run_greybox(folder, "predict", "s_a.gbm", "cutting/X_D.mcap", "--out", "pe.csv")
    run_greybox(folder, "train", "--model", "coulomb", "--train", "data/X_A.mcap", "--out", "c.gbm")
    evaluate = run_greybox(folder, "evaluate", "c.gbm", "--test", "data/X_D.mcap")

    table = pd.read_csv(folder / "process.csv")
    shown = table[table["time_s"].isin(TABLE_TIMES_S)]
    truth = read_log(folder / "cutting" / "X_D.mcap")
    t = table["time_s"].to_numpy()
    stretch = (t >= CUT_STRETCH_S[0]) & (t <= CUT_STRETCH_S[1])
    truth_stretch = (truth.time >= CUT_STRETCH_S[0]) & (truth.time <= CUT_STRETCH_S[1])
    return {
        "predict_lines": predict,
        "table_text": shown.to_string(index=False),
        "row_at_10_s": {key: float(value) for key, value in shown[shown["time_s"] == 10.0].iloc[0].items()},
        "cut_stretch_s": list(CUT_STRETCH_S),
        "cut_mean_current_A": float(np.mean(table["current_process_A"].to_numpy()[stretch])),
        "cut_mean_force_N": float(np.mean(table["force_process_N"].to_numpy()[stretch])),
        "cut_true_force_N": float(np.mean(truth.extras["truth_process_force_N"][truth_stretch])),
        "air_after_s": AIR_AFTER_S,
        "air_process_std_A": float(np.std(table["current_process_A"].to_numpy()[t > AIR_AFTER_S])),
        "noise_rms_A": float(np.sqrt(np.mean(truth.extras["truth_noise_A"] ** 2))),
        "interval_lines": [line for line in interval if line.lstrip().startswith("interval")],
        "evaluate_lines": evaluate,
        "outside_lines": [line for line in stribeck
                          if line.startswith("note:") or line.lstrip().startswith("outside the training region")],
        "outside_gmssvr": next(line.strip() for line in predict
                               if line.lstrip().startswith("outside the training region")),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figures", type=Path, help="copy the two pictures here as predict-gmssvr-X_D.png and "
                        "predict-interval-X_D.png (the pages' figures)")
    args = parser.parse_args(argv)
    with reader_folder("greybox-walkthrough-") as folder:
        figures = walkthrough(folder)
        if args.figures:
            for made, name in (("process.png", "predict-gmssvr-X_D.png"), ("interval.png", "predict-interval-X_D.png")):
                write_bytes_atomic(args.figures / name, (folder / made).read_bytes())
    for key in ("predict_lines", "interval_lines", "outside_lines", "evaluate_lines"):
        print("\n".join(figures[key]))
    print(figures["table_text"])
    print(json.dumps(figures, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
