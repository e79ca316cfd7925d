"""Saving and loading fitted models, without pickle.

File format (format name ``greybox-model``, version 5)
------------------------------------------------------
A model file is a ZIP archive (any file name; ``.gbm`` by convention) with

``model.json``
    A JSON object::

        {"format": "greybox-model", "format_version": 5,
         "greybox_version": "0.1.0",
         "model": {"kind": "gms",
                   "params": {...},       # get_params(deep=False)
                   "attributes": {...}}}  # learned attributes (names ending in "_")

``"records"`` (optional, beside ``"model"``)
    Self-contained records about the model, each a JSON object under its name and checked on
    saving and loading by the function :data:`RECORD_CHECKS` holds for that name: ``"training"``
    (:func:`greybox.provenance.training_record`: training files, preparation, errors, ranges). A
    record of a name this greybox does not know is skipped; one that fails its check refuses the
    file. Files without records (older ones) load as before.

``arrays/NNN_<attribute>.npy``
    One NumPy ``.npy`` file per array, referenced from the JSON as
    ``{"__ndarray__": "arrays/NNN_<attribute>.npy"}`` and read back with
    ``allow_pickle=False``.

Values inside ``params`` and ``attributes`` are JSON numbers, strings,
booleans, null, lists and objects with string keys, plus these tagged objects:
``{"__ndarray__": member}`` (numeric, boolean or string arrays),
``{"__tuple__": [...]}``, ``{"__float__": "nan" | "inf" | "-inf"}`` (strict
JSON has no non-finite numbers) and ``{"__estimator__": {"kind", "params",
"attributes"}}`` for a registered model nested in another (a fitted first
stage, say). Floats are written with Python's shortest round-trip repr, and
arrays byte for byte, so a loaded model predicts bit-identically.

``digest.json`` (format version 3)
    The SHA-256 of every other member, ``{"format": "greybox-digest", "algorithm": "sha256",
    "members": {name: hex digest}}``, and, when the file was saved with the plant's key
    (:func:`model_key`), ``"hmac_sha256"``: HMAC-SHA256 with that key over the canonical JSON of
    ``members`` (keys sorted, no spaces). At load every member is hashed and compared: a member
    changed, added or removed since the file was written is refused in one line naming it. With the
    plant's key set, a file whose signature is missing or does not verify is refused; without it the
    signature is not checked. A file without ``digest.json`` (written before it existed) loads with a
    warning that changes to it cannot be detected, and is refused when the plant's key is set.

The class of a model is looked up by its ``kind`` in the explicit registry
:data:`greybox.models.registry.MODEL_CLASSES`; nothing named in the file is ever
imported. A file of a newer format version, of an unknown kind, or with
parameters the class does not take is refused with a
:class:`~greybox.errors.ModelFileError` naming the file. Files are written
atomically (a temporary file in the same directory, then :func:`os.replace`),
with fixed ZIP timestamps, so the same model always gives the same bytes.
"""

from __future__ import annotations

import hashlib
import hmac
import io
import json
import math
import os
import re
import warnings
import zipfile
import zlib
from os import PathLike
from pathlib import Path

import numpy as np
from sklearn.utils.validation import check_is_fitted

from ..atomic import atomic_output
from ..data.log import AxisLog
from ..data.quantities import MOTIONS
from ..errors import GreyboxError, ModelFileError, ParameterError
from ..identify.intervals import check_intervals
from ..identify.selection import check_selection_record
from ..provenance import TRAINING_ATTRIBUTE, TRAINING_RECORD, check_training_record
from . import registry
from .estimator import MAX_PARAMETER_MAGNITUDE, check_inertia

__all__ = ["DIGEST_MEMBER", "FORMAT_NAME", "FORMAT_VERSION", "KEY_ENV", "KEY_FILE_ENV", "RECORD_CHECKS",
           "RENAMED_ATTRIBUTES", "digest_document", "model_key", "save_model", "save_verified", "load_model",
           "check_fitted", "check_format", "check_reproduces"]

#: Check of each record a model file may hold, by name: returns the record or raises ValueError.
RECORD_CHECKS = {TRAINING_RECORD: check_training_record}

