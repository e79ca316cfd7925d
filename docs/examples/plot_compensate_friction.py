"""
Compensate friction in a position loop
======================================

A friction model is only as good as what it does for the machine. Here the synthetic X axis runs
under one PID position loop, tuned once, with a feed-forward of the inertia alone or of the inertia
plus a friction model, and the tracking error tells the models apart. The command line does the
same with::

    greybox compensate --plant twin-X --model stribeck gms --out compensation

To keep the example short the models are fitted on 20 s of the twin's datasets A and P (pre-sliding
excitation) and the loop follows a 10 s low-stroke reference (the command: 60 s each).
"""

from greybox.control import TwinPlant, plot_tracking_errors
from greybox.control.report import comparison_rows
from greybox.control.workflow import compensation_study, twin_training_runs
from greybox.models.friction.gms import GMSModel
from greybox.models.friction.stribeck import StribeckModel

# %%
# The plant and the feed-forward models
# -------------------------------------
plant = TwinPlant.for_axis("X")
runs = twin_training_runs(plant, seed=0, duration_s=20.0)
models = {"stribeck": StribeckModel().fit(runs), "gms": GMSModel(random_state=0).fit(runs)}

# %%
# The loop with each feed-forward
# -------------------------------
study = compensation_study(plant, models, references=("low",), duration_s=10.0, seed=0)
print(f"PID: kp = {study.gains.kp:.4g} A/mm, controller period {study.controller_period_s * 1e3:g} ms")
for row in comparison_rows(study.results):
    name = "inertia only" if row["feedforward"] == "none" else row["feedforward"]
    print(f"{name:>12}: RMS tracking error {row['rms_error_mm'] * 1e3:.3f} um "
          f"({100 * row['rms_vs_none']:.0f} % of inertia only)")

# %%
# The tracking error over time: at each reversal a static friction curve switches its full level at
# once, while the real friction builds up along its pre-sliding curve, which GMS follows.
figure = plot_tracking_errors(study.results, study.results[0].reference.name)
