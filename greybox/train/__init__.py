"""Training as a library: :func:`train_logs` (one model), :func:`train_machine_logs` (a model per axis) and
:func:`train_auto_logs` (the model chosen by held-out runs).

Each reads and prepares the logs, fits, attaches the parameter intervals and records how the model was
made (:func:`record_training`: the model's ``training_record_``, which every model file it is saved to
carries), and returns the model; a model kind named without options gets the training defaults
(:func:`with_training_defaults`: an offset where it takes one), as ``greybox train --model KIND``. Given
``out``, it also saves it and checks the file reproduces it.
``greybox train``, ``greybox compensate`` and the fleet (:mod:`greybox.fleet.train`) train through these.
"""

from .choice import train_auto_logs
from .defaults import with_training_defaults
from .logs import fit_runs, read_training_logs, train_logs
from .machine import train_machine_logs
from .record import record_training, run_names

__all__ = ["fit_runs", "read_training_logs", "record_training", "run_names", "train_auto_logs", "train_logs",
           "train_machine_logs", "with_training_defaults"]