#: Value of the ``format`` field of every model file.
FORMAT_NAME = "greybox-model"
#: Newest format version this greybox writes and reads. Version 2 renamed learned attributes
#: (:data:`RENAMED_ATTRIBUTES`); version-1 files are read with the old names mapped. Version 3 added the
#: member :data:`DIGEST_MEMBER` (an older greybox would refuse it as an unexpected member). Version 4 added
#: the ``operating`` record inside the ``training`` record (:mod:`greybox.data.operating`), which an older
#: greybox's check of that record refuses as an unknown key: with the bump it says "written by a newer
#: greybox" instead. Files of versions 1 to 3 load as before (a version-3 file may already hold ``operating``).
#: Version 5 added ``reversals`` to the ``operating`` record (:data:`greybox.data.operating.REVERSALS_RULE`),
#: which an older greybox refuses as an unknown key; files of version 4 load and predict as before (their
#: region without the rule of the reversals).
FORMAT_VERSION = 5

#: Member holding the SHA-256 of every other member (and the signature with the plant's key).
DIGEST_MEMBER = "digest.json"

#: Environment variable holding the plant's key for signing and checking model files (its text, UTF-8).
KEY_ENV = "GREYBOX_MODEL_KEY"
#: Environment variable naming a file that holds the plant's key (its bytes; a final newline is dropped).
KEY_FILE_ENV = "GREYBOX_MODEL_KEY_FILE"

#: Learned attributes that files of format version 1 hold under an older name, by model kind:
#: ``{kind: {old name: new name}}`` (the GMS slip rate and viscous coefficient had names other models use).
RENAMED_ATTRIBUTES = {"gms": {"C_": "slip_rate_", "mu_": "viscous_", "s0_": "s_0_"}}

_JSON_MEMBER = "model.json"
_ARRAY_DIR = "arrays/"
_ZIP_TIME = (1980, 1, 1, 0, 0, 0)
_ARRAY_KINDS = "biufcU"  # bool, integers, floats, complex, unicode: never object
_ATTRIBUTE_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*_$")
#: Names an array member may have (what :class:`_Encoder` writes): no folders, no ``..``, no backslash.
_ARRAY_MEMBER = re.compile(r"^arrays/[0-9]{3,}_[A-Za-z0-9_.-]{0,80}\.npy$")

#: Limits of what a model file may declare, checked before anything is decompressed: a model holds a
#: JSON document and some arrays of support vectors and parameters (tens of MB at most).
MAX_MEMBERS = 10_000
MAX_JSON_BYTES = 64 << 20
MAX_MEMBER_BYTES = 512 << 20
MAX_TOTAL_BYTES = 1 << 30
#: Largest compression ratio of a member above 1 MiB (a zip bomb compresses by 1000 and more).
MAX_COMPRESSION_RATIO = 200


# ------------------------------------------------------------------- writing
class _Encoder:
    """Turn parameter and attribute values into JSON values plus ``.npy`` members."""

    def __init__(self, path: Path):
        self.path = path
        self.arrays: dict[str, bytes] = {}

    def fail(self, where: str, problem: str):
        raise ModelFileError(f"{self.path}: cannot save {where}: {problem}")

    def estimator(self, model, where: str) -> dict:
        try:
            kind = registry.model_kind(model)
        except KeyError as error:
            self.fail(where, str(error.args[0]))
        params = model.get_params(deep=False)
        learned = {name: value for name, value in vars(model).items()
                   if _ATTRIBUTE_NAME.match(name) and name != TRAINING_ATTRIBUTE}  # that one is the file's record
        return {
            "kind": kind,
            "params": {name: self.value(value, f"{where}.{name}") for name, value in params.items()},
            "attributes": {name: self.value(value, f"{where}.{name}") for name, value in sorted(learned.items())},
        }

    def value(self, value, where: str):
        if value is None or isinstance(value, (bool, str)):
            return value
        if isinstance(value, (int, np.integer)) and not isinstance(value, np.bool_):
            return int(value)
        if isinstance(value, np.bool_):
            return bool(value)
        if isinstance(value, (float, np.floating)):
            value = float(value)
            return value if math.isfinite(value) else {"__float__": repr(value)}
        if isinstance(value, np.ndarray):
            return self.array(value, where)
        if isinstance(value, tuple):
            return {"__tuple__": [self.value(v, f"{where}[{i}]") for i, v in enumerate(value)]}
        if isinstance(value, list):
            return [self.value(v, f"{where}[{i}]") for i, v in enumerate(value)]
        if isinstance(value, dict):
            for key in value:
                if not isinstance(key, str):
                    self.fail(where, f"dictionary key {key!r} is not a string")
                if key.startswith("__") and key.endswith("__"):
                    self.fail(where, f"dictionary key {key!r} is reserved")
            return {key: self.value(v, f"{where}[{key!r}]") for key, v in value.items()}
        if hasattr(value, "get_params"):
            return {"__estimator__": self.estimator(value, where)}
        self.fail(where, f"values of type {type(value).__name__} are not supported")

    def array(self, array: np.ndarray, where: str) -> dict:
        if array.dtype.kind not in _ARRAY_KINDS or array.dtype.fields is not None:
            self.fail(where, f"arrays of dtype {array.dtype} are not supported")
        label = re.sub(r"[^A-Za-z0-9_.-]+", "_", where)[:80]
        member = f"{_ARRAY_DIR}{len(self.arrays):03d}_{label}.npy"
        buffer = io.BytesIO()
        np.save(buffer, array, allow_pickle=False)
        self.arrays[member] = buffer.getvalue()
        return {"__ndarray__": member}


