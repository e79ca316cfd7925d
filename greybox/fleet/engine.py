"""A plant's worth of logs on dask.distributed: the engine of every fleet run.

:func:`expand_logs` turns files, directories (searched recursively for log files) and glob patterns
into the list of logs. :func:`run_tasks` is the one engine of every fleet run (``greybox predict`` over
many logs in :mod:`greybox.fleet.predict`, ``greybox train --per-machine`` in :mod:`greybox.fleet.train`):
it runs one task per job on a Dask cluster, by default a local cluster of processes, one per core and one
thread each, or the cluster of a scheduler address, so that the same command runs on a laptop and on a
cluster; it skips the jobs complete from an earlier run, reports a job that fails and goes on, and writes
``OUT/_manifest.json``, saved while the fleet runs so that a re-run after a run that was killed skips what
is done. Every file is written atomically. :func:`fleet_summary` is the report of a finished fleet.
"""

from __future__ import annotations

import contextlib
import functools
import glob
import json
import os
import time
import unicodedata
import warnings
from pathlib import Path
from typing import Callable, Iterator, Sequence
from urllib.parse import quote, unquote

from ..atomic import write_text_atomic
from ..data.io import LOG_SUFFIXES
from ..errors import GreyboxError, Setting
from ..models.plant import MANIFEST, load_manifest, machine_of, read_manifest

__all__ = ["LOG_SUFFIXES", "MAX_NAME_BYTES", "SAVE_EVERY_S", "attempt", "check_machines", "check_names",
           "check_out_dir", "decode_name", "encode_name", "expand_logs", "fleet_summary", "log_names", "log_stamp",
           "out_dir_of", "run_tasks"]

#: Least time between two saves of the manifest while a fleet runs [s]: the jobs finished so far are kept
#: for a re-run when a run is killed.
SAVE_EVERY_S = 10.0

#: Longest name of one directory level most file systems take [bytes]: a partition ``log=<name>`` longer than
#: this cannot be written and is refused before a fleet run starts.
MAX_NAME_BYTES = 255

_GLOB_CHARACTERS = set("*?[")


def expand_logs(items: Sequence[str], *, exclude: Sequence[str | os.PathLike] = ()) -> list[Path]:
    """The log files named by files, directories (searched recursively) and glob patterns, each once.

    Directories and patterns yield the files with a log extension (:data:`LOG_SUFFIXES`), so that a CSV
    log's metadata sidecar or a manifest beside the logs is not taken for a log; they never yield a file
    inside a fleet run's output (a directory holding a :data:`MANIFEST`, or one of ``exclude``), so that an
    output directory inside the input tree is not read back as logs.

    Parameters
    ----------
    items : sequence of str
        Log files, directories and glob patterns (``**`` matches across directories).
    exclude : sequence of path-like, default ()
        Directories whose files are never logs (the run's own output directory).

    Returns
    -------
    list of pathlib.Path
        The logs, resolved to absolute paths, in the order found; a file named twice appears once.

    Raises
    ------
    GreyboxError
        For an item that names nothing, or no log at all.
    """
    excluded = [Path(path).resolve() for path in exclude]
    logs: list[Path] = []
    for item in items:
        if _GLOB_CHARACTERS & set(item):
            found = [Path(name) for name in sorted(glob.glob(item, recursive=True))
                     if Path(name).is_file() and Path(name).suffix.lower() in LOG_SUFFIXES
                     and not _in_output(Path(name), excluded)]
            if not found:
                raise GreyboxError(f"{item}: the pattern matches no log file ({', '.join(LOG_SUFFIXES)})")
            logs += found
        elif os.path.isdir(item):
            found = sorted(path for path in _walk(Path(item), excluded) if path.suffix.lower() in LOG_SUFFIXES
                           and not path.name.startswith("."))
            if not found:
                raise GreyboxError(f"{item}: no log file ({', '.join(LOG_SUFFIXES)}) in the directory")
            logs += found
        elif os.path.isfile(item):
            logs.append(Path(item))
        else:
            raise GreyboxError(f"{item}: no such log, directory or pattern")
    unique = list(dict.fromkeys(path.resolve() for path in logs))
    if not unique:
        raise GreyboxError("no log given")
    return unique


def _is_output(directory: Path, excluded: Sequence[Path]) -> bool:
    """Whether ``directory`` is a fleet run's output: one of ``excluded``, or holding a :data:`MANIFEST`."""
    return (directory / MANIFEST).is_file() or directory.resolve() in excluded


