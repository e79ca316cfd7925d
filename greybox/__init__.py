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
"""

import os as _os

_os.environ.setdefault("NUMBA_CACHE_DIR", _os.path.join(
    _os.environ.get("XDG_CACHE_HOME") or _os.path.join(_os.path.expanduser("~"), ".cache"), "greybox", "numba"))

from .data.log import AxisLog  # noqa: E402  (after the cache location, before numba is imported)
from .errors import GreyboxError, LogError  # noqa: E402

__version__ = "0.1.0"

__all__ = ["AxisLog", "GreyboxError", "LogError", "__version__"]
