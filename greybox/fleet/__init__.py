"""Plant-wide runs on dask.distributed: the engine every fleet run shares (:mod:`greybox.fleet.engine`:
logs found, one task per job on a cluster, failures reported, the manifest, a re-run skipping what is done)
and the training of a model per machine and axis (:mod:`greybox.fleet.train`, ``greybox train
--per-machine``). The fleet runs of prediction and monitoring run on this engine from their own packages
(:mod:`greybox.predict.fleet`, :mod:`greybox.monitor.workflow`), which their entry points
(:func:`greybox.predict.predict_logs`, :func:`greybox.monitor.run_monitor`) dispatch to.

This package imports only its engine: the workflows import the engine without importing the fleet's
training.
"""

from .engine import (
    LOG_SUFFIXES,
    MANIFEST,
    MAX_NAME_BYTES,
    MODELS_FORMAT,
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
    machine_of,
    out_dir_of,
    partition,
    read_manifest,
    run_tasks,
)

__all__ = [
    "LOG_SUFFIXES",
    "MANIFEST",
    "MAX_NAME_BYTES",
    "MODELS_FORMAT",
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
    "machine_of",
    "out_dir_of",
    "partition",
    "read_manifest",
    "run_tasks",
]
