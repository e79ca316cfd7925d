"""greybox: grey-box motor-current models of machine-tool feed axes.

A Generalized Maxwell-Slip (GMS) friction model plus an SVR correction of its
position dependence estimate the friction and inertia share of a feed axis'
motor current from recorded axis logs, so that the rest can be attributed to
the cutting process.
"""

from .data.log import AxisLog
from .errors import GreyboxError, LogError

__version__ = "0.1.0"

__all__ = ["AxisLog", "GreyboxError", "LogError", "__version__"]
