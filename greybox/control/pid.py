"""Discrete PID position controller with a filtered derivative and anti-windup.

At every controller sample ``k`` (period ``T``), with the tracking error
``e[k] = r[k] - y[k]`` [mm] of the measured position ``y``:

    D[k] = Tf / (Tf + T) * D[k-1] + kd / (Tf + T) * (e[k] - e[k-1])
    u[k] = sat(u_ff[k] + kp e[k] + I[k] + D[k])
    I[k+1] = I[k] + ki T e[k]   unless u is saturated and e[k] drives it further

The derivative is ``kd s / (1 + Tf s)`` discretised by backward Euler (no
kick at the first sample: ``e[-1] = e[0]``); the integral is forward Euler
with conditional integration as anti-windup; ``sat`` clips the motor
current at +-``current_limit_A``. The measured position is the true one
rounded to the encoder resolution (:func:`measure`). :func:`pid_step` is the
compiled update the loop kernels call.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from ..errors import ParameterError

__all__ = ["PIDGains", "ControllerSettings", "measure", "pid_step"]


@dataclass(frozen=True)
class PIDGains:
    """Gains of the PID position controller (output: motor current).

    Parameters
    ----------
    kp : float
        Proportional gain [A/mm].
    ki : float
        Integral gain [A/(mm s)].
    kd : float
        Derivative gain [A s/mm].
    derivative_filter_s : float
        Time constant ``Tf`` [s] of the first-order derivative filter.
    """

    kp: float
    ki: float
    kd: float
    derivative_filter_s: float

    def __post_init__(self):
        for name in ("kp", "ki", "kd"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0.0):
                raise ParameterError(f"PID gain {name} must be finite and non-negative, got {value}")
        if not (np.isfinite(self.derivative_filter_s) and self.derivative_filter_s >= 0.0):
            raise ParameterError(f"derivative filter time constant must be non-negative, "
                                 f"got {self.derivative_filter_s} s")

    def to_dict(self) -> dict:
        """JSON-serialisable gains."""
        return asdict(self)


class ControllerSettings(NamedTuple):
    """The controller as the compiled loop kernels take it (see :meth:`from_gains`).

    Attributes
    ----------
    period_s : float
        Controller period ``T`` [s].
    kp : float
        Proportional gain [A/mm].
    ki_dt : float
        ``ki T`` [A/mm]: integral increment per unit error.
    derivative_decay : float
        ``Tf / (Tf + T)``.
    derivative_gain : float
        ``kd / (Tf + T)`` [A/mm].
    current_limit_A : float
        Saturation of the motor current [A].
    resolution_mm : float
        Position measurement resolution [mm] (0: exact measurement).
    """

    period_s: float
    kp: float
    ki_dt: float
    derivative_decay: float
    derivative_gain: float
    current_limit_A: float
    resolution_mm: float

    @classmethod
    def from_gains(cls, gains: PIDGains, period_s: float, current_limit_A: float,
                   resolution_mm: float) -> "ControllerSettings":
        """Discretise ``gains`` at the controller period ``period_s`` [s].

        Parameters
        ----------
        gains : PIDGains
            Continuous-time gains of the controller.
        period_s : float
            Controller period ``T`` [s], > 0.
        current_limit_A : float
            Saturation of the motor current [A], > 0.
        resolution_mm : float
            Position measurement resolution [mm], >= 0 (0: exact measurement).

        Raises
        ------
        ParameterError
            If the period, the current limit or the resolution is out of range.
        """
        if not (np.isfinite(period_s) and period_s > 0.0):
            raise ParameterError(f"controller period must be positive, got {period_s} s")
        if not (np.isfinite(current_limit_A) and current_limit_A > 0.0):
            raise ParameterError(f"current limit must be positive, got {current_limit_A} A")
        if not (np.isfinite(resolution_mm) and resolution_mm >= 0.0):
            raise ParameterError(f"position resolution must be non-negative, got {resolution_mm} mm")
        tf, dt = gains.derivative_filter_s, period_s
        return cls(float(dt), float(gains.kp), float(gains.ki * dt), float(tf / (tf + dt)),
                   float(gains.kd / (tf + dt)), float(current_limit_A), float(resolution_mm))


@njit(cache=True)
def measure(position_mm, resolution_mm):
    """Encoder reading of a position [mm]: rounded to the resolution (unchanged when it is 0).

    Parameters
    ----------
    position_mm : float
        True position [mm].
    resolution_mm : float
        Encoder resolution [mm]; 0 for an ideal encoder.
    """
    if resolution_mm > 0.0:
        return np.round(position_mm / resolution_mm) * resolution_mm
    return position_mm


@njit(cache=True)
def pid_step(memory, settings, error_mm, feedforward_A):
    """One controller sample: the saturated motor current [A]; updates ``memory`` in place.

    Parameters
    ----------
    memory : ndarray, shape (3,)
        Controller state: integral term [A], derivative term [A], previous error [mm].
        Start with ``(0, 0, e[0])``.
    settings : ControllerSettings
        Discretised controller.
    error_mm : float
        Tracking error of the measured position [mm].
    feedforward_A : float
        Feed-forward current [A].

    Returns
    -------
    float
        Motor current command [A], within +-``settings.current_limit_A``.
    """
    derivative = settings.derivative_decay * memory[1] + settings.derivative_gain * (error_mm - memory[2])
    demand = feedforward_A + settings.kp * error_mm + memory[0] + derivative
    limit = settings.current_limit_A
    current = min(max(demand, -limit), limit)
    winding_up = (demand > limit and error_mm > 0.0) or (demand < -limit and error_mm < 0.0)
    if not winding_up:
        memory[0] += settings.ki_dt * error_mm
    memory[1] = derivative
    memory[2] = error_mm
    return current
