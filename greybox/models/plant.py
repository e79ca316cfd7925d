"""A plant's files: the manifest a run over many logs leaves in its output directory, the machine a log belongs
to, and the models directory of ``greybox train --per-machine`` with the model of a log's machine.

The machine of a log is the name of its folder (:func:`machine_of`), as in the ``machine=`` partition of a fleet
prediction: folders of one name in different places are one machine. The models directory holds
``<machine>/<axis>.gbm`` and its :data:`MANIFEST` of format :data:`MODELS_FORMAT`, listing each model with its
status; :func:`machine_models` reads the models it lists as trained and :func:`model_of_log` picks a log's.
The fleet runs (:mod:`greybox.fleet`) write these directories; prediction reads them, one log at a time or a
fleet of logs.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from ..errors import GreyboxError

__all__ = ["MANIFEST", "MODELS_FORMAT", "load_manifest", "machine_models", "machine_of", "model_for", "model_of_log",
           "partition", "read_manifest"]

#: Name of the manifest in the output directory (a leading "_": dataset readers skip it).
MANIFEST = "_manifest.json"

#: ``format`` of the manifest of the models directory of ``greybox train --per-machine``.
MODELS_FORMAT = "greybox-fleet-models"

def partition(value: str) -> str:
    """A partition value safe in a path: letters, digits, ``-``, ``_`` and ``.``.

    Parameters
    ----------
    value : str
        Name to make safe; every other character becomes ``_``, and an empty name ``_``.
    """
    return "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in value) or "_"


def machine_of(log: str | os.PathLike) -> str:
    """The machine a log belongs to: the name of its folder, made safe for a path (:func:`partition`).

    Parameters
    ----------
    log : str or path-like
        Log file.
    """
    return partition(Path(log).parent.name)


def load_manifest(directory: str | os.PathLike) -> dict:
    """The manifest in ``directory`` of any format, or ``{}`` when there is none or it is unreadable.

    Parameters
    ----------
    directory : str or path-like
        Output directory holding :data:`MANIFEST`.
    """
    path = Path(directory) / MANIFEST
    if not path.is_file():
        return {}
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError):
        return {}
    return document if isinstance(document, dict) else {}


def read_manifest(directory: str | os.PathLike, fmt: str) -> dict:
    """The manifest of ``fmt`` in ``directory``, or ``{}`` when there is none, it is unreadable or of another format.

    Parameters
    ----------
    directory : str or path-like
        Output directory holding :data:`MANIFEST`.
    fmt : str
        The ``format`` the manifest must have (:data:`MODELS_FORMAT`, or that of a fleet prediction).
    """
    document = load_manifest(directory)
    return document if document.get("format") == fmt else {}


def machine_models(directory: str | os.PathLike) -> dict[str, dict[str, str]]:
    """The models of a directory written by ``greybox train --per-machine``: ``{machine: {axis: model file}}``.

    Only the models its manifest lists as trained (``ok`` or ``skipped``) whose file is there count.

    Parameters
    ----------
    directory : str or path-like
        Output directory of ``greybox train --per-machine``, with its manifest.

    Raises
    ------
    GreyboxError
        For a directory without such a manifest.
    """
    directory = Path(directory)
    document = read_manifest(directory, MODELS_FORMAT)
    if not document:
        raise GreyboxError(f"{directory}: a directory without the {MANIFEST} of 'greybox train --per-machine'; "
                           "give a model file or a directory of models it wrote")
    table: dict[str, dict[str, str]] = {}
    for entry in document.get("models", []):
        if isinstance(entry, dict) and entry.get("status") in ("ok", "skipped") and \
                isinstance(entry.get("output"), str) and (directory / entry["output"]).is_file():
            table.setdefault(str(entry.get("machine")), {})[str(entry.get("axis"))] = str(directory / entry["output"])
    return table


def model_of_log(directory: str | os.PathLike, log: str | os.PathLike, axis: str | None = None) -> str:
    """The model file of ``log``'s machine (the name of its folder) in a directory of ``greybox train --per-machine``.

    Parameters
    ----------
    directory : str or path-like
        Output directory of ``greybox train --per-machine``, with its manifest.
    log : str or path-like
        Log file; its folder names its machine.
    axis : str, optional
        The axis whose model to take where the machine has models of several.

    Raises
    ------
    GreyboxError
        For a directory without that manifest, a machine without a model, or (without ``axis``) a machine
        with models of several axes.
    """
    return model_for(Path(log), machine_of(Path(log)), machine_models(directory), str(directory), axis)


def model_for(log: Path, machine: str, models: dict[str, dict[str, str]], directory: str, axis: str | None) -> str:
    """The model file of ``log``'s machine in a models directory (of ``axis`` where it has several).

    Parameters
    ----------
    log : Path
        Log file, named in the messages.
    machine : str
        Its machine (:func:`machine_of`).
    models : dict
        ``{machine: {axis: model file}}`` of the directory (:func:`machine_models`).
    directory : str
        The models directory, named in the messages.
    axis : str or None
        The axis whose model to take where the machine has models of several.

    Raises
    ------
    GreyboxError
        For a machine without a model, or (without ``axis``) a machine with models of several axes.
    """
    by_axis = models.get(machine)
    if not by_axis:
        known = ", ".join(sorted(models)) or "none"
        raise GreyboxError(f"{log}: no trained model of machine {machine} in {directory} (machines: {known})")
    if axis is not None:
        if axis not in by_axis:
            raise GreyboxError(f"{log}: --axis {axis}: machine {machine} has models of axes "
                               f"{', '.join(sorted(by_axis))}")
        return by_axis[axis]
    if len(by_axis) > 1:
        raise GreyboxError(f"{log}: machine {machine} has models of axes {', '.join(sorted(by_axis))} in {directory}; "
                           "give --axis NAME (one fleet per axis)")
    return next(iter(by_axis.values()))
