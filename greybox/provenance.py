"""Where a report's figures were measured: greybox and library versions, Python, machine, cores.

Every report greybox writes records this, so a figure can be traced to the
versions and the machine that printed it (results of the Bayesian search and
of libsvm may move with library versions; timings move with the core count).
"""

from __future__ import annotations

import os
import platform
import sys
from importlib import metadata

__all__ = ["LIBRARIES", "provenance", "provenance_line"]

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