def _write_member(archive: zipfile.ZipFile, name: str, data: bytes) -> None:
    info = zipfile.ZipInfo(name, date_time=_ZIP_TIME)
    info.compress_type = zipfile.ZIP_DEFLATED
    info.external_attr = 0o644 << 16
    archive.writestr(info, data)


def model_key() -> bytes | None:
    """The plant's key for model-file signatures: from :data:`KEY_FILE_ENV` (a file) or :data:`KEY_ENV`; None.

    Raises
    ------
    ModelFileError
        When the key file cannot be read, or the key is empty.
    """
    named = os.environ.get(KEY_FILE_ENV)
    if named:
        try:
            key = Path(named).read_bytes()
        except OSError as error:
            raise ModelFileError(f"{named}: cannot read the model key file ({KEY_FILE_ENV}, --key-file): "
                                 f"{error.strerror or error}") from None
        key = key[:-1] if key.endswith(b"\n") else key
        if not key:
            raise ModelFileError(f"{named}: the model key file is empty")
        return key
    text = os.environ.get(KEY_ENV)
    if text is None:
        return None
    if not text:
        raise ModelFileError(f"{KEY_ENV} is set but empty; give the plant's key or unset it")
    return text.encode("utf-8")


def _canonical_members(members: dict) -> bytes:
    return json.dumps(members, sort_keys=True, separators=(",", ":")).encode("utf-8")


def digest_document(members: dict[str, bytes], key: bytes | None = None) -> bytes:
    """The bytes of :data:`DIGEST_MEMBER` for a model file of these members: their SHA-256, signed with ``key``.

    Parameters
    ----------
    members : dict of str to bytes
        Every other member of the file by name, with its content.
    key : bytes, optional
        The plant's key: adds ``hmac_sha256`` (HMAC-SHA256 over the canonical JSON of the digests).
    """
    digests = {name: hashlib.sha256(data).hexdigest() for name, data in sorted(members.items())}
    document = {"format": "greybox-digest", "algorithm": "sha256", "members": digests}
    if key is not None:
        document["hmac_sha256"] = hmac.new(key, _canonical_members(digests), hashlib.sha256).hexdigest()
    return (json.dumps(document, indent=1, sort_keys=True) + "\n").encode("utf-8")


def _check_digest(archive: zipfile.ZipFile, path: Path, key: bytes | None) -> None:
    """Refuse a file whose members are not those its digest records, or whose signature does not verify."""
    names = [name for name in archive.namelist() if name != DIGEST_MEMBER]
    if DIGEST_MEMBER not in archive.namelist():
        if key is not None:
            raise ModelFileError(f"{path}: carries no digest or signature, and the plant's key is set ({KEY_ENV} "
                                 "or --key-file): refused; save it again with the key")
        warnings.warn(f"{path}: written before model files carried a digest: a change to it cannot be detected; "
                      "save it again (greybox train) to add one", UserWarning, stacklevel=3)
        return
    try:
        document = json.loads(_read_member(archive, DIGEST_MEMBER, 1 << 20).decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError):
        raise ModelFileError(f"{path}: {DIGEST_MEMBER} is not valid JSON") from None
    recorded = document.get("members") if isinstance(document, dict) else None
    if document.get("algorithm") != "sha256" or not isinstance(recorded, dict) or not all(
            isinstance(value, str) and re.fullmatch(r"[0-9a-f]{64}", value) for value in recorded.values()):
        raise ModelFileError(f"{path}: {DIGEST_MEMBER} is not a digest of SHA-256 values by member")
    for name in sorted(set(names) - set(recorded)):
        raise ModelFileError(f"{path}: member {name} is not in the file's digest: added after the file was "
                             "written; refused")
    for name in sorted(set(recorded) - set(names)):
        raise ModelFileError(f"{path}: member {name} of the file's digest is missing: removed after the file was "
                             "written; refused")
    for name in sorted(names):
        limit = MAX_JSON_BYTES if name == _JSON_MEMBER else MAX_MEMBER_BYTES
        if hashlib.sha256(_read_member(archive, name, limit)).hexdigest() != recorded[name]:
            raise ModelFileError(f"{path}: member {name} was changed after the file was written (its SHA-256 is "
                                 f"not the one {DIGEST_MEMBER} records); refused")
    if key is not None:
        signature = document.get("hmac_sha256")
        if not isinstance(signature, str):
            raise ModelFileError(f"{path}: not signed, and the plant's key is set ({KEY_ENV} or --key-file): "
                                 "refused; save it again with the key")
        expected = hmac.new(key, _canonical_members(recorded), hashlib.sha256).hexdigest()
        if not hmac.compare_digest(signature, expected):
            raise ModelFileError(f"{path}: its signature does not match the plant's key: changed after it was "
                                 "signed, or signed with another key; refused")


