"""
Predict the cutting force from a cutting log
============================================

A model trained on air cuts predicts the current the drive needs for inertia and friction. Run over a
log recorded while cutting, what is left of the measured current is the share of the process, and
the axis file (torque constant, screw lead, gear ratio, efficiencies) turns it into the force on the
table. The command line does the same with::

    greybox train --model lugre --train data/X_B.mcap --out x_lugre.gbm
    greybox synth --axis X --datasets D --cutting --seed 7 --out cutting
    greybox predict x_lugre.gbm cutting/X_D.mcap --out process.csv --axis-config examples/axis_x.toml

Here the cutting log comes from the synthetic axis (the twin), which also records the true process
force, so the estimate can be checked.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from greybox.data import prepare, read_log
from greybox.data.axis_config import read_axis_config
from greybox.models.friction.lugre import LuGreModel
from greybox.predict.process import predict_process
from greybox.twin import make_dataset

root = Path("../..")  # the repository (the gallery runs from docs/examples)

# %%
# Train on an air cut over the whole travel
# -----------------------------------------
# Dataset B sweeps the travel at constant feeds, so the model has seen every position the cutting
# log visits. The model is the LuGre friction model (one bristle state), quick to fit; ``GMSModel``
# or the grey-box ``GMSSVRModel`` take the same place.
air_cuts = prepare([read_log(root / "data" / "X_B.mcap")])
model = LuGreModel(random_state=0).fit(air_cuts)

# %%
# A cutting log
# -------------
# Trajectory D of the synthetic X axis with a milling load on its outbound stroke (seed 7, the
# default cut of ``greybox synth --cutting``).
(cutting,) = prepare([make_dataset("X", "D", seed=7, cutting=True)])
print(f"{cutting.duration:.1f} s of cutting log, {len(cutting.time)} samples")

# %%
# Process current and force
# -------------------------
axis = read_axis_config(root / "examples" / "axis_x.toml")
print(f"N per A while driving / back-driven: {axis.load_constants[0]:.1f} / {axis.load_constants[1]:.1f}")
result = predict_process(model, cutting, axis_config=axis)
table = result.to_frame()
print(table.iloc[::5000, :6].to_string(index=False))

# %%
# Where the tool cuts, compare the mean estimated force with the truth the twin recorded.
truth = cutting.extras["truth_process_force_N"]
in_cut = np.abs(truth) > 0
print(f"mean process force in the cut: {result.load[in_cut].mean():.1f} N (true {truth[in_cut].mean():.1f} N)")


def moving_mean(values, samples=50):
    """Mean over ``samples`` consecutive samples (0.1 s at 2 ms)."""
    return np.convolve(values, np.ones(samples) / samples, mode="same")


fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(8, 5))
top.plot(result.time, result.measured, color="0.6", lw=0.6, label="measured")
top.plot(result.time, result.model, lw=0.8, label="model (air cut)")
top.set_ylabel("current [A]")
top.legend(loc="upper right")
bottom.plot(result.time, moving_mean(result.load), label="estimated process force, 0.1 s mean")
bottom.plot(result.time, truth, color="k", lw=0.8, label="true process force")
bottom.set_xlabel("time [s]")
bottom.set_ylabel("force [N]")
bottom.legend(loc="lower right")
fig.tight_layout()
