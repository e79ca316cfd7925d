"""Prediction: the process share of the motor current of cutting logs, and the force behind it.

:func:`predict_logs` is the one entry point of one log (``greybox predict``): a model file, a machine model or
a directory of per-machine models, the log read whole or block by block, written as a table (and a picture).
A fleet of logs runs on Dask in :mod:`greybox.fleet.predict`, on top of this package. Its parts:
:mod:`~greybox.predict.process` (the process current and force of prepared runs), :mod:`~greybox.predict.stream`
(block by block), :mod:`~greybox.predict.output` (the tables), :mod:`~greybox.predict.plot` (the picture),
:mod:`~greybox.predict.machine` (every axis of a machine), :mod:`~greybox.predict.interval` (calibrated
bounds), :mod:`~greybox.predict.sources` (the model sources: file, machine model, per-machine models),
:mod:`~greybox.predict.request` (a call's options and its result) and :mod:`~greybox.predict.run` (the entry
point).

The names below are loaded on first use, so that importing a part (the command line's option
defaults, the live estimator's :mod:`~greybox.predict.process`) does not load every other.
"""

from __future__ import annotations

__all__ = ["AxisFigures", "ChunkProgress", "Prediction", "predict_logs"]


def __getattr__(name: str):
    """:func:`predict_logs` (:mod:`greybox.predict.run`) and its result types (:mod:`greybox.predict.request`),
    on first use."""
    if name == "predict_logs":
        from .run import predict_logs

        return predict_logs
    if name in __all__:
        from . import request

        return getattr(request, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