def _in_output(path: Path, excluded: Sequence[Path]) -> bool:
    """Whether the file ``path`` lies inside a fleet run's output directory (:func:`_is_output`)."""
    return any(_is_output(folder, excluded) for folder in path.absolute().parents)


def _walk(root: Path, excluded: Sequence[Path]) -> Iterator[Path]:
    """The files under ``root``, recursively, leaving out fleet outputs (:func:`_is_output`)."""
    if _in_output(root / "_", excluded):
        return
    for folder, subfolders, files in os.walk(root):
        subfolders[:] = sorted(name for name in subfolders if not _is_output(Path(folder) / name, excluded))
        for name in files:
            if os.path.isfile(os.path.join(folder, name)):
                yield Path(folder) / name


def log_names(logs: Sequence[str | os.PathLike]) -> list[str]:
    """Each log's path relative to the deepest folder holding them all (``/`` between folders), suffix kept.

    Distinct files get distinct names; with :func:`encode_name` they name a fleet's outputs.

    Parameters
    ----------
    logs : sequence of str or path-like
        Absolute paths of distinct log files (:func:`expand_logs`).
    """
    if not logs:
        return []
    root = os.path.commonpath([os.path.dirname(os.fspath(log)) for log in logs])
    return [Path(os.path.relpath(os.fspath(log), root)).as_posix() for log in logs]


def encode_name(name: str) -> str:
    """A name as a partition value, reversibly: every character but letters, digits and ``-_.~`` percent-encoded.

    ``pyarrow.dataset`` decodes the value when it reads a hive-partitioned dataset; :func:`decode_name`
    is the inverse. ``/`` becomes ``%2F``, so that a relative path is one directory level.

    Parameters
    ----------
    name : str
        Any name (a log's relative path, :func:`log_names`).
    """
    return quote(name, safe="")


def decode_name(value: str) -> str:
    """The name a partition value of :func:`encode_name` encodes.

    Parameters
    ----------
    value : str
        The value, as in the directory's name after ``log=``.
    """
    return unquote(value)


def check_names(logs: Sequence[str], names: Sequence[str]) -> None:
    """Refuse, before anything is written, output names a file system would merge or cannot hold.

    Distinct logs have distinct names (:func:`log_names`); a file system that ignores case or Unicode
    normalisation would still write two of them to one directory, and a name over :data:`MAX_NAME_BYTES`
    cannot be written at all.

    Parameters
    ----------
    logs : sequence of str
        The logs.
    names : sequence of str
        Their encoded names (:func:`encode_name`), in the same order.

    Raises
    ------
    GreyboxError
        Naming the log(s).
    """
    seen: dict[str, str] = {}
    for log, name in zip(logs, names):
        if len(f"log={name}".encode()) > MAX_NAME_BYTES:
            raise GreyboxError(f"{log}: its output name, the path relative to the folder of all logs, is longer "
                               f"than {MAX_NAME_BYTES} bytes once encoded; give logs of fewer folder levels")
        key = unicodedata.normalize("NFC", decode_name(name)).casefold()
        if key in seen:
            raise GreyboxError(f"{log}: its output would take the place of that of {seen[key]} on a file system "
                               "that ignores case; rename one of them")
        seen[key] = log


def check_machines(logs: Sequence[str | os.PathLike]) -> None:
    """Refuse logs whose different folder names give one machine name (:func:`machine_of`: ``run 1``, ``run_1``).

    Folders of one name in different places are one machine, by design; folders whose names differ only in
    the characters a partition value cannot hold would be merged without a word.

    Parameters
    ----------
    logs : sequence of str or path-like
        The logs of a fleet run.

    Raises
    ------
    GreyboxError
        Naming the two folders.
    """
    seen: dict[str, str] = {}
    for log in logs:
        folder = Path(log).parent.name
        name = machine_of(log)
        if seen.setdefault(name, folder) != folder:
            raise GreyboxError(f"{Path(log).parent}: the folders {seen[name]!r} and {folder!r} both give the machine "
                               f"name {name}; rename one of them (a machine name holds letters, digits, '-', '_', '.')")


def log_stamp(path: str | os.PathLike) -> dict:
    """``size`` [bytes] and ``mtime_ns`` [ns] of a file: a log changed since a run differs in one of them.

    Parameters
    ----------
    path : str or path-like
        An existing file.
    """
    stat = os.stat(path)
    return {"size": stat.st_size, "mtime_ns": stat.st_mtime_ns}


