"""The one builder of unfitted models from command-line options (train, discover, compensate)."""

from __future__ import annotations

import argparse
import json

from ..errors import GreyboxError
from ..models.friction.backlash import BacklashModel
from ..models.registry import model_class
from ..train.defaults import with_training_defaults
from ._model_options import MODEL_OPTIONS, CommandLineError
from ._types import NON_NEGATIVE, POSITIVE_INT, SEED

__all__ = ["CommandLineError", "add_model_arguments", "build_model", "parse_setting"]


def add_model_arguments(parser: argparse.ArgumentParser, *, title: str = "model options",
                        settings: bool = True, backlash: bool = False, offset_default: bool = False) -> None:
    """Add the options that set the hyperparameters of the model a command builds.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        Parser of the sub-command.
    title : str
        Heading of the option group in ``--help``.
    settings : bool, default True
        Also offer ``--set NAME=VALUE`` for any hyperparameter.
    backlash : bool, default False
        Also offer ``--backlash`` (a model behind an identified backlash).
    offset_default : bool, default False
        Offer ``--offset/--no-offset`` and leave the options not given to the training defaults
        (:func:`greybox.train.defaults.with_training_defaults`: a constant effort offset where the model takes
        one, unless ``--no-offset`` or ``--asymmetric`` is given), as ``greybox train`` does.
    """
    group = parser.add_argument_group(title)
    if offset_default:
        group.add_argument("--offset", action=argparse.BooleanOptionalAction, default=None,
                           help="fit a constant effort offset (a current sensor's offset, an axis's weight): the "
                           "default of the models that take one, except with --asymmetric; --no-offset leaves "
                           "it out")
        parser.set_defaults(offset_default=True)
    else:
        group.add_argument("--offset", action="store_true", help="also fit a constant effort offset")
    group.add_argument("--asymmetric", action="store_true",
                       help="direction-dependent friction: sliding levels, Stribeck curve and viscous "
                       "coefficient of their own for positive and negative motion (coulomb, stribeck, lugre, gms, "
                       "and the GMS stage of gmssvr; not with --offset)")
    group.add_argument("--elements", type=POSITIVE_INT, metavar="N",
                       help="number of Maxwell-slip elements (gms and the GMS stage of gmssvr; default 4)")
    inertia = group.add_mutually_exclusive_group()
    inertia.add_argument("--inertia", dest="model_inertia", type=NON_NEGATIVE, metavar="J",
                         help="known inertia J in effort s^2/length (A s^2/mm, N s^2/mm = t, Nm s^2/deg), e.g. from "
                         "the drive's commissioning: the model identifies no inertia of its own (default: identified)")
    inertia.add_argument("--load-side", dest="model_inertia", action="store_const", const=0.0,
                         help="the effort is measured at the load (a force or torque sensor on the device), so no "
                         "inertia lies between the sensor and the friction: J = 0 (the same as --inertia 0)")
    if backlash:
        group.add_argument("--backlash", action="store_true",
                           help="put the model behind a backlash whose width is identified from the data: no force "
                           "passes while the motion crosses the gap after the force changes sign (slow: one fit "
                           "of the model per trial width, about 18)")
    group.add_argument("--model-seed", type=SEED, metavar="N",
                       help="seed of the identification: multi-start searches (lugre, gms) and SVR "
                       "subsets and hyperparameter search (svr, gmssvr); default 0")
    if settings:
        group.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                           help="set any model hyperparameter, e.g. --set n_starts=8 or --set C=2.0 (repeatable; "
                           "VALUE is read as a JSON number, true, false or null, else as text)")


def build_model(kind: str, args: argparse.Namespace):
    """Return an unfitted model of ``kind`` with the hyperparameters given on the command line.

    Options a command does not offer count as not given. An option the
    model does not take but its first stage does (``--asymmetric``,
    ``--elements``, ``--offset`` of gmssvr) is set on the first stage.
    ``--backlash`` wraps the model in a :class:`BacklashModel`. With ``offset_default`` set on
    ``args`` (:func:`add_model_arguments`), the options not given take the training defaults of
    :func:`greybox.train.defaults.with_training_defaults` (an offset where the model takes one), as
    :func:`greybox.train.train_logs` gives a model kind named without options.

    Parameters
    ----------
    kind : str
        Registered model kind (e.g. ``"gms"``, ``"svr"``, ``"gmssvr"``), as in
        :func:`~greybox.models.registry.model_class`.
    args : argparse.Namespace
        Parsed command-line arguments; the model options (``offset``, ``asymmetric``, ``elements``,
        ``model_seed``, ``set``, ``backlash``) are read from it, and those it lacks count as not given.

    Raises
    ------
    GreyboxError
        If an option does not apply to the model kind, or a ``--set`` is malformed or unknown.
    """
    model = model_class(kind)()
    accepted = model.get_params(deep=False)
    stage = model.first_stage()
    params, stage_params = {}, {}
    given = set()  # hyperparameters the command line sets: the library's training defaults leave them
    for option, attribute, name in MODEL_OPTIONS:
        value = getattr(args, attribute, None)
        if value is not None and (value is not False or name == "fit_offset"):
            given.add(name)  # --no-offset (False) chooses too
        if value is None or value is False:
            continue
        if name in accepted:
            params[name] = value
        elif stage is not None and name in stage.get_params(deep=False):
            stage_params[name] = value  # e.g. --asymmetric of gmssvr: its GMS stage
        else:
            raise GreyboxError(f"option {option} does not apply to the {kind} model")
    if stage_params:
        params[model.first_stage_param] = stage.set_params(**stage_params)
    for setting in getattr(args, "set", None) or []:
        name, sep, text = setting.partition("=")
        name = name.strip()
        if not sep or not name:
            raise CommandLineError(f"--set expects NAME=VALUE, got {setting!r}")
        if name not in accepted:
            offered = {hyperparameter: option for option, _, hyperparameter in MODEL_OPTIONS}
            takes = ", ".join(offered.get(other, f"--set {other}=...") for other in sorted(accepted))
            raise CommandLineError(f"--set {name}=...: the {kind} model has no such hyperparameter; it takes {takes}")
        params[name] = parse_setting(text)
        given.add(name)
    model.set_params(**params)
    if getattr(args, "offset_default", False):
        with_training_defaults(model, given)
    return BacklashModel(base=model) if getattr(args, "backlash", False) else model


#: Python's and JSON's spellings of the constants a ``--set`` value may be.
_CONSTANTS = {"true": True, "false": False, "null": None, "none": None}


def parse_setting(text: str):
    """The value of ``--set NAME=VALUE``: a JSON value; ``true``/``false``/``null`` in any case
    (``False`` and ``None`` too); anything else as text (the model's checks refuse a wrong type).

    Parameters
    ----------
    text : str
        The ``VALUE`` part of the option, after the first ``=``.
    """
    stripped = text.strip()
    if stripped.lower() in _CONSTANTS:
        return _CONSTANTS[stripped.lower()]
    try:
        return json.loads(stripped)
    except json.JSONDecodeError:
        return text
