"""Where a report's figures were measured, and how a model was made.

:func:`provenance`: greybox and library versions, Python, machine, cores.
:func:`training_record`: the training files (name, size, SHA-256), their preparation, the training
errors and ranges, stored in every model file :mod:`greybox.models.files` writes for ``greybox train``.

Every report greybox writes records this, so a figure can be traced to the
versions and the machine that printed it (results of the Bayesian search and
of libsvm may move with library versions; timings move with the core count).
"""

from __future__ import annotations

import math
import os
import platform
import sys
from importlib import metadata

from .data.effort import EFFORT_UNITS
from .data.operating import check_operating_record

__all__ = ["LIBRARIES", "provenance", "provenance_line", "TRAINING_RECORD", "TRAINING_ATTRIBUTE", "PREPARATION_KEYS",
           "file_identity", "file_sha256",
           "axis_warning", "training_file_warning", "training_record", "check_training_record",
           "preparation_differences", "model_quantity"]

#: Libraries whose versions can move a figure or a timing.
LIBRARIES = ("numpy", "scipy", "scikit-learn", "scikit-optimize", "pandas", "numba", "matplotlib", "pyarrow", "mcap")


def _version(distribution: str) -> str:
    try:
        return metadata.version(distribution)
    except metadata.PackageNotFoundError:
        return "not installed"


def provenance() -> dict:
    """Versions and machine of this run, JSON-ready.

    Returns
    -------
    dict
        ``greybox`` (version), ``python``, ``platform`` (OS and machine),
        ``cpu_count`` (logical cores usable by this process) and ``libraries``
        (distribution name -> version).
    """
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cores = os.cpu_count() or 1
    return {
        "greybox": _version("greybox"),
        "python": sys.version.split()[0],
        "platform": f"{platform.system()} {platform.release()} {platform.machine()}",
        "cpu_count": cores,
        "libraries": {name: _version(name) for name in LIBRARIES},
    }


def provenance_line(info: dict | None = None) -> str:
    """One line for text and Markdown reports.

    For example ``greybox 0.1.0, Python 3.11.7, Linux 6.1 x86_64, 2 cores; numpy 2.4.6, ...``.

    Parameters
    ----------
    info : dict, optional
        What :func:`provenance` returns; default measured now.
    """
    info = provenance() if info is None else info
    libraries = ", ".join(f"{name} {version}" for name, version in info["libraries"].items())
    return (f"greybox {info['greybox']}, Python {info['python']}, {info['platform']}, {info['cpu_count']} cores; "
            f"{libraries}")


# ------------------------------------------------------------------ how a model was made
#: Name of the training record in a model file's records (:func:`greybox.models.files.save_model`).
TRAINING_RECORD = "training"
#: The learned attribute a trained model keeps its training record in (:func:`greybox.train.record_training`);
#: :mod:`greybox.models.files` writes it as the file's :data:`TRAINING_RECORD` and sets it again on loading.
TRAINING_ATTRIBUTE = "training_record_"
#: Version of the training record's layout.
TRAINING_RECORD_VERSION = 1
#: Keys of the training record's ``preparation``: the options that change what a model sees of a log.
PREPARATION_KEYS = ("sample_time_s", "cutoff_hz", "resample_s", "max_gap_steps", "time_tolerance", "derived")
#: Relative difference of a sample time or cut-off that counts as a different preparation.
PREPARATION_TOLERANCE = 0.01
#: What a training record's effort may be (``training_error.quantity``).
EFFORT_QUANTITY_NAMES = tuple(EFFORT_UNITS)
_HEX = frozenset("0123456789abcdef")
_MAX_FILES = 10_000


def file_sha256(path: str | os.PathLike) -> str:
    """SHA-256 of a file's bytes (hex), read block by block.

    Parameters
    ----------
    path : str or path-like
        An existing file.
    """
    import hashlib

    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def file_identity(path) -> dict:
    """Name, size and SHA-256 of a file, to tell later whether a log is the one a model was trained on.

    Parameters
    ----------
    path : str or path-like
        The file.

    Returns
    -------
    dict
        ``name`` (the file name without folders), ``bytes`` and ``sha256`` (hex digest of the content).
    """
    return {"name": os.path.basename(os.fspath(path)), "bytes": os.path.getsize(path), "sha256": file_sha256(path)}


