"""
Train a friction model on air cuts
==================================

Fit a GMS friction model (four Maxwell-slip elements, the paper's default) and a static Stribeck
curve on the shipped air cut ``X_A`` of the synthetic X axis, then compare both with the measured
current of ``X_C``, an air cut neither model has seen. The command line does the same with::

    greybox train --model gms --train data/X_A.mcap --out x_gms.gbm
    greybox evaluate x_gms.gbm --test data/X_C.mcap

To keep the example short, both models train on the first 40 s of ``X_A`` only.
"""

from pathlib import Path

import matplotlib.pyplot as plt

from greybox.data import prepare, read_log
from greybox.metrics import relative_error, rmse
from greybox.models.friction.gms import GMSModel
from greybox.models.friction.stribeck import StribeckModel

data = Path("../../data")  # the data/ folder of the repository (the gallery runs from docs/examples)

# %%
# Read and prepare the logs
# -------------------------
# ``prepare`` checks the time base and derives velocity and acceleration from the position; each
# file stays a separate run.
(air_cut,) = prepare([read_log(data / "X_A.mcap")])
(test,) = prepare([read_log(data / "X_C.mcap")])
train = air_cut.select(air_cut.time < air_cut.time[0] + 40.0)
print(f"training: {len(train.time)} samples, test: {len(test.time)} samples at {test.sample_time * 1e3:.0f} ms")

# %%
# Fit the two models
# ------------------
# Both are scikit-learn style estimators: settings in the constructor, ``fit`` returns the model.
stribeck = StribeckModel().fit([train])
gms = GMSModel(n_elements=4, random_state=0).fit([train])
for parameter in gms.parameter_table():
    print(f"{parameter.name:>10} = {parameter.value} {parameter.unit}  ({parameter.description})")

# %%
# Test on the unseen air cut
# --------------------------
# RE is the RMSE divided by the mean absolute current, in %.
for name, model in [("Stribeck", stribeck), ("GMS", gms)]:
    predicted = model.predict([test])
    print(f"{name:>8}: RMSE {rmse(test.current, predicted):.3f} A, RE {relative_error(test.current, predicted):.2f} %")

# %%
# Around a few reversals the dynamic model follows the pre-sliding transitions that the static
# curve switches at once.
window = (test.time > 20.0) & (test.time < 24.0)
fig, ax = plt.subplots(figsize=(8, 4))
ax.plot(test.time[window], test.current[window], color="0.6", lw=0.8, label="measured")
ax.plot(test.time[window], stribeck.predict([test])[window], label="Stribeck")
ax.plot(test.time[window], gms.predict([test])[window], label="GMS")
ax.set_xlabel("time [s]")
ax.set_ylabel("motor current [A]")
ax.legend()
fig.tight_layout()
