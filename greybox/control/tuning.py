"""One set of PID gains, tuned once by a standard rule and used for every feed-forward.

As in Tjahjowidodo et al. (2005), the feedback controller is the same for
all friction compensators, so that differences in tracking error come from
the feed-forward alone. The rule places the three closed-loop poles of the
rigid axis ``1 / (J s^2)`` under the ideal PID at ``-omega``:

    J s^3 + kd s^2 + kp s + ki = J (s + omega)^3
    =>  kd = 3 J omega,  kp = 3 J omega^2,  ki = J omega^3,

with the derivative filtered at ``Tf = 1 / (10 omega)``. The default
bandwidth ``omega = 0.1 / T`` (8 Hz at a 2 ms controller period) keeps the
sampled loop well damped: with the zero-order hold at ``T`` and the
filtered derivative, the least damped closed-loop pole of the rigid axis has
a damping ratio of about 0.5 (0.27 at ``omega = 0.2 / T``; the sampled loop
becomes unstable near ``omega = 0.38 / T``).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError
from .pid import PIDGains

__all__ = ["default_bandwidth_hz", "pole_placement_gains"]

#: Default ``omega T`` of :func:`default_bandwidth_hz`.
BANDWIDTH_TIMES_PERIOD = 0.1

#: Ratio of the derivative-filter corner to the bandwidth.
DERIVATIVE_FILTER_RATIO = 10.0


def default_bandwidth_hz(sample_time_s: float) -> float:
    """Default closed-loop bandwidth [Hz] for a controller period [s]: ``omega = 0.1 / T``.

    Parameters
    ----------
    sample_time_s : float
        Controller period ``T`` [s], > 0.

    Raises
    ------
    ParameterError
        If ``sample_time_s`` is not positive and finite.
    """
    if not (np.isfinite(sample_time_s) and sample_time_s > 0.0):
        raise ParameterError(f"controller period must be positive, got {sample_time_s} s")
    return BANDWIDTH_TIMES_PERIOD / sample_time_s / (2.0 * math.pi)


def pole_placement_gains(inertia_A_s2_mm: float, bandwidth_hz: float) -> PIDGains:
    """PID gains placing a triple closed-loop pole at ``-2 pi bandwidth_hz`` for the rigid axis.

    Parameters
    ----------
    inertia_A_s2_mm : float
        Inertia ``J`` [A s^2/mm] of the axis (current per acceleration).
    bandwidth_hz : float
        ``omega / (2 pi)`` [Hz].

    Returns
    -------
    PIDGains
        ``kp = 3 J omega^2`` [A/mm], ``ki = J omega^3`` [A/(mm s)],
        ``kd = 3 J omega`` [A s/mm], ``Tf = 1 / (10 omega)`` [s].
    """
    if not (np.isfinite(inertia_A_s2_mm) and inertia_A_s2_mm > 0.0):
        raise ParameterError(f"inertia must be positive to tune the loop, got {inertia_A_s2_mm} A s^2/mm")
    if not (np.isfinite(bandwidth_hz) and bandwidth_hz > 0.0):
        raise ParameterError(f"bandwidth must be positive, got {bandwidth_hz} Hz")
    omega = 2.0 * math.pi * bandwidth_hz
    j = float(inertia_A_s2_mm)
    return PIDGains(kp=3.0 * j * omega**2, ki=j * omega**3, kd=3.0 * j * omega,
                    derivative_filter_s=1.0 / (DERIVATIVE_FILTER_RATIO * omega))