def training_record(files, preparation: dict, runs, total: dict, ranges: dict, axis: str | None = None,
                    operating: dict | None = None) -> dict:
    """The record of how a model was made, checked (:func:`check_training_record`), JSON-ready.

    Parameters
    ----------
    files : list of dict
        :func:`file_identity` of every training log.
    preparation : dict
        The preparation of the training runs, keys :data:`PREPARATION_KEYS`: the runs' sample time [s],
        the derivative filter's cut-off [Hz] (the one used, default or given), ``resample_s`` [s] or None,
        ``max_gap_steps``, ``time_tolerance`` (fraction) and ``derived`` (channels derived from the position).
    runs : list of dict
        Per training run: ``name``, ``samples``, ``rmse`` (in the effort unit) and ``re_percent``.
    total : dict
        The same figures over all runs, ``unit`` (the effort unit) and ``quantity`` (what the effort is:
        one of :data:`EFFORT_QUANTITY_NAMES`; optional, files written before it lack it).
    ranges : dict
        ``{channel: [low, high]}`` of the training runs (position, velocity, acceleration in the log's units).
    axis : str, optional
        The axis the training logs name (``"axis"``, left out when they name none).
    operating : dict, optional
        The operating region of the training runs (:func:`greybox.data.operating.operating_record`).

    Returns
    -------
    dict
        ``{"version", "greybox", "files", "preparation", "runs", "training_error", "ranges"}`` and
        ``"axis"`` and ``"operating"`` where known: the same
        logs and options give the same record (no time stamps, no output name), so a model file stays
        reproducible byte for byte.
    """
    record = {"version": TRAINING_RECORD_VERSION, "greybox": _version("greybox"),
              "files": list(files), "preparation": dict(preparation), "runs": list(runs),
              "training_error": dict(total), "ranges": {name: list(pair) for name, pair in ranges.items()}}
    if axis is not None:
        record["axis"] = str(axis)
    if operating is not None:
        record["operating"] = operating
    return check_training_record(record)


def _number(value, where: str, *, optional: bool = False, positive: bool = False):
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{where} must be a finite number, got {value!r}")
    if positive and value <= 0:
        raise ValueError(f"{where} must be positive, got {value!r}")
    return value


def _text(value, where: str, limit: int = 4096) -> str:
    if not isinstance(value, str) or len(value) > limit:
        raise ValueError(f"{where} must be text of at most {limit} characters")
    return value


