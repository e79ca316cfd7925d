"""
Predict a fleet of logs
=======================

With many logs, from many machines, the prediction runs one task per log on Dask and writes the
process tables to one Parquet dataset partitioned like the plant
(``machine=<folder of the log>/axis=<axis>/log=<path relative to the logs' folder>``), with a manifest of every log. The
command line does the same with::

    greybox predict x.gbm plant/ --out results --axis-config examples/axis_x.toml

Here the plant is two machines with one shipped air cut each, the model a Stribeck curve fitted on
40 s of ``X_A``, and the cluster a small one inside this process (the command starts a local cluster
of processes, one per core, or uses an existing one given by ``--scheduler``).
"""

import shutil
import tempfile
from pathlib import Path

import pyarrow.dataset
from distributed import LocalCluster

from greybox.data import prepare, read_log
from greybox.fleet.predict import predict_fleet
from greybox.models.files import save_model
from greybox.models.friction.stribeck import StribeckModel

root = Path("../..")  # the repository (the gallery runs from docs/examples)
work = Path(tempfile.mkdtemp())

# %%
# A plant of two machines, and a model
# ------------------------------------
for machine, name in [("mill_1", "X_C.mcap"), ("mill_2", "X_D.mcap")]:
    (work / "plant" / machine).mkdir(parents=True)
    shutil.copy(root / "data" / name, work / "plant" / machine / name)
(air_cut,) = prepare([read_log(root / "data" / "X_A.mcap")])
model = StribeckModel().fit([air_cut.select(air_cut.time < air_cut.time[0] + 40.0)])
save_model(model, work / "x_stribeck.gbm")

# %%
# One job per log, run on the cluster
# -----------------------------------
# A folder of logs makes a fleet run: one task per log on Dask, the results a Parquet dataset
# partitioned by machine, axis and log.
with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
    done = predict_fleet(work / "x_stribeck.gbm", [str(work / "plant")], out=work / "results",
                         axis_config=str(root / "examples" / "axis_x.toml"), scheduler=cluster.scheduler_address)
for entry in done.manifest["logs"]:
    print(entry["status"], Path(entry["log"]).relative_to(work), entry.get("samples"), "samples")

# %%
# The results as one table
# ------------------------
table = pyarrow.dataset.dataset(work / "results", partitioning="hive").to_table().to_pandas()
print(table.groupby(["machine", "log"])["force_process_N"].describe()[["count", "mean", "std"]])
shutil.rmtree(work)