def attempt(label: str, work: Callable[[], dict]) -> dict:
    """Run one task's ``work`` on a worker and say how it went; never raises for bad input.

    Parameters
    ----------
    label : str
        What the task works on (e.g. the log file), named in the error of a failure that is a bug.
    work : callable
        ``work() -> dict``: does the task and returns the fields of its entry; a
        :class:`GreyboxError` it raises is reported as the failure.

    Returns
    -------
    dict
        ``status`` ``ok`` with what ``work`` returned, ``seconds`` and ``peak_rss_mb`` (of the worker
        process so far [MB]); or ``failed`` with ``error``, one line (a bug is named an internal
        error of ``label``), and ``seconds``; ``notes``, the first line of each warning ``work`` issued
        (once each), where it issued any: they are printed by :func:`fleet_summary`, not by the worker.
    """
    started = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:  # the worker's warnings go to the manifest, not its stderr
        warnings.simplefilter("default")
        try:
            result = work()
        except GreyboxError as error:
            result = {"status": "failed", "error": str(error)}
        except Exception as error:  # a bug, not bad input: reported in the manifest, the fleet goes on
            result = {"status": "failed", "error": f"{label}: internal error {type(error).__name__}: {error}"}
    notes = list(dict.fromkeys(str(item.message).splitlines()[0] for item in caught if str(item.message)))
    extra = {"notes": notes} if notes else {}
    if result.get("status") == "failed":
        return {**result, **extra, "seconds": time.perf_counter() - started}
    return {"status": "ok", **result, **extra, "seconds": time.perf_counter() - started,
            "peak_rss_mb": _peak_rss_mb()}


def _peak_rss_mb() -> float | None:
    """Peak resident memory of this (worker) process so far [MB]; None where the OS does not say.

    On Linux ``VmHWM`` of ``/proc/self/status``: ``ru_maxrss`` keeps across ``exec`` the peak of the
    process the worker was forked from (a large parent would be counted as the worker's own).
    """
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            return next(int(line.split()[1]) for line in status if line.startswith("VmHWM:")) / 1024.0
    except (OSError, StopIteration, ValueError, IndexError):
        pass
    try:
        import resource
    except ImportError:  # not on Windows
        return None
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / 1024.0 if os.uname().sysname != "Darwin" else peak / 2**20


def _canonical(value) -> str:
    return json.dumps(value, sort_keys=True)


def _complete(document: dict, items: str, out_dir: Path, fields: Sequence[str]) -> dict:
    """Entries of an earlier manifest a re-run may keep, by their ``fields``: ok, output still there."""
    kept = {}
    for entry in document.get(items, []):
        if isinstance(entry, dict) and entry.get("status") in ("ok", "skipped") and \
                isinstance(entry.get("output"), str) and (out_dir / entry["output"]).is_file():
            kept[_canonical({name: entry.get(name) for name in fields})] = entry
    return kept


def _versions() -> dict:
    from importlib.metadata import PackageNotFoundError, version

    out = {}
    for package in ("greybox", "numpy", "scipy", "scikit-learn", "numba", "pyarrow", "dask", "distributed"):
        try:
            out[package] = version(package)
        except PackageNotFoundError:
            out[package] = None
    return out