def check_training_record(record) -> dict:
    """Check a training record's layout and values (a model file is never trusted); return it.

    Parameters
    ----------
    record : object
        The record as read from a model file.

    Returns
    -------
    dict
        The same record.

    Raises
    ------
    ValueError
        Naming the first key that is missing, of the wrong type or out of range.
    """
    if not isinstance(record, dict):
        raise ValueError("the record must be an object")
    expected = {"version", "greybox", "files", "preparation", "runs", "training_error", "ranges"}
    if set(record) - {"axis", "operating"} != expected:  # "axis", "operating": files since they were recorded
        raise ValueError(f"the record must hold exactly {', '.join(sorted(expected))} (and axis, operating)")
    if "operating" in record:
        check_operating_record(record["operating"])
    if "axis" in record:
        _text(record["axis"], "axis", 256)
    if record["version"] != TRAINING_RECORD_VERSION:
        raise ValueError(f"version {record['version']!r} is not {TRAINING_RECORD_VERSION}")
    _text(record["greybox"], "greybox")
    files = record["files"]
    if not isinstance(files, list) or len(files) > _MAX_FILES:
        raise ValueError(f"files must be a list of at most {_MAX_FILES}")
    for k, entry in enumerate(files):
        if not isinstance(entry, dict) or set(entry) != {"name", "bytes", "sha256"}:
            raise ValueError(f"files[{k}] must hold name, bytes and sha256")
        _text(entry["name"], f"files[{k}].name", 1024)
        if isinstance(entry["bytes"], bool) or not isinstance(entry["bytes"], int) or entry["bytes"] < 0:
            raise ValueError(f"files[{k}].bytes must be a non-negative integer")
        digest = entry["sha256"]
        if not isinstance(digest, str) or len(digest) != 64 or not set(digest) <= _HEX:
            raise ValueError(f"files[{k}].sha256 must be 64 hex digits")
    preparation = record["preparation"]
    if not isinstance(preparation, dict) or set(preparation) != set(PREPARATION_KEYS):
        raise ValueError(f"preparation must hold exactly {', '.join(PREPARATION_KEYS)}")
    _number(preparation["sample_time_s"], "preparation.sample_time_s", positive=True)
    _number(preparation["cutoff_hz"], "preparation.cutoff_hz", optional=True, positive=True)
    _number(preparation["resample_s"], "preparation.resample_s", optional=True, positive=True)
    _number(preparation["max_gap_steps"], "preparation.max_gap_steps", positive=True)
    _number(preparation["time_tolerance"], "preparation.time_tolerance", positive=True)
    derived = preparation["derived"]
    if not isinstance(derived, list) or not all(name in ("velocity", "acceleration") for name in derived):
        raise ValueError("preparation.derived must list velocity and/or acceleration")
    runs = record["runs"]
    if not isinstance(runs, list) or len(runs) > _MAX_FILES:
        raise ValueError(f"runs must be a list of at most {_MAX_FILES}")
    for k, entry in enumerate([*runs, record["training_error"]]):
        where = f"runs[{k}]" if k < len(runs) else "training_error"
        keys = {"name", "samples", "rmse", "re_percent"} if k < len(runs) else {"samples", "rmse", "re_percent",
                                                                                 "unit"}
        if k == len(runs) and isinstance(entry, dict) and "quantity" in entry:  # files since the effort's quantity
            keys = keys | {"quantity"}
            if entry["quantity"] not in EFFORT_QUANTITY_NAMES:
                raise ValueError(f"training_error.quantity must be one of {', '.join(EFFORT_QUANTITY_NAMES)}")
        if not isinstance(entry, dict) or set(entry) != keys:
            raise ValueError(f"{where} must hold {', '.join(sorted(keys))}")
        _text(entry.get("name", entry.get("unit")), f"{where}.{'name' if k < len(runs) else 'unit'}", 1024)
        if isinstance(entry["samples"], bool) or not isinstance(entry["samples"], int) or entry["samples"] < 0:
            raise ValueError(f"{where}.samples must be a non-negative integer")
        _number(entry["rmse"], f"{where}.rmse")
        _number(entry["re_percent"], f"{where}.re_percent", optional=True)
    ranges = record["ranges"]
    if not isinstance(ranges, dict) or not set(ranges) <= {"position", "velocity", "acceleration"}:
        raise ValueError("ranges must be an object of position, velocity and acceleration")
    for name, pair in ranges.items():
        if not isinstance(pair, list) or len(pair) != 2:
            raise ValueError(f"ranges.{name} must be [low, high]")
        low, high = (_number(value, f"ranges.{name}") for value in pair)
        if low > high:
            raise ValueError(f"ranges.{name} has low {low} above high {high}")
    return record


def preparation_differences(trained: dict, used: dict) -> list[str]:
    """How a log's preparation differs from the training logs' (empty when it does not).

    Parameters
    ----------
    trained : dict
        ``preparation`` of the model's training record.
    used : dict
        The same keys for the log at hand (:data:`PREPARATION_KEYS`).

    Returns
    -------
    list of str
        One phrase per difference, e.g. ``"cut-off 20 Hz (training 50 Hz; --cutoff-hz 50)"``.
    """
    differences = []

    def differs(a, b) -> bool:
        if a is None or b is None:
            return a is not b
        return abs(a - b) > PREPARATION_TOLERANCE * max(abs(a), abs(b))

    if differs(used["cutoff_hz"], trained["cutoff_hz"]):
        differences.append(f"derivative cut-off {used['cutoff_hz']:g} Hz (training {trained['cutoff_hz']:g} Hz; "
                           f"--cutoff-hz {trained['cutoff_hz']:g})")
    if differs(used["sample_time_s"], trained["sample_time_s"]):
        option = (f"--resample {trained['sample_time_s']:g}" if trained["resample_s"] is None
                  else f"--resample {trained['resample_s']:g}")
        differences.append(f"sample time {used['sample_time_s'] * 1e3:g} ms (training "
                           f"{trained['sample_time_s'] * 1e3:g} ms; {option})")
    elif differs(used["resample_s"], trained["resample_s"]):
        now, then = (f"--resample {value:g}" if value is not None else "no --resample"
                     for value in (used["resample_s"], trained["resample_s"]))
        differences.append(f"{now} (training {then})")
    if sorted(used["derived"]) != sorted(trained["derived"]):
        shown = ", ".join(used["derived"]) or "nothing"
        differences.append(f"derived {shown} (training derived {', '.join(trained['derived']) or 'nothing'}: a "
                           "logged velocity in one and not the other)")
    return differences


