"""greybox: grey-box motor-current models of machine-tool feed axes.

A Generalized Maxwell-Slip (GMS) friction model plus an SVR correction of its
position dependence estimate the friction and inertia share of a feed axis'
motor current from recorded axis logs, so that the rest can be attributed to
the cutting process.

Compiled kernels (numba, ``cache=True``) keep their cache in the user's cache
directory (``$XDG_CACHE_HOME/greybox/numba``, else ``~/.cache/greybox/numba``)
unless ``NUMBA_CACHE_DIR`` is set: a cache beside the installed sources would
outlive ``pip uninstall`` and leave a ``site-packages/greybox`` folder that
hides a later editable install.

:class:`AxisLog` is loaded when first named (``from greybox import AxisLog``),
so that importing greybox (and ``greybox --help``) loads no NumPy.
"""

import os as _os

_os.environ.setdefault("NUMBA_CACHE_DIR", _os.path.join(
    _os.environ.get("XDG_CACHE_HOME") or _os.path.join(_os.path.expanduser("~"), ".cache"), "greybox", "numba"))

from .errors import GreyboxError, LogError  # noqa: E402  (after the cache location, before numba is imported)

__version__ = "0.1.0"

__all__ = ["AxisLog", "GreyboxError", "LogError", "__version__"]


def __getattr__(name: str):
    """``greybox.AxisLog``, imported on first use (PEP 562)."""
    if name == "AxisLog":
        from .data.log import AxisLog

        return AxisLog
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    """The public names, :class:`AxisLog` included before it is loaded."""
    return sorted(set(globals()) | set(__all__))