def _checked_records(records, path: Path, action: str) -> dict:
    """The records of a model file that this greybox knows, each checked; a malformed one is an error."""
    if records is None:
        return {}
    if not isinstance(records, dict):
        raise ModelFileError(f"{path}: records must be an object of named records")
    checked = {}
    for name, record in records.items():
        check = RECORD_CHECKS.get(name)
        if check is None:
            if action == "save":
                raise ModelFileError(f"{path}: cannot save the unknown record {name!r} "
                                     f"(known: {', '.join(RECORD_CHECKS)})")
            continue
        try:
            checked[name] = check(record)
        except (ValueError, TypeError) as error:
            raise ModelFileError(f"{path}: the {name} record is malformed: {error}") from None
    return checked


def save_model(model, path: str | PathLike, *, overwrite: bool = False, records: dict | None = None,
               key: bytes | None = None) -> Path:
    """Save a (fitted or unfitted) model to one file, atomically.

    Parameters
    ----------
    model : estimator
        An instance of a class in :data:`greybox.models.registry.MODEL_CLASSES`.
        Its ``get_params(deep=False)`` and every attribute whose name ends in
        ``_`` (the learned attributes) are saved; they may be numbers, strings,
        booleans, None, lists, tuples, dicts with string keys, NumPy arrays
        (not of object dtype) and registered models.
    path : str or path-like
        File to write (``.gbm`` by convention).
    overwrite : bool, default False
        Replace an existing file; otherwise an existing file is an error.
    records : dict, optional
        Records about the model by name (``{"training": ...}``), each checked by :data:`RECORD_CHECKS`;
        without a ``training`` record, the model's own (``training_record_``, set by
        :func:`greybox.train.record_training`) where it has one.
    key : bytes, optional
        The plant's key the file is signed with (:data:`DIGEST_MEMBER`); default :func:`model_key`, none
        when it is not set.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    ModelFileError
        If the file exists and ``overwrite`` is false, the model is not
        registered, or a value cannot be saved without pickle.
    """
    from .. import __version__

    path = Path(path)
    if path.exists() and not overwrite:
        raise ModelFileError(f"{path}: file exists; refusing to overwrite it "
                             "(save_model(..., overwrite=True) replaces it)")
    if path.is_dir():
        raise ModelFileError(f"{path}: is a directory")
    encoder = _Encoder(path)
    document = {
        "format": FORMAT_NAME,
        "format_version": FORMAT_VERSION,
        "greybox_version": __version__,
        "model": encoder.estimator(model, "model"),
    }
    own = getattr(model, TRAINING_ATTRIBUTE, None)
    if own is not None and TRAINING_RECORD not in (records or {}):
        records = {**(records or {}), TRAINING_RECORD: own}
    checked = _checked_records(records, path, "save")
    if checked:
        document["records"] = checked
    text = json.dumps(document, indent=1, allow_nan=False)
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise ModelFileError(f"{path}: directory {directory} does not exist")
    members = {_JSON_MEMBER: text.encode("utf-8"), **encoder.arrays}
    signed_with = model_key() if key is None else key
    with atomic_output(path) as temporary:
        with zipfile.ZipFile(temporary, "w") as archive:
            for member, data in members.items():
                _write_member(archive, member, data)
            _write_member(archive, DIGEST_MEMBER, digest_document(members, signed_with))
    return path


