"""Plain-Python truth laws of the family, the references of the compiled kernels.

Written from the module docs of :mod:`greybox.twin.laws` one step at a time,
without numba and without calling the package's kernels.
"""

from __future__ import annotations

import math

import numpy as np


def stribeck(v, r_c, v_s, delta):
    return r_c + (1.0 - r_c) * math.exp(-((abs(v) / v_s) ** delta))


def bristle(position, velocity, stride, sigma0, sigma1, static, r_c, v_s, delta):
    """LuGre-type bristle: exact exponential update of z per fine step; F = sigma0 z + sigma1 dz/dt."""
    out, z = [], 0.0
    for i in range(len(position)):
        v = float(velocity[i])
        g = static * stribeck(v, r_c, v_s, delta) / sigma0
        if i > 0:
            dx = float(position[i] - position[i - 1])
            if dx != 0.0:
                s = 1.0 if dx > 0 else -1.0
                z = s * g + (z - s * g) * math.exp(-abs(dx) / g)
        if i % stride == 0:
            out.append(sigma0 * z + sigma1 * (v - abs(v) * z / g))
    return np.array(out)


def dahl_step(force, dx, level, sigma0, alpha):
    if dx == 0.0:
        return force
    s = 1.0 if dx > 0 else -1.0
    y = 1.0 - force * s / level
    if y <= 0.0:
        return s * level
    k = sigma0 / level
    if alpha == 1.0:
        y *= math.exp(-k * abs(dx))
    else:
        w = y ** (1.0 - alpha) - (1.0 - alpha) * k * abs(dx)
        y = w ** (1.0 / (1.0 - alpha)) if w > 0 else 0.0
    return s * level * (1.0 - y)


def dahl(position, stride, level, sigma0, alpha):
    out, force = [], 0.0
    for i in range(len(position)):
        if i > 0:
            force = dahl_step(force, float(position[i] - position[i - 1]), level, sigma0, alpha)
        if i % stride == 0:
            out.append(force)
    return np.array(out)


def backlash_screw(position, velocity, acceleration, step, stride, law, table_inertia):
    """The backlash screw of :mod:`greybox.twin.laws.backlash_screw`, step by step."""
    half = law.play_mm / 2
    guide_sigma0 = law.guide_static_A / law.guide_presliding_mm
    table, nut, z, closed = float(position[0]), 0.0, 0.0, False
    pulse_left, impulse = 0.0, 0.0
    friction, inertia = [], []
    for i in range(len(position)):
        x, v = float(position[i]), float(velocity[i])
        if i > 0:
            nut = dahl_step(nut, x - float(position[i - 1]), law.nut_A, law.nut_A / law.nut_presliding_mm, 1.0)
        before = table
        table = min(max(table, x - half), x + half)
        was_closed, closed = closed, abs(x - table) >= half * (1 - 1e-9)
        if closed:
            g = law.guide_static_A * stribeck(v, law.guide_coulomb_ratio, law.guide_stribeck_mm_s,
                                              law.guide_shape) / guide_sigma0
            dx = table - before
            if dx != 0.0:
                s = 1.0 if dx > 0 else -1.0
                z = s * g + (z - s * g) * math.exp(-abs(dx) / g)
            if not was_closed and i > 0:
                impulse, pulse_left = table_inertia * v, law.pulse_s
        else:
            z = 0.0
        force = table_inertia * float(acceleration[i]) if closed else 0.0
        if pulse_left > 0:
            # mean of impulse * pi / (2 T) * sin(pi t / T) over the step
            start = law.pulse_s - pulse_left
            end = min(start + step, law.pulse_s)
            swing = math.cos(math.pi * start / law.pulse_s) - math.cos(math.pi * end / law.pulse_s)
            force += impulse * swing / (2 * step)
            pulse_left -= step
        if i % stride == 0:
            friction.append(nut + (guide_sigma0 * z if closed else 0.0))
            inertia.append(force)
    return np.array(friction), np.array(inertia)