def run_tasks(task: Callable, jobs: Sequence, fingerprints: Sequence[dict], *, out_dir: str | os.PathLike,
              header: dict, items: str, scheduler: str | None = None, workers: int | None = None,
              force: bool = False, progress: Callable[[int, int, dict], None] | None = None) -> dict:
    """Run ``task(job)`` for every job not complete from an earlier run, on a Dask cluster; write the manifest.

    Parameters
    ----------
    task : callable
        Picklable function a worker runs, ``task(job) -> dict`` (an entry with ``status``, ``output``
        relative to ``out_dir`` or absolute, ...; see :func:`attempt`).
    jobs : sequence
        Picklable jobs.
    fingerprints : sequence of dict
        Per job, what makes its output current (its inputs' names, stamps, options), JSON values,
        the same keys for all jobs; merged into its entry. A job whose fingerprint matches an ``ok``
        entry of the earlier manifest, its output still there, is skipped.
    out_dir : path-like
        Output directory (created); the manifest is ``out_dir/_manifest.json``.
    header : dict
        First fields of the manifest; ``header["format"]`` names its format.
    items : str
        Name of the manifest's list of entries (``"logs"``, ``"models"``), in the order of ``jobs``.
    scheduler : str, optional
        Address of a running ``dask.distributed`` scheduler (``tcp://host:8786``); default a local
        cluster of ``workers`` processes, one thread each.
    workers : int, optional
        Processes of the local cluster (default: the machine's cores).
    force : bool, default False
        Run every job, whatever the earlier manifest says.
    progress : callable, optional
        ``progress(done, total, entry)`` after each job.

    While the jobs run, the manifest lists those finished, saved at most every :data:`SAVE_EVERY_S`
    seconds, so that a re-run after the run was killed skips them.

    Returns
    -------
    dict
        The manifest: ``header``, ``cluster``, ``versions``, ``seconds`` (wall time [s]), ``counts``
        per status and the entries.

    Raises
    ------
    GreyboxError
        When ``out_dir`` holds the manifest of another kind of fleet run, or the scheduler cannot be reached.
    """
    out_dir = Path(out_dir)
    other = load_manifest(out_dir).get("format", header["format"])
    if other != header["format"]:
        raise GreyboxError(f"{out_dir}: holds the {MANIFEST} of another kind of run ({other}); choose another "
                           "output directory")
    out_dir.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    fields = list(fingerprints[0]) if fingerprints else []
    previous = {} if force else _complete(read_manifest(out_dir, header["format"]), items, out_dir, fields)
    entries: list[dict | None] = [None] * len(jobs)
    done, saved = 0, time.perf_counter()

    def finish(index: int, entry: dict) -> None:
        nonlocal done, saved
        entries[index] = {**entry, **fingerprints[index]}
        done += 1
        if time.perf_counter() - saved >= SAVE_EVERY_S:  # a run killed later keeps what is done
            _write_manifest(out_dir, {**header, items: [entry for entry in entries if entry is not None]})
            saved = time.perf_counter()
        if progress is not None:
            progress(done, len(jobs), entries[index])

    todo = []
    for index, fingerprint in enumerate(fingerprints):
        kept = previous.get(_canonical(fingerprint))
        if kept is not None:
            finish(index, {**kept, "status": "skipped"})
        else:
            todo.append(index)
    cluster = _run_on_cluster(task, [(index, jobs[index]) for index in todo], scheduler, workers, finish)
    manifest = {**header, "cluster": cluster, "versions": _versions(), "seconds": time.perf_counter() - started,
                "counts": {status: sum(entry["status"] == status for entry in entries)
                           for status in ("ok", "skipped", "failed")},
                items: entries}
    _write_manifest(out_dir, manifest)
    return manifest


def _write_manifest(out_dir: Path, manifest: dict) -> None:
    """Write ``out_dir/_manifest.json`` atomically."""
    write_text_atomic(out_dir / MANIFEST, json.dumps(manifest, indent=1) + "\n")


def out_dir_of(jobs: Sequence, nothing: str) -> str:
    """The one output directory of a fleet's jobs (their ``out_dir``).

    Parameters
    ----------
    jobs : sequence
        Jobs with an ``out_dir`` attribute (:class:`greybox.fleet.predict.FleetJob`, or those of
        ``greybox train --per-machine``).
    nothing : str
        Error message for no job at all.

    Raises
    ------
    GreyboxError
        With the message ``nothing`` for no job, or for jobs that disagree.
    """
    if not jobs:
        raise GreyboxError(nothing)
    outs = {job.out_dir for job in jobs}
    if len(outs) != 1:
        raise GreyboxError("a fleet run has one output directory")
    return outs.pop()


def check_out_dir(out: str | os.PathLike, inputs=()) -> Path:
    """The output directory of a fleet run: a directory or a path not yet taken, none of the ``inputs``; resolved.

    Parameters
    ----------
    out : str or path-like
        The output directory asked for.
    inputs : iterable of str or path-like, default ()
        Input paths of the run; the output directory must not be one of them.

    Raises
    ------
    GreyboxError
        For a path that is a file or one of the inputs.
    """
    path = Path(out)
    if path.exists() and not path.is_dir():
        raise GreyboxError(f"{path}: exists and is not a directory; the output of a fleet run is a directory")
    if any(path.resolve() == Path(item).resolve() for item in inputs):
        raise GreyboxError(Setting("out", assign=False), f" {path}: is one of the inputs; choose another output "
                           "directory")
    return path.resolve()


