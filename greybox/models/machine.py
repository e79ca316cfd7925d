"""Machine models: one fitted current model per axis of a machine, kept together in a directory.

Layout (format name ``greybox-machine``, version 1)::

    machine_dir/
        machine.json      {"format": "greybox-machine", "format_version": 1, "greybox_version": "...",
                           "name": "five-axis mill",
                           "axes": {"X": {"model": "X.gbm", "kind": "gmssvr", "motion": "linear"}, ...}}
        X.gbm             the X axis's model file (greybox.models.files)
        Y.gbm
        C.gbm

Every model file is an ordinary greybox model file, so ``greybox predict
machine_dir/X.gbm LOG --axis X`` works on one axis alone. The manifest is
written last and atomically: a directory whose training was interrupted has
no manifest of the new run. Reading validates the manifest fully (format,
version, axis names, a model file per axis named ``<axis>.gbm`` inside the
directory, its kind and kind of axis against the manifest) and loads each
model file with :func:`greybox.models.files.load_model`, which executes nothing.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path
from typing import Mapping

from ..atomic import write_text_atomic
from ..errors import ModelFileError
from .files import check_format, check_reproduces, load_model, save_model
from .registry import model_kind

__all__ = ["MACHINE_FORMAT", "MACHINE_FORMAT_VERSION", "MANIFEST", "MachineModel", "is_machine_model",
           "check_machine_output", "save_machine", "load_machine"]

#: Value of the ``format`` field of the manifest.
MACHINE_FORMAT = "greybox-machine"
#: Newest manifest version this greybox writes and reads.
MACHINE_FORMAT_VERSION = 1
#: File name of the manifest inside the directory.
MANIFEST = "machine.json"
#: Largest manifest read [bytes]: a machine has a handful of axes.
_MAX_MANIFEST_BYTES = 1 << 20


@dataclass(frozen=True)
class MachineModel:
    """Fitted current models of the axes of one machine.

    Parameters
    ----------
    models : mapping of str to CurrentModel
        One fitted model per axis, in the machine's axis order.
    name : str, default ""
        Machine name.
    source : str, default ""
        Directory the machine model was loaded from (:func:`load_machine`); empty when built in memory.
        Not compared in equality.
    """

    models: Mapping[str, object]
    name: str = ""
    source: str = field(default="", compare=False)

    @property
    def axes(self) -> list[str]:
        """Axis names, in order."""
        return list(self.models)


def is_machine_model(path: str | PathLike) -> bool:
    """True when ``path`` is a directory holding a machine manifest.

    Parameters
    ----------
    path : str or path-like
        File or directory to test.
    """
    path = Path(path)
    return path.is_dir() and (path / MANIFEST).is_file()


def _check_axis_name(axis, where: str) -> str:
    if not isinstance(axis, str) or not axis[:1].isalpha() or not axis.isalnum() or len(axis) > 32:
        raise ModelFileError(f"{where}: axis name {axis!r} must be up to 32 letters and digits, starting with a letter")
    return axis


def check_machine_output(directory: str | PathLike, axes, *, overwrite: bool = False) -> dict[str, Path]:
    """Raise unless a machine model of ``axes`` may be written to ``directory``; return its model paths.

    Parameters
    ----------
    directory : str or path-like
        Directory of the machine model (created by :func:`save_machine` if missing).
    axes : sequence of str
        Axis names.
    overwrite : bool, default False
        Whether the files of an existing machine model may be replaced.

    Returns
    -------
    dict of str to pathlib.Path
        ``{axis: directory / "<axis>.gbm"}``.

    Raises
    ------
    ModelFileError
        For a path that is a file, a missing parent directory, no axes, an invalid axis name, or
        an existing manifest or model file without ``overwrite``.
    """
    directory = Path(directory)
    if directory.exists() and not directory.is_dir():
        raise ModelFileError(f"{directory}: exists and is not a directory (a machine model is a directory)")
    if not axes:
        raise ModelFileError(f"{directory}: a machine model needs at least one axis")
    targets = {_check_axis_name(axis, str(directory)): directory / f"{axis}.gbm" for axis in axes}
    if not overwrite:
        existing = [path for path in (directory / MANIFEST, *targets.values()) if path.exists()]
        if existing:
            raise ModelFileError(f"{existing[0]}: file exists; refusing to overwrite it (--force replaces the "
                                 "machine model)")
    parent = directory.parent if str(directory.parent) else Path(".")
    if not parent.is_dir():
        raise ModelFileError(f"{directory}: directory {parent} does not exist")
    return targets


def save_machine(machine: MachineModel, directory: str | PathLike, *, overwrite: bool = False,
                 records: dict | None = None, verify: Mapping[str, tuple] | None = None) -> list[Path]:
    """Write a machine model: one model file per axis, then the manifest.

    Parameters
    ----------
    machine : MachineModel
        Fitted models by axis.
    directory : str or path-like
        Directory to write; created if missing (its parent must exist).
    overwrite : bool, default False
        Replace the files of an existing machine model in ``directory``.
    records : dict, optional
        ``{axis: records}``: the records of each axis's model file (:func:`greybox.models.files.save_model`).
    verify : mapping, optional
        ``{axis: (runs, predictions)}``: read the machine model back and check that each axis's model
        predicts these runs exactly as the fitted one did (:func:`greybox.models.files.check_reproduces`).

    Returns
    -------
    list of pathlib.Path
        The files written, the manifest last.

    Raises
    ------
    ModelFileError
        For a path that is a file, a directory holding a machine model (or an axis's file)
        without ``overwrite``, an invalid axis name, a model that cannot be saved, or (with ``verify``)
        a saved model that does not reproduce the fitted one's predictions.
    """
    from .. import __version__

    directory = Path(directory)
    targets = check_machine_output(directory, list(machine.models), overwrite=overwrite)
    directory.mkdir(exist_ok=True)
    axes = {}
    for axis, model in machine.models.items():
        save_model(model, targets[axis], overwrite=overwrite, records=(records or {}).get(axis))
        axes[axis] = {"model": targets[axis].name, "kind": model_kind(model), "motion": model.units_.name}
    manifest = {"format": MACHINE_FORMAT, "format_version": MACHINE_FORMAT_VERSION,
                "greybox_version": __version__, "name": machine.name, "axes": axes}
    write_text_atomic(directory / MANIFEST, json.dumps(manifest, indent=1) + "\n")
    if verify:
        reloaded = load_machine(directory)
        for axis, (runs, predictions) in verify.items():
            check_reproduces(reloaded.models[axis], runs, predictions, directory,
                             label=f"the saved model of axis {axis}")
    return [*targets.values(), directory / MANIFEST]


def _manifest(directory: Path) -> dict:
    path = directory / MANIFEST
    if not path.is_file():
        raise ModelFileError(f"{directory}: not a machine model (no {MANIFEST}); give a model file or a directory "
                             "written by 'greybox train --axes'")
    if path.stat().st_size > _MAX_MANIFEST_BYTES:
        raise ModelFileError(f"{path}: {path.stat().st_size} bytes, too large for a machine manifest")
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as error:
        raise ModelFileError(f"{path}: not a JSON manifest ({error})") from None
    check_format(document, path, name=MACHINE_FORMAT, newest=MACHINE_FORMAT_VERSION, what="machine manifest")
    unknown = sorted(set(document) - {"format", "format_version", "greybox_version", "name", "axes"})
    if unknown:
        raise ModelFileError(f"{path}: unknown manifest key {unknown[0]!r}")
    if not isinstance(document.get("name", ""), str):
        raise ModelFileError(f"{path}: name must be text")
    axes = document.get("axes")
    if not isinstance(axes, dict) or not axes:
        raise ModelFileError(f"{path}: 'axes' must be an object with at least one axis")
    return document


def load_machine(directory: str | PathLike) -> MachineModel:
    """Read and validate a machine model directory.

    Parameters
    ----------
    directory : str or path-like
        Directory written by :func:`save_machine`.

    Returns
    -------
    MachineModel

    Raises
    ------
    ModelFileError
        For a missing or malformed manifest, an axis entry naming another file than ``<axis>.gbm``,
        a model file that does not load, or a model whose kind or kind of axis disagrees with the
        manifest; the message names the file.
    """
    directory = Path(directory)
    document = _manifest(directory)
    where = str(directory / MANIFEST)
    models = {}
    for axis, entry in document["axes"].items():
        _check_axis_name(axis, where)
        if not isinstance(entry, dict) or set(entry) != {"model", "kind", "motion"}:
            raise ModelFileError(f"{where}: axis {axis} must give exactly model, kind and motion")
        if entry["model"] != f"{axis}.gbm":
            raise ModelFileError(f"{where}: axis {axis} names the model file {entry['model']!r}; a machine model "
                                 f"keeps it as {axis}.gbm beside the manifest")
        model = load_model(directory / entry["model"])
        try:
            motion = model.units_.name
        except (AttributeError, ValueError):  # sklearn's NotFittedError is both
            raise ModelFileError(f"{directory / entry['model']}: the model is not fitted") from None
        if model_kind(model) != entry["kind"] or motion != entry["motion"]:
            raise ModelFileError(f"{directory / entry['model']}: a {model_kind(model)} model of a {motion} axis, "
                                 f"the manifest says {entry['kind']!r} of a {entry['motion']!r} axis")
        models[axis] = model
    return MachineModel(models=models, name=document.get("name", ""), source=str(directory))
