"""Seeded synthetic motion that exercises every branch of the friction models (stick, slip, reversals, rest),
for their tests and benchmarks (numpy only)."""

from __future__ import annotations

import numpy as np

from greybox.data.log import AxisLog

#: Sample time of the synthetic logs [s] (500 Hz, as SINUMERIK traces).
STEP = 0.002


def velocity_profile(duration: float, *, seed: int = 0, step: float = STEP, v_max: float = 100.0,
                     a_max: float = 2000.0) -> np.ndarray:
    """Velocity [mm/s] of an axis that holds random speeds and makes small back-and-forth moves.

    Random plateaus between 0.3 and ``v_max`` mm/s in both directions, reached
    with at most ``a_max`` mm/s^2, alternate with short sinusoidal oscillations
    of 0.005-0.1 mm amplitude (pre-sliding, inner reversal loops) and standstills.
    """
    rng = np.random.default_rng(seed)
    n = int(round(duration / step))
    pieces = []
    v_now = 0.0
    while sum(p.size for p in pieces) < n:
        kind = rng.choice(["plateau", "oscillation", "rest"], p=[0.6, 0.3, 0.1])
        if kind == "plateau":
            target = rng.choice([-1.0, 1.0]) * np.exp(rng.uniform(np.log(0.3), np.log(v_max)))
            ramp = max(int(np.ceil(abs(target - v_now) / (0.5 * a_max * step))), 2)
            shape = 0.5 - 0.5 * np.cos(np.linspace(0.0, np.pi, ramp))
            pieces.append(v_now + (target - v_now) * shape)
            pieces.append(np.full(int(rng.uniform(0.2, 1.0) / step), target))
            v_now = target
        else:
            ramp = max(int(np.ceil(abs(v_now) / (0.5 * a_max * step))), 2)
            pieces.append(v_now * (0.5 + 0.5 * np.cos(np.linspace(0.0, np.pi, ramp))))
            v_now = 0.0
            if kind == "rest":
                pieces.append(np.zeros(int(rng.uniform(0.05, 0.3) / step)))
            else:
                amplitude = np.exp(rng.uniform(np.log(0.005), np.log(0.1)))
                frequency = rng.uniform(0.5, 4.0)
                t = np.arange(int(rng.uniform(1.0, 3.0) * frequency) * int(1.0 / (frequency * step))) * step
                pieces.append(2 * np.pi * frequency * amplitude * np.sin(2 * np.pi * frequency * t))
    return np.concatenate(pieces)[:n]


def motion_log(velocity: np.ndarray, effort: np.ndarray | None = None, *, step: float = STEP,
               source: str = "synthetic.mcap", effort_unit: str = "A") -> AxisLog:
    """A prepared log of the given velocity [mm/s] (position integrated, acceleration differentiated)."""
    velocity = np.asarray(velocity, dtype=float)
    time = np.arange(velocity.size) * step
    position = np.concatenate(([0.0], np.cumsum(velocity[:-1]) * step))
    acceleration = np.gradient(velocity, step)
    effort = np.zeros_like(velocity) if effort is None else np.asarray(effort, dtype=float)
    return AxisLog(time=time, position=position, effort=effort, velocity=velocity,
                   acceleration=acceleration, effort_unit=effort_unit, source=source)