def save_verified(model, path: str | PathLike, runs, *, predictions=None, overwrite: bool = False,
                  records: dict | None = None) -> Path:
    """Save a fitted model atomically, load the file back and check it predicts what the model did.

    Parameters
    ----------
    model : estimator
        A fitted instance of a class in :data:`greybox.models.registry.MODEL_CLASSES`.
    path : str or path-like
        File to write (``.gbm`` by convention).
    runs : sequence of AxisLog
        Runs (the training runs, say) both models predict; the comparison is bit for bit.
    predictions : sequence of ndarray, optional
        The fitted model's predictions of ``runs`` [A or N m] when already computed; else computed here.
    overwrite : bool, default False
        Replace an existing file; otherwise an existing file is an error.
    records : dict, optional
        Records about the model by name, as :func:`save_model` takes them.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    ModelFileError
        As :func:`save_model` and :func:`load_model` do, and if the file's model predicts any run
        differently (the message names the file).
    """
    if predictions is None:
        predictions = [model.predict(run) for run in runs]
    path = save_model(model, path, overwrite=overwrite, records=records)
    check_reproduces(load_model(path), runs, predictions, path)
    return path


def check_reproduces(loaded, runs, predictions, path: str | PathLike, *, label: str = "the saved model") -> None:
    """Refuse a model read back from a file that does not predict what the fitted model did, bit for bit.

    Parameters
    ----------
    loaded : estimator
        The model read back from ``path``.
    runs : sequence of AxisLog
        Runs to predict.
    predictions : sequence of ndarray
        The fitted model's predictions of ``runs`` [A or N m].
    path : str or path-like
        The file (or machine model directory) named in the message.
    label : str, default "the saved model"
        What the message calls the model (``"the saved model of axis X"``).

    Raises
    ------
    ModelFileError
        If any run's prediction differs.
    """
    if not all(np.array_equal(loaded.predict(run), expected) for run, expected in zip(runs, predictions)):
        raise ModelFileError(f"{path}: {label} does not reproduce the fitted model's predictions")


# ------------------------------------------------------------------- reading
class _Decoder:
    """Rebuild values (and nested models) from the JSON and the ``.npy`` members."""

    def __init__(self, path: Path, archive: zipfile.ZipFile, version: int):
        self.path = path
        self.archive = archive
        self.version = version
        self.referenced: set[str] = set()

    def fail(self, problem: str):
        raise ModelFileError(f"{self.path}: {problem}")

    def estimator(self, entry, where: str):
        if not isinstance(entry, dict) or not {"kind", "params", "attributes"} <= set(entry):
            self.fail(f"{where} lacks kind, params or attributes")
        kind = entry["kind"]
        try:
            cls = registry.model_class(kind)
        except KeyError:
            known = ", ".join(sorted(registry.MODEL_CLASSES))
            self.fail(f"unknown model kind {kind!r} in {where} (this greybox knows: {known})")
        params = entry["params"]
        attributes = entry["attributes"]
        if not isinstance(params, dict) or not isinstance(attributes, dict):
            self.fail(f"params and attributes of {where} must be objects")
        accepted = set(cls().get_params(deep=False))
        unknown = sorted(set(params) - accepted)
        if unknown:
            self.fail(f"{kind} model in {where} has parameters this greybox does not know: {', '.join(unknown)}")
        model = cls(**{name: self.value(value, f"{where}.{name}") for name, value in params.items()})
        if self.version < 2:
            renamed = RENAMED_ATTRIBUTES.get(kind, {})
            attributes = {renamed.get(name, name): value for name, value in attributes.items()}
        for name, value in attributes.items():
            if not isinstance(name, str) or not _ATTRIBUTE_NAME.match(name):
                self.fail(f"{where} has an invalid learned-attribute name {name!r}")
            setattr(model, name, self.value(value, f"{where}.{name}"))
        return model

    def value(self, value, where: str):
        if isinstance(value, list):
            return [self.value(v, where) for v in value]
        if not isinstance(value, dict):
            return value
        if len(value) == 1:
            (tag, content), = value.items()
            if tag == "__ndarray__":
                return self.array(content, where)
            if tag == "__tuple__" and isinstance(content, list):
                return tuple(self.value(v, where) for v in content)
            if tag == "__float__" and content in ("nan", "inf", "-inf"):
                return float(content)
            if tag == "__estimator__":
                return self.estimator(content, where)
        if any(key.startswith("__") and key.endswith("__") for key in value):
            self.fail(f"unknown tagged value in {where}: {sorted(value)}")
        return {key: self.value(v, f"{where}[{key!r}]") for key, v in value.items()}

    def array(self, member, where: str) -> np.ndarray:
        if not isinstance(member, str) or not _ARRAY_MEMBER.match(member):
            self.fail(f"bad array reference in {where}: {member!r}")
        if member in self.referenced:
            self.fail(f"array {member} is referenced twice ({where})")
        try:
            data = _read_member(self.archive, member, MAX_MEMBER_BYTES)
        except KeyError:
            self.fail(f"array {member} of {where} is missing")
        self.referenced.add(member)
        try:
            array = np.load(io.BytesIO(data), allow_pickle=False)
        except (ValueError, EOFError, OSError) as error:
            self.fail(f"array {member} of {where} cannot be read: {error}")
        if not isinstance(array, np.ndarray) or array.dtype.kind not in _ARRAY_KINDS or array.dtype.fields:
            self.fail(f"array {member} of {where} has dtype {getattr(array, 'dtype', type(array).__name__)}; "
                      "model files hold numbers, booleans and text only")
        return array


