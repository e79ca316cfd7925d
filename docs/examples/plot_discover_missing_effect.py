"""
Discover a missing effect
=========================

A friction model that misses an effect leaves a residual with structure. ``discover`` looks for it
among a library of named effects, names one only if it beats a simulated null and lowers the error on
held-out blocks of the training time, adds it to the model and shows how much of the gap it closes on
a test log. The command line does the same with::

    greybox discover --model coulomb --train X_A.mcap --test X_C.mcap --json report.json

Here the synthetic axis hides an effect on purpose: a force that ripples with the position
(``position_periodic_force``, e.g. motor cogging), which a Coulomb + viscous base cannot represent. To keep
the example short the logs are 40 s long, the base is the Coulomb model, and each step draws 19 null
replicates (the command's default is 99).
"""

import matplotlib.pyplot as plt
import numpy as np

from greybox.data import prepare
from greybox.discover.workflow import discover
from greybox.models.friction.coulomb import CoulombModel
from greybox.twin import make_dataset

# %%
# Training and test logs with a hidden effect
# -------------------------------------------
# Datasets A (training) and C (test) of the synthetic X axis, with the same hidden effect at 0.2 A.
train = prepare([make_dataset("X", "A", seed=11, effect="position_periodic_force", effect_strength=0.2,
                              duration_s=40.0)])
test = prepare([make_dataset("X", "C", seed=12, effect="position_periodic_force", effect_strength=0.2,
                             duration_s=40.0)])

# %%
# Run the workflow
# ----------------
result = discover(CoulombModel(), train, test, max_effects=1, n_null=19, seed=0, refine_base=False)
print("verdict:", result.verdict)
for effect in result.effects:
    print(effect["name"], {name: round(value, 4) if isinstance(value, float) else value
                           for name, value in effect["parameters"].items()})
print(f"test RMSE before {result.test['rmse_before']:.4f} A, after {result.test['rmse_after']:.4f} A")

# %%
# The residual of the base model against position, before and after the named effect is added: the
# ripple along the travel is what the added term takes out.
(run,) = test
before = run.current - result.base_model.predict(test)
after = run.current - result.model.predict(test)
order = np.argsort(run.position)
fig, ax = plt.subplots(figsize=(8, 4))
ax.plot(run.position[order], before[order], ".", ms=1, alpha=0.3, label="base alone")
ax.plot(run.position[order], after[order], ".", ms=1, alpha=0.3, label="base + named effect")
ax.set_xlabel("position [mm]")
ax.set_ylabel("residual current [A]")
ax.legend(markerscale=10)
fig.tight_layout()
