"""Advice from what a training measured: a ``note:`` line each, for the caller to show."""

from __future__ import annotations

import numpy as np

__all__ = ["OFFSET_SHARE", "offset_note", "takes_hyperparameter"]

#: A training residual whose mean is at least this share of its RMS points to an offset the model lacks.
OFFSET_SHARE = 0.2


def takes_hyperparameter(model, name: str) -> bool:
    """Whether ``model`` or a model nested in it takes the hyperparameter ``name`` (so that its option applies).

    Parameters
    ----------
    model : estimator
        An unfitted or fitted model; its nested models (a first stage, the base behind a backlash) count.
    name : str
        Hyperparameter, e.g. ``"fit_offset"``.
    """
    stage = model.first_stage()
    nested = stage.get_params(deep=True) if stage is not None else {}
    return any(key == name or key.endswith("__" + name) for key in [*model.get_params(deep=True), *nested])


def offset_note(efforts, predictions, unit: str) -> str | None:
    """The note naming ``--offset`` when the training residual's mean says the logs hold an offset.

    A model that fits a constant offset leaves a residual of mean (nearly) zero; a mean of at least
    :data:`OFFSET_SHARE` of the residual's RMS is a current sensor's offset or an axis's weight the model
    does not carry, which ``greybox predict`` would report as process force.

    Parameters
    ----------
    efforts : sequence of ndarray
        Measured effort of each training run [A, or N, Nm].
    predictions : sequence of ndarray
        The model's effort for each run [same unit].
    unit : str
        Effort unit, for the message.

    Returns
    -------
    str or None
        The note, or None when the residual's mean is small.
    """
    residual = np.concatenate([np.asarray(e, float) - np.asarray(p, float) for e, p in zip(efforts, predictions)])
    if residual.size == 0:
        return None
    mean = float(np.mean(residual))
    rms = float(np.sqrt(np.mean(residual ** 2)))
    if rms == 0.0 or abs(mean) < OFFSET_SHARE * rms:
        return None
    return (f"note: the training residual's mean is {mean:.4g} {unit} ({abs(mean) / rms:.0%} of its RMS): the logs "
            "hold an offset the model does not fit (a current sensor's offset, an axis's weight), which predict "
            "would report as process force; --offset fits one")