def fleet_summary(manifest: dict, items: str, verb: str, describe: Callable[[dict], str]) -> tuple[list[str], int]:
    """The summary line of a finished fleet and a line per failed job; the exit status (2 if any job failed).

    Parameters
    ----------
    manifest : dict
        Written by :func:`run_tasks`.
    items : str
        Its list of entries (``"logs"``, ``"models"``), also the noun of the summary.
    verb : str
        What an ``ok`` job did (``"predicted"``, ``"trained"``).
    describe : callable
        The line of a failed entry.

    Returns
    -------
    (list of str, int)
        The lines and the exit status.
    """
    counts = manifest["counts"]
    cluster = manifest["cluster"]
    where = f" on {cluster['workers']} worker(s) of {cluster['scheduler']}" if cluster["workers"] else ""
    lines = [f"fleet: {counts['ok']} {verb}, {counts['skipped']} skipped (complete from an earlier run), "
             f"{counts['failed']} failed of {len(manifest[items])} {items} in {manifest['seconds']:.1f} s{where}"]
    lines += [f"  failed: {describe(entry)}" for entry in manifest[items] if entry["status"] == "failed"]
    lines += [f"  note: {_entry_label(entry)}: {note}" for entry in manifest[items] if entry["status"] != "skipped"
              for note in entry.get("notes", ())]
    return lines, 2 if counts["failed"] else 0


def _entry_label(entry: dict) -> str:
    """What a manifest entry is of: its log, or its machine (and axis)."""
    if entry.get("log"):
        return Path(entry["log"]).name
    return "/".join(str(entry[name]) for name in ("machine", "axis") if entry.get(name)) or "?"


@contextlib.contextmanager
def _client(scheduler: str | None, workers: int | None) -> Iterator:
    """A Dask client of the scheduler at ``scheduler``, or of a local cluster of ``workers`` processes."""
    import logging

    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="5s")
        except (OSError, TimeoutError) as error:
            raise GreyboxError(Setting("scheduler", assign=False), f" {scheduler}: cannot reach the Dask scheduler "
                                   f"({error})") from None
        cluster = None
    else:
        # one thread per worker process, compiled kernels included (each task runs them on one thread:
        # _on_one_thread): the processes share out the cores. NUMBA_NUM_THREADS is not set for the workers:
        # Dask sets such variables in a worker after it started, and a worker that had imported numba before
        # (a spawned worker imports the parent's main script) and launched its threads under the old value
        # failed at its next compilation ("Cannot set NUMBA_NUM_THREADS to a different value once the
        # threads have been launched"), depending on what numba's cache held
        cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.ERROR, env={"OMP_NUM_THREADS": "1"})
        client = Client(cluster)
    try:
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _on_one_thread(task: Callable, job):
    """``task(job)`` with the compiled kernels of this thread on one thread (numba's setting, not its variable)."""
    import numba

    numba.set_num_threads(1)
    return task(job)


def _run_on_cluster(task: Callable, todo: list, scheduler: str | None, workers: int | None,
                    finish: Callable[[int, dict], None]) -> dict:
    """Run ``task`` on every ``(index, job)`` of ``todo``; ``finish(index, entry)`` as each ends; the cluster."""
    if not todo:
        return {"scheduler": scheduler, "workers": 0}
    from distributed import as_completed

    with _client(scheduler, workers) as client:
        info = {"scheduler": scheduler or "local", "workers": len(client.scheduler_info().get("workers", {}))}
        # on a local cluster the kernels of a task run on one thread (the processes share out the cores)
        run = task if scheduler is not None else functools.partial(_on_one_thread, task)
        futures = client.map(run, [job for _, job in todo], pure=False)
        index = {future.key: position for future, (position, _) in zip(futures, todo)}
        jobs = {future.key: job for future, (_, job) in zip(futures, todo)}
        for future in as_completed(futures):
            error = future.exception() if future.status == "error" else None
            finish(index[future.key], future.result() if error is None else
                   {"status": "failed", "error": f"{_job_label(jobs[future.key])}: lost on the cluster (the worker "
                                                 f"running it died, e.g. out of memory or killed: "
                                                 f"{type(error).__name__})"})
        return info


def _job_label(job) -> str:
    """What a fleet job works on, for a message: its log, its file or its machine."""
    for name in ("log", "path", "machine"):
        value = getattr(job, name, None)
        if value:
            return str(value)
    return type(job).__name__