def _read_member(archive: zipfile.ZipFile, name: str, limit: int) -> bytes:
    """A member's bytes, reading at most ``limit`` (a member whose real size exceeds its header is refused)."""
    with archive.open(name) as stream:
        data = stream.read(limit + 1)
    if len(data) > limit:
        raise ModelFileError(f"{archive.filename}: member {name} holds more than {limit} bytes")
    return data


def _check_members(archive: zipfile.ZipFile, path: Path) -> None:
    """Refuse a ZIP whose members a model file does not have, or whose declared sizes are out of bounds."""
    infos = archive.infolist()
    if len(infos) > MAX_MEMBERS:
        raise ModelFileError(f"{path}: {len(infos)} members; a model file has at most {MAX_MEMBERS}")
    names = [info.filename for info in infos]
    if _JSON_MEMBER not in names:
        raise ModelFileError(f"{path}: not a greybox model file ({_JSON_MEMBER} missing)")
    if len(set(names)) != len(names):
        twice = sorted({name for name in names if names.count(name) > 1})
        raise ModelFileError(f"{path}: the member {twice[0]!r} is stored twice")
    for info in infos:
        if info.filename not in (_JSON_MEMBER, DIGEST_MEMBER) and not _ARRAY_MEMBER.match(info.filename):
            raise ModelFileError(f"{path}: unexpected member {info.filename!r} (a model file holds {_JSON_MEMBER} "
                                 f"and {_ARRAY_DIR}NNN_name.npy only)")
        limit = MAX_JSON_BYTES if info.filename == _JSON_MEMBER else MAX_MEMBER_BYTES
        if info.file_size > limit:
            raise ModelFileError(f"{path}: member {info.filename} declares {info.file_size} bytes, more than the "
                                 f"{limit} a model file may hold")
        if info.file_size > (1 << 20) and info.file_size > MAX_COMPRESSION_RATIO * max(info.compress_size, 1):
            ratio = info.file_size // max(info.compress_size, 1)
            raise ModelFileError(f"{path}: member {info.filename} expands {ratio} times (a ZIP bomb?); refused")
    total = sum(info.file_size for info in infos)
    if total > MAX_TOTAL_BYTES:
        raise ModelFileError(f"{path}: members of {total} bytes in all, more than {MAX_TOTAL_BYTES}")


