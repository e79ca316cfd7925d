"""The table of the options that set a model hyperparameter, and the errors the command line words itself.

Kept apart from the model builder (:mod:`greybox.cli._build`, which imports the
model kinds) so that the one-line messages (:mod:`greybox.cli._spelling`) need
no model to be loaded: ``greybox --help`` imports this module only.
"""

from __future__ import annotations

from ..errors import GreyboxError

__all__ = ["MODEL_OPTIONS", "CommandLineError"]


class CommandLineError(GreyboxError):
    """An error the command line words itself (its message names options already and is printed as is)."""


#: Options that set a model hyperparameter: (option, attribute of the parsed arguments, hyperparameter).
MODEL_OPTIONS = (
    ("--offset", "offset", "fit_offset"),
    ("--asymmetric", "asymmetric", "asymmetric"),
    ("--elements", "elements", "n_elements"),
    ("--model-seed", "model_seed", "random_state"),
    ("--inertia", "model_inertia", "inertia"),
)