def preparation_of(runs, read) -> dict:
    """The preparation of prepared ``runs`` read with the options ``read``: :data:`PREPARATION_KEYS`.

    Parameters
    ----------
    runs : list of AxisLog
        The prepared runs; the first gives the sample time [s] and the derivative filter's cut-off [Hz].
    read : mapping
        Options of reading and preparing (:func:`greybox.data.reading.read_prepared`): ``resample`` [s],
        ``max_gap`` [steps], ``time_tolerance`` (fraction of the step); missing ones take their defaults.
    """
    from .data.prepare import MAX_GAP_STEPS

    filters = [run.attrs.get("derivative_filter") or {} for run in runs]
    cutoff = filters[0].get("cutoff_hz")
    return {"sample_time_s": float(runs[0].sample_time),
            "cutoff_hz": None if cutoff is None else float(cutoff),
            "resample_s": read.get("resample"),
            "max_gap_steps": float(read.get("max_gap", MAX_GAP_STEPS)),
            "time_tolerance": float(read.get("time_tolerance", 0.25)),
            "derived": sorted({name for entry in filters for name in entry.get("derived", ())})}


def axis_warning(records: dict, axis: str | None, log_name: str, model_name: str) -> str | None:
    """The ``warning:`` line when a log names another axis than the model's training logs did, else None.

    Parameters
    ----------
    records : dict
        The model file's records (a file without a training record, or one without its axis, warns of nothing).
    axis : str or None
        The axis the log names (None: it names none, nothing to compare).
    log_name, model_name : str
        Names for the message.
    """
    trained = (records.get(TRAINING_RECORD) or {}).get("axis")
    if trained is None or not axis or str(axis) == trained:
        return None
    return (f"warning: {log_name} is of axis {axis}, but {model_name} was trained on axis {trained}: another axis's "
            "friction and inertia; predict it with its own axis's model")


def training_file_warning(records: dict, path, model_name: str) -> str | None:
    """The ``warning:`` line when the file ``path`` is one of the model's training files (by SHA-256), else None.

    Parameters
    ----------
    records : dict
        The model file's records (a file without a training record warns of nothing).
    path : str or path-like
        A file given as held-out data (a calibration log).
    model_name : str
        Name of the model file, for the message.
    """
    record = records.get(TRAINING_RECORD)
    if record is None:
        return None
    digest = file_identity(path)["sha256"]
    trained = next((entry["name"] for entry in record["files"] if entry["sha256"] == digest), None)
    if trained is None:
        return None
    return (f"warning: calibration log {os.path.basename(os.fspath(path))} is the training file {trained} of "
            f"{model_name} (the same SHA-256): an interval calibrated on data the model was fitted to is too "
            "narrow; calibrate on air cuts the model was not trained on")


def preparation_warning(records: dict, read, runs, log_name: str, model_name: str) -> str | None:
    """The ``warning:`` line when ``runs`` are prepared otherwise than the model's training logs, else None.

    Parameters
    ----------
    records : dict
        The model file's records (a file without a training record warns of nothing).
    read : mapping
        Options of reading and preparing (:func:`preparation_of`; also ``cutoff_hz`` [Hz]).
    runs : list of AxisLog or None
        The prepared runs of the log; None when the log is streamed (then the options alone are compared,
        at the training logs' sample time).
    log_name, model_name : str
        Names for the message.
    """
    from .data.prepare import default_cutoff

    record = records.get(TRAINING_RECORD)
    if record is None:
        return None
    trained = record["preparation"]
    if runs is None:
        cutoff = read.get("cutoff_hz")
        cutoff = cutoff if cutoff is not None else default_cutoff(trained["sample_time_s"])
        used = {**trained, "cutoff_hz": float(cutoff), "resample_s": read.get("resample")}
    else:
        used = preparation_of(runs, read)
    differences = preparation_differences(trained, used)
    if not differences:
        return None
    return (f"warning: {log_name} is prepared otherwise than the training logs of {model_name}: "
            + "; ".join(differences))


def model_quantity(records: dict, model) -> str:
    """What the model's effort is (:func:`~greybox.data.effort.effort_quantity`), from its training record.

    A file without the record's ``quantity`` (written before it) is taken as fitted to a current, or to the
    load its effort unit names.

    Parameters
    ----------
    records : dict
        The model file's records.
    model : CurrentModel
        The fitted model (its ``effort_unit_`` and ``units_``).
    """
    quantity = (records.get(TRAINING_RECORD) or {}).get("training_error", {}).get("quantity")
    if quantity is not None:
        return quantity
    return "current" if model.effort_unit_ == "A" else model.units_.load