def check_format(document, path, *, name: str, newest: int, what: str) -> int:
    """The format version of a greybox document (a model file's ``model.json``, a machine manifest), checked.

    Parameters
    ----------
    document : object
        The parsed JSON document.
    path : path-like
        Its file, named in the messages.
    name : str
        The ``format`` it must have.
    newest : int
        The newest ``format_version`` this greybox reads.
    what : str
        What the document is, in the messages (``"model file"``, ``"machine manifest"``).

    Returns
    -------
    int
        The format version, from 1 to ``newest``.

    Raises
    ------
    ModelFileError
        For another format, an invalid version, or one written by a newer greybox.
    """
    if not isinstance(document, dict) or document.get("format") != name:
        raise ModelFileError(f"{path}: not a greybox {what} (format is not {name!r})")
    version = document.get("format_version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise ModelFileError(f"{path}: invalid format version {version!r}")
    if version > newest:
        raise ModelFileError(f"{path}: {what} format version {version} was written by a newer greybox "
                             f"({document.get('greybox_version', 'unknown version')}); this greybox reads versions "
                             f"up to {newest}: upgrade greybox")
    return version


def load_model(path: str | PathLike, *, records: bool = False, key: bytes | None = None):
    """Load a model saved by :func:`save_model`.

    Parameters
    ----------
    path : str or path-like
        Model file.
    records : bool, default False
        Also return the file's records (checked; ``{}`` for a file without any).
    key : bytes, optional
        The plant's key the file must be signed with; default :func:`model_key` (unset: the signature is
        not checked, the digest is).

    Returns
    -------
    estimator or (estimator, dict)
        A new instance of the saved model's class with its parameters and
        learned attributes restored; it predicts exactly what the saved one did. Its training record,
        where the file holds one, is its ``training_record_`` again.
        With ``records``, the model and ``{name: record}``.

    Raises
    ------
    ModelFileError
        If the file is missing, not a greybox model file, of a newer format
        version, of a model kind this greybox does not know, damaged, changed
        since it was written (:data:`DIGEST_MEMBER`) or not signed with the plant's key.
    """
    path = Path(path)
    if path.is_dir():
        hint = (" holding a machine model (one model file per axis): give one axis's file, e.g. "
                f"{path / '<axis>.gbm'}, and the log's axis with --axis" if (path / "machine.json").is_file() else "")
        raise ModelFileError(f"{path}: is a directory{hint}; expected a model file")
    if not path.is_file():
        raise ModelFileError(f"{path}: no such model file")
    try:
        with zipfile.ZipFile(path) as archive:
            _check_members(archive, path)
            _check_digest(archive, path, model_key() if key is None else key)
            try:
                document = json.loads(_read_member(archive, _JSON_MEMBER, MAX_JSON_BYTES).decode("utf-8"))
            except KeyError:
                raise ModelFileError(f"{path}: not a greybox model file ({_JSON_MEMBER} missing)") from None
            except GreyboxError:
                raise
            except (UnicodeDecodeError, ValueError, RecursionError) as error:  # ValueError: also too long a number
                raise ModelFileError(f"{path}: {_JSON_MEMBER} is not valid JSON: {error}") from None
            version = check_format(document, path, name=FORMAT_NAME, newest=FORMAT_VERSION, what="model file")
            held = _checked_records(document.get("records"), path, "load")
            decoder = _Decoder(path, archive, version)
            try:
                model = decoder.estimator(document.get("model"), "model")
            except GreyboxError:
                raise
            except RecursionError:
                raise ModelFileError(f"{path}: values nested too deeply") from None
            except (TypeError, ValueError) as error:  # the class refused a parameter value
                raise ModelFileError(f"{path}: a parameter of the model is malformed: {error}") from None
            unused = sorted(set(archive.namelist()) - {_JSON_MEMBER, DIGEST_MEMBER} - decoder.referenced)
    except (zipfile.BadZipFile, zlib.error, EOFError, RuntimeError, NotImplementedError) as error:
        # a flipped bit in a ZIP header may also read as "encrypted" or "unsupported compression"
        if zipfile.is_zipfile(path):
            raise ModelFileError(f"{path}: damaged model file (a ZIP archive whose content does not check out: "
                                 f"{error})") from None
        raise ModelFileError(f"{path}: not a greybox model file (not a ZIP archive)") from None
    except (zipfile.LargeZipFile, OSError) as error:
        raise ModelFileError(f"{path}: cannot read model file: {error}") from None
    if any(name.endswith("_") and not name.startswith("_") for name in vars(model)):  # fitted: check it works
        try:
            check_fitted(model)
        except GreyboxError as error:
            raise ModelFileError(f"{path}: invalid {type(model).__name__} in the model file: {error}") from None
    if unused:
        raise ModelFileError(f"{path}: member {unused[0]} is not part of the model (no value refers to it)")
    if TRAINING_RECORD in held:
        setattr(model, TRAINING_ATTRIBUTE, held[TRAINING_RECORD])
    return (model, held) if records else model


# ------------------------------------------------------------------- checking
def check_fitted(model) -> None:
    """Check that a model's learned state is complete and usable, as one read from a file must be.

    Checks the hyperparameters, the records of the learned state (kind of axis, effort unit,
    selection, notes, intervals, sample time), that every identified parameter is finite and of a
    plausible magnitude, and predicts a short probe run (a reversal and a dwell at the fitted sample
    time) at once and in two chunks.

    The probe simulation is needed, not a formality: a model file holds the learned state of a
    dynamic model (element states, support vectors, effect shapes) that no table of parameters
    shows in full, so a file whose numbers are each finite can still predict non-finite values, or
    predict differently chunk by chunk (``greybox predict`` streaming a log) than at once. Running
    200 samples finds such a file at load, with the file's name, instead of midway through a log.

    Parameters
    ----------
    model : CurrentModel
        A fitted model (:class:`greybox.models.estimator.CurrentModel`).

    Raises
    ------
    ParameterError
        Naming the missing or malformed learned attribute, a parameter that is not finite or
        beyond :data:`~greybox.models.estimator.MAX_PARAMETER_MAGNITUDE`, the invalid hyperparameter, or the
        error the probe prediction gave.
    """
    model._check_params()  # the model's own hyperparameter check, as fit runs it first
    check_inertia(model.inertia)
    try:
        check_is_fitted(model)
        motion = getattr(model, "motion_", "linear")
        if motion not in MOTIONS:
            raise ParameterError(f"motion_ must be one of {', '.join(MOTIONS)}, got {motion!r}")
        if model.effort_unit_ not in MOTIONS[motion].effort_units:
            raise ParameterError(f"effort_unit_ of a {motion} axis must be one of "
                                 f"{MOTIONS[motion].effort_units}, got {model.effort_unit_!r}")
        for row in model.parameter_table():
            values = np.asarray(row.value, dtype=float)
            if not np.all(np.isfinite(values)):
                raise ParameterError(f"parameter {row.name} is not finite: {row.value!r}")
            if values.size and np.max(np.abs(values)) > MAX_PARAMETER_MAGNITUDE:
                raise ParameterError(f"parameter {row.name} = {np.max(np.abs(values)):.3g} in magnitude, beyond "
                                     f"{MAX_PARAMETER_MAGNITUDE:g}: not a model of a feed axis")
        record = getattr(model, "selection_", None)  # only a model chosen by cross-validation has one
        if record is not None:
            check_selection_record(record)
        notes = getattr(model, "notes_", [])
        if not (isinstance(notes, list) and all(isinstance(note, str) and len(note) <= 2000 for note in notes)):
            raise ParameterError("notes_ must be a list of sentences (text of at most 2000 characters each)")
        check_intervals(model)
        step = float(model.sample_time_)
        if not (np.isfinite(step) and step > 0.0):
            raise ParameterError(f"sample_time_ must be a positive number of seconds, got {step!r}")
        probe = _probe_run(step, model.effort_unit_, motion)
        whole = model.predict(probe)
        first, state = model.predict_chunk(probe.select(slice(0, 50)), sample_time=step)
        second, _ = model.predict_chunk(probe.select(slice(50, None)), state, sample_time=step)
        if whole.shape != (len(probe),) or not np.all(np.isfinite(whole)):
            raise ParameterError("the prediction of a probe run is not finite")
        if not np.allclose(np.concatenate((first, second)), whole, rtol=0, atol=1e-9 * (1 + np.abs(whole).max())):
            raise ParameterError("chunked and one-shot prediction of a probe run differ")
    except AttributeError as error:
        missing = getattr(error, "name", None)  # the attribute's name; else Python's message
        raise ParameterError(f"a learned attribute is missing: {missing or error}") from None
    except (TypeError, ValueError, IndexError, KeyError) as error:
        if isinstance(error, ParameterError):
            raise
        raise ParameterError(f"a learned attribute is malformed: {error}") from None


def _probe_run(sample_time: float, effort_unit: str, motion: str) -> AxisLog:
    """A short prepared run with a reversal and a dwell: 200 samples at ``sample_time`` [s]."""
    n = 200
    time = np.arange(n) * sample_time
    phase = np.linspace(0.0, 2.0 * np.pi, n)
    velocity = 10.0 * np.sin(phase)
    velocity[150:] = 0.0
    position = np.concatenate(([0.0], np.cumsum(velocity[:-1] * sample_time)))
    acceleration = np.gradient(velocity, sample_time)
    return AxisLog(time=time, position=position, effort=np.zeros(n), velocity=velocity,
                   acceleration=acceleration, effort_unit=effort_unit, motion=motion)
