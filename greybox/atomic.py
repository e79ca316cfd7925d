"""Atomic file output: nothing half-written is ever left under the target name.

Every file greybox writes (logs, model files, reports, figures) goes through
:func:`atomic_output`: the content is written to a temporary file in the target
directory, flushed, given the permissions a plain ``open`` would give, and
renamed over the target in one step. If writing fails, the temporary file is
removed and an existing file of that name is left untouched. The temporary file
is hidden and named after the target and the writing process
(``.<name>.<pid>-<random>.tmp``); one left by a process that was killed (SIGKILL
runs no clean-up) is removed by the next write of the same target once that
process is gone (:data:`STALE_AFTER_S`). An error of the operating system while
writing (a full disk, a read-only file system) names the target, not the
temporary file.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import stat
import time
from pathlib import Path
from typing import Iterator

from .errors import GreyboxError

__all__ = ["STALE_AFTER_S", "atomic_output", "check_output_path", "remove_stale_temporaries", "write_text_atomic",
           "write_bytes_atomic"]

#: Age [s] since its last change after which a temporary file of a process that is gone is removed; one of a
#: process still running (on this host) is kept, unless unchanged for a day (a writer on another host).
STALE_AFTER_S = 60.0
_DAY_S = 86400.0


def _default_mode() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path to write; on success it replaces ``path``.

    Parameters
    ----------
    path : path-like
        Final file name. Its directory must exist.

    Yields
    ------
    pathlib.Path
        Temporary file in the same directory (already created, empty). Write it
        by name; it is renamed to ``path`` when the block ends without error.

    Raises
    ------
    FileNotFoundError
        If the target directory does not exist.
    """
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise FileNotFoundError(f"{path}: directory {directory} does not exist")
    remove_stale_temporaries(path)
    temporary = None
    try:
        while temporary is None:
            # the name is known before the file exists: a Ctrl-C or SIGTERM (delivered to whichever thread,
            # so it cannot be held back) that stops the command from here on finds the file and removes it
            temporary = directory / f".{path.name}.{os.getpid()}-{secrets.token_hex(8)}.tmp"
            try:
                os.close(os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
            except FileExistsError:  # another file of that name (not ours): draw again
                temporary = None
        try:
            yield temporary
            with open(temporary, "rb+") as stream:
                os.fsync(stream.fileno())
            os.chmod(temporary, _default_mode())
            os.replace(temporary, path)
        except OSError as error:  # name the user's file, not our hidden one
            if error.filename is not None and os.fspath(error.filename) == os.fspath(temporary) and error.errno:
                raise OSError(error.errno, error.strerror, str(path)) from None
            raise
    finally:
        if temporary is not None and os.path.exists(temporary):
            os.unlink(temporary)


def _alive(pid: int) -> bool:
    """Whether a process of this id runs on this host (True where it cannot be told)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError, ValueError, OverflowError):  # another user's, or no such call (Windows)
        return True
    return True


def remove_stale_temporaries(path: str | os.PathLike) -> list[Path]:
    """Remove the temporary files of ``path`` that killed writers left; the files removed.

    A temporary file (``.<name>.<pid>-<random>.tmp`` beside ``path``) is stale when its process is gone and
    it has not changed for :data:`STALE_AFTER_S`, or has not changed for a day. Regular files only.

    Parameters
    ----------
    path : path-like
        The target file whose temporary files are looked for.
    """
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    prefix = f".{path.name}."
    removed = []
    try:
        names = [name for name in os.listdir(directory) if name.startswith(prefix) and name.endswith(".tmp")]
    except OSError:
        return removed
    now = time.time()
    for name in names:
        middle = name[len(prefix):-len(".tmp")]
        pid = middle.split("-", 1)[0]
        candidate = directory / name
        try:
            info = os.lstat(candidate)
        except OSError:
            continue
        age = now - info.st_mtime
        gone = pid.isdigit() and not _alive(int(pid))
        if stat.S_ISREG(info.st_mode) and ((gone and age > STALE_AFTER_S) or age > _DAY_S):
            try:
                os.unlink(candidate)
            except OSError:
                continue
            removed.append(candidate)
    return removed


def check_output_path(path: str | os.PathLike, *, overwrite: bool = False, protect=(),
                      error: type[GreyboxError] = GreyboxError,
                      inputs_name: str = "an input of this command") -> None:
    """Raise unless ``path`` may be written: refuse to overwrite without ``overwrite``, never replace an input.

    Parameters
    ----------
    path : path-like
        Output file.
    overwrite : bool, default False
        Whether an existing file may be replaced (the commands' ``--force``).
    protect : iterable of path-like
        Input files that must never be replaced, whatever ``overwrite``.
    error : type, default GreyboxError
        Error class raised (a :class:`GreyboxError` subclass).
    inputs_name : str, default "an input of this command"
        What the protected files are, for the message.

    Raises
    ------
    GreyboxError
        (of class ``error``) If ``path`` is a directory, its directory does
        not exist, it is one of ``protect``, or it exists and ``overwrite`` is false.
    """
    path = Path(path)
    if path.is_dir():
        raise error(f"{path}: is a directory")
    if not path.parent.is_dir():
        raise error(f"{path}: directory {path.parent} does not exist")
    if path.exists():
        for source in protect:
            if os.path.exists(source) and os.path.samefile(path, source):
                raise error(f"{path}: is {inputs_name}; refusing to overwrite it")
        if not overwrite:
            raise error(f"{path}: file exists; use --force to overwrite it")


def write_bytes_atomic(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically and return the path.

    Parameters
    ----------
    path : path-like
        Target file; its directory must exist. An existing file is replaced.
    data : bytes
        The complete file content.
    """
    with atomic_output(path) as temporary:
        temporary.write_bytes(data)
    return Path(path)


def write_text_atomic(path: str | os.PathLike, text: str) -> Path:
    """Write UTF-8 ``text`` to ``path`` atomically and return the path.

    Parameters
    ----------
    path : path-like
        Target file; its directory must exist. An existing file is replaced.
    text : str
        The complete file content, encoded as UTF-8.
    """
    return write_bytes_atomic(path, text.encode("utf-8"))
