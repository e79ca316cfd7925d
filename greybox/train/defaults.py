"""The hyperparameters a model is trained with unless its caller says otherwise.

One rule for every way of training (``greybox train``, :func:`greybox.train.train_logs`, a machine model):
a model that takes a constant effort offset fits one, since a current sensor's offset, or the weight a
vertical axis carries, is in every real drive's current, and a model without it reads the offset as process
force. A caller who sets the offset or direction-dependent friction (the two do not go together) has chosen.
"""

from __future__ import annotations

from typing import Collection

__all__ = ["OFFSET", "with_training_defaults"]

#: Hyperparameter of a constant effort offset.
OFFSET = "fit_offset"

#: Hyperparameters whose setting is a choice about the offset (an asymmetric model fits none).
_OFFSET_CHOICES = frozenset({OFFSET, "asymmetric"})


def _takes_offset(model) -> bool:
    """Whether ``model`` takes an offset and nothing about it (direction-dependent friction) refuses one."""
    params = model.get_params(deep=False)
    return OFFSET in params and not params.get("asymmetric", False)


def with_training_defaults(model, given: Collection[str] = ()):
    """Set the training defaults on an unfitted ``model`` (in place) for the hyperparameters not ``given``.

    The model, or else its first stage (the GMS stage of gmssvr), fits a constant effort offset
    (``fit_offset=True``) where it takes one, unless ``given`` names ``fit_offset`` or ``asymmetric``, or the
    model is direction-dependent. A first stage given whole (its hyperparameter, ``gms`` of gmssvr, in
    ``given``) is left as given.

    Parameters
    ----------
    model : CurrentModel
        Unfitted model of a registered kind.
    given : collection of str, default ()
        Hyperparameters the caller set, of the model or of its first stage.

    Returns
    -------
    CurrentModel
        ``model``.
    """
    if _OFFSET_CHOICES & set(given):
        return model
    if OFFSET in model.get_params(deep=False):
        if _takes_offset(model):
            model.set_params(**{OFFSET: True})
        return model
    stage = model.first_stage()
    if stage is not None and model.first_stage_param not in given and _takes_offset(stage):
        model.set_params(**{model.first_stage_param: stage.set_params(**{OFFSET: True})})
    return model
