"""Plant-wide runs on dask.distributed: the engine every fleet run shares (:mod:`greybox.fleet.engine`:
logs found, one task per job on a cluster, failures reported, the manifest, a re-run skipping what is done)
and the runs on it: the training of a model per machine and axis (:mod:`greybox.fleet.train`, ``greybox train
--per-machine``), the prediction of many logs into a partitioned dataset (:mod:`greybox.fleet.predict`,
``greybox predict`` with several logs) and the fingerprints of ``greybox monitor`` on a cluster
(:mod:`greybox.fleet.monitor`). Each run stands on the package of its workflow (:mod:`greybox.train`,
:mod:`greybox.predict`, :mod:`greybox.monitor`), which imports nothing of this one; the command line calls
the fleet's entry point when a run is a fleet run. The files a run leaves (the manifest, the models directory)
are read by :mod:`greybox.models.plant`.

This package imports only its engine: the engine imports no run on it.
"""

from .engine import (
    LOG_SUFFIXES,
    MAX_NAME_BYTES,
    SAVE_EVERY_S,
    attempt,
    check_machines,
    check_names,
    check_out_dir,
    decode_name,
    encode_name,
    expand_logs,
    fleet_summary,
    log_names,
    log_stamp,
    out_dir_of,
    run_tasks,
)

__all__ = [
    "LOG_SUFFIXES",
    "MAX_NAME_BYTES",
    "SAVE_EVERY_S",
    "attempt",
    "check_machines",
    "check_names",
    "check_out_dir",
    "decode_name",
    "encode_name",
    "expand_logs",
    "fleet_summary",
    "log_names",
    "log_stamp",
    "out_dir_of",
    "run_tasks",
]
