"""``greybox train --model auto`` as an entry of the benchmark protocols' model tables.

The protocols construct every model from its seed and call its ``fit`` on the
training runs; this stand-in's ``fit`` returns the model that
:func:`greybox.train.candidates.choose_model` chooses on those runs, each
training file held out in turn (one file: three stretches of it), fitted
on all of them and carrying the table it was chosen from in ``selection_``.
"""

from __future__ import annotations

import os

from greybox.data.log import as_log_list
from greybox.train.candidates import choose_model

__all__ = ["HeldOutChoice"]


class HeldOutChoice:
    """The model ``--model auto`` chooses, with its default candidates.

    Parameters
    ----------
    seed : int
        Not used: the candidates run with their default seeds, as ``--model auto`` runs them.
    """

    def __init__(self, seed: int):
        self.seed = seed

    def fit(self, logs, progress=None):
        """The chosen model, fitted on ``logs`` (one group per source file).

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            The prepared training runs.
        progress : None, bool or callable, optional
            Any true value prints a line per candidate fit.

        Returns
        -------
        CurrentModel
            The chosen model, with ``selection_``.
        """
        runs = as_log_list(logs)
        report = (lambda line: print(f"  auto: {line}", flush=True)) if progress else None
        return choose_model(runs, [run.source or "training run" for run in runs], workers=os.cpu_count() or 1,
                            progress=report)
