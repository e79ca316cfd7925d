"""Running greybox's commands as a page prints them, for the records of the pages' examples.

A page's example names its files relative to where the reader stands (``data/X_A.mcap``, ``x.gbm``); run
in a temporary folder that links the repository's ``data/`` and ``examples/``, the commands print what the
reader would see, with the same names.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

from .records import ROOT

__all__ = ["reader_folder", "run_greybox"]


@contextmanager
def reader_folder(prefix: str = "greybox-example-") -> Iterator[Path]:
    """A temporary folder holding links to the repository's ``data/`` and ``examples/``, removed afterwards.

    Parameters
    ----------
    prefix : str, default "greybox-example-"
        Prefix of the folder's name.

    Yields
    ------
    pathlib.Path
    """
    with tempfile.TemporaryDirectory(prefix=prefix) as folder:
        for name in ("data", "examples"):
            (Path(folder) / name).symlink_to(ROOT / name, target_is_directory=True)
        yield Path(folder)


def run_greybox(folder: Path, *args: str) -> list[str]:
    """Run ``greybox ARGS`` with this Python in ``folder``: its ``note:`` lines, then its standard output's lines.

    Parameters
    ----------
    folder : pathlib.Path
        Where the command runs.
    *args : str
        The command's arguments after ``greybox``.

    Returns
    -------
    list of str
        The non-empty lines; the progress lines on standard error are dropped.

    Raises
    ------
    SystemExit
        With one line naming the command, when it fails.
    """
    done = subprocess.run([sys.executable, "-m", "greybox", *args], cwd=folder, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"error: greybox {' '.join(args)} failed ({done.returncode}): {done.stderr.strip()}")
    notes = [line for line in done.stderr.splitlines() if line.startswith("note:")]
    return [line for line in [*notes, *done.stdout.splitlines()] if line.strip()]
