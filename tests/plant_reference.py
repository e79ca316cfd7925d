"""Plain-Python plant laws and position loop, the references of the compiled ones.

Written from the equations (docs/friction-models.md, docs/compensate.md and
the twin's module doc), one element and one step at a time, without numba:

* :class:`GMSPlant`, :class:`LuGrePlant`, :class:`TwinPlant`: a friction law
  as a plant, ``friction(x, v)`` [A] of the present state and
  ``advance(v, h)`` over one internal step ``h`` [s] at the new velocity;
* :func:`python_loop`: the PID position loop around such a plant
  (semi-implicit Euler at the internal step).
"""

from __future__ import annotations

import math

import numpy as np


class GMSPlant:
    """GMS elements: stick until ``|z_i| = alpha_i s(v)``, then slip with ``alpha_i C (sgn v - z_i / s_i)``."""

    def __init__(self, alpha, k, sigma, s_0, s_inf, v_s, C, mu):
        self.alpha, self.k = [float(a) for a in alpha], [float(a) for a in k]
        self.sigma, self.s_0, self.s_inf, self.v_s, self.C, self.mu = sigma, s_0, s_inf, v_s, C, mu
        self.z = [0.0] * len(self.alpha)
        self.slipping = [0] * len(self.alpha)
        self.rate = 0.0

    @classmethod
    def of(cls, m):
        """The plant of a fitted GMSModel."""
        return cls(m.alpha_, m.k_, m.sigma_, m.s_0_, m.s_inf_, m.v_s_, m.slip_rate_, m.viscous_)

    def friction(self, x, v):
        return self.mu * v + self.sigma * self.rate + sum(k * z for k, z in zip(self.k, self.z))

    def advance(self, v, h):
        s = self.s_inf + (self.s_0 - self.s_inf) * math.exp(-abs(v) / self.v_s)
        d = int(v > 0) - int(v < 0)
        self.rate = 0.0
        for i, a in enumerate(self.alpha):
            z = self.z[i]
            if self.slipping[i] != d:
                self.slipping[i] = 0
            if self.slipping[i] == 0:
                new = z + v * h
                if d != 0 and d * new >= a * s:
                    self.slipping[i] = d
                    new = d * a * s if d * z < a * s else z + self.C * h * (a * d - z / s)
            else:
                new = z + self.C * h * (a * d - z / s)
            self.rate += a * (new - z) / h
            self.z[i] = new


class LuGrePlant:
    """LuGre bristles ``dz/dt = v - sigma0 |v| z / g(v)``, solved exactly over each step with ``v`` held.

    ``sigma2``, ``coulomb``, ``static`` and ``v_s`` are numbers or pairs (positive motion, negative motion).
    """

    def __init__(self, sigma0, sigma1, sigma2, coulomb, static, v_s):
        self.sigma0, self.sigma1 = sigma0, sigma1
        self.sigma2, self.coulomb, self.static, self.v_s = (tuple(np.broadcast_to(np.asarray(x, dtype=float), 2))
                                                            for x in (sigma2, coulomb, static, v_s))
        self.z, self.rate = 0.0, 0.0

    @classmethod
    def of(cls, m):
        """The plant of a fitted LuGreModel."""
        if m.asymmetric:
            return cls(m.sigma0_, m.sigma1_, (m.viscous_, m.viscous_neg_), (m.coulomb_, m.coulomb_neg_),
                       (m.static_, m.static_neg_), (m.v_s_, m.v_s_neg_))
        return cls(m.sigma0_, m.sigma1_, m.viscous_, m.coulomb_, m.static_, m.v_s_)

    def friction(self, x, v):
        return self.sigma0 * self.z + self.sigma1 * self.rate + self.sigma2[int(v < 0)] * v

    def advance(self, v, h):
        r = int(v < 0)
        g = self.coulomb[r] + (self.static[r] - self.coulomb[r]) * math.exp(-abs(v) / self.v_s[r])
        lam = self.sigma0 * abs(v) / g
        if lam > 0:
            new = self.z * math.exp(-lam * h) + v * (1 - math.exp(-lam * h)) / lam
        else:
            new = self.z + v * h
        self.rate = (new - self.z) / h
        self.z = new


class TwinPlant:
    """The twin's elasto-plastic elements with a lagged Stribeck ratio, viscous term, position factor and cogging."""

    def __init__(self, p, friction=True):
        scale = 1.0 if friction else 0.0
        self.p = p
        self.k = [scale * k for k in p.stiffness_A_mm]
        self.viscous = scale * p.viscous_A_s_mm
        self.cogging = scale * p.cogging_A
        self.D = list(p.breakaway_deflection_mm)
        self.d = [0.0] * len(self.k)
        self.level, self.elastic = 1.0, 0.0

    def friction(self, x, v):
        p = self.p
        u = (2 * x - p.travel_mm[0] - p.travel_mm[1]) / (p.travel_mm[1] - p.travel_mm[0])
        g = 1 + p.preload_gain * u**4 + p.tilt_gain * u + p.lead_gain * math.sin(
            2 * math.pi * x / p.lead_mm + p.lead_phase_rad)
        cogging = self.cogging * math.sin(2 * math.pi * x / p.cogging_period_mm + p.cogging_phase_rad)
        return g * self.elastic + self.viscous * v + cogging

    def advance(self, v, h):
        p = self.p
        target = p.coulomb_ratio + (1 - p.coulomb_ratio) * math.exp(-((abs(v) / p.stribeck_velocity_mm_s)
                                                                         ** p.stribeck_shape))
        decay = math.exp(-h / p.lag_time_s) if p.lag_time_s > 0 else 0.0
        self.level = target + (self.level - target) * decay
        self.elastic = 0.0
        for j in range(len(self.d)):
            self.d[j] = min(max(self.d[j] + v * h, -self.D[j] * self.level), self.D[j] * self.level)
            self.elastic += self.k[j] * self.d[j]


def python_pid(memory, s, error, feedforward):
    """The PID of greybox.control.pid, one controller sample."""
    derivative = s.derivative_decay * memory[1] + s.derivative_gain * (error - memory[2])
    demand = feedforward + s.kp * error + memory[0] + derivative
    current = min(max(demand, -s.current_limit_A), s.current_limit_A)
    if not ((demand > s.current_limit_A and error > 0) or (demand < -s.current_limit_A and error < 0)):
        memory[0] += s.ki_dt * error
    memory[1], memory[2] = derivative, error
    return current


def python_measure(x, resolution):
    return float(np.round(x / resolution) * resolution) if resolution > 0 else x


def python_loop(reference, feedforward, disturbance, s, periods, stride, step, plant, inertia, offset=0.0):
    """Position loop around ``plant``; rows: position, mean current, friction, saturated fraction."""
    n = reference.shape[0]
    out = np.empty((4, n))
    x, v = reference[0, 0], 0.0
    memory = [0.0, 0.0, reference[0, 0] - python_measure(x, s.resolution_mm)]
    for k in range(n):
        out[0, k], out[2, k] = x, plant.friction(x, v)
        total, saturated = 0.0, 0
        for j in range(periods):
            t = j * s.period_s
            target = reference[k, 0] + t * (reference[k, 1] + 0.5 * t * reference[k, 2])
            current = python_pid(memory, s, target - python_measure(x, s.resolution_mm), feedforward[k])
            total += current
            saturated += abs(current) >= s.current_limit_A
            for _ in range(stride):
                v += step * (current + disturbance[k] - offset - plant.friction(x, v)) / inertia
                x += step * v
                plant.advance(v, step)
        out[1, k], out[3, k] = total / periods, saturated / periods
    return out
