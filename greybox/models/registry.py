"""The explicit registry of model classes that model files may name.

A model file stores its model's ``kind`` (a key of :data:`MODEL_CLASSES`);
loading looks the class up here. Nothing named in a file is ever imported, so
a file cannot make greybox run code other than these classes' constructors.
"""

from __future__ import annotations

from .augmented import AugmentedModel
from .friction import CoulombModel, GMSModel, LuGreModel, StribeckModel
from .friction.backlash import BacklashModel
from .gmssvr import GMSSVRModel
from .svr import SVRCurrentModel

__all__ = ["MODEL_CLASSES", "DERIVED_MODEL_CLASSES", "model_class", "model_kind"]

#: Model kind (as written in model files and given to ``greybox train --model``) -> class.
MODEL_CLASSES: dict[str, type] = {
    "coulomb": CoulombModel,
    "stribeck": StribeckModel,
    "lugre": LuGreModel,
    "gms": GMSModel,
    "svr": SVRCurrentModel,
    "gmssvr": GMSSVRModel,
}

#: Kinds that wrap another model and model files may hold, but ``greybox train --model`` does not
#: name: the base model plus named effects of ``greybox discover``, and any model behind a backlash
#: (``greybox train --backlash``).
DERIVED_MODEL_CLASSES: dict[str, type] = {
    "augmented": AugmentedModel,
    "backlash": BacklashModel,
}


def _file_kinds() -> dict[str, type]:
    """Every kind a model file may hold (looked up at call time, so registrations count)."""
    return {**MODEL_CLASSES, **DERIVED_MODEL_CLASSES}


def model_class(kind: str) -> type:
    """Return the class registered under ``kind``.

    Parameters
    ----------
    kind : str
        A key of :data:`MODEL_CLASSES` or :data:`DERIVED_MODEL_CLASSES`, as stored in a model file.

    Raises
    ------
    KeyError
        If no class is registered under that name.
    """
    kinds = _file_kinds()
    if not isinstance(kind, str) or kind not in kinds:
        raise KeyError(f"unknown model kind {kind!r}; known: {', '.join(sorted(kinds))}")
    return kinds[kind]


def model_kind(model) -> str:
    """Return the registered kind of ``model`` (its exact class, not a subclass).

    Parameters
    ----------
    model : object
        A current model (fitted or not).

    Raises
    ------
    KeyError
        If the model's class is not registered.
    """
    for kind, cls in _file_kinds().items():
        if type(model) is cls:
            return kind
    raise KeyError(f"model class {type(model).__name__} is not registered in greybox.models.registry")
