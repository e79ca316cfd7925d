"""Plain-Python reference implementations of the compiled friction kernels.

Written directly from the equations in docs/friction-models.md, one sample
and one element at a time, without numba, so that the tests can check the
kernels against them (scikit-learn's and stumpy's rule for compiled code);
benchmarks/bench_gms.py times :func:`gms_reference` as the plain-Python
baseline. Slow by design: not for use on real logs.
"""

from __future__ import annotations

import math


def _per_direction(value):
    """``(positive, negative)`` from a number or a pair."""
    if isinstance(value, (int, float)):
        return (float(value), float(value))
    positive, negative = value
    return (float(positive), float(negative))


def gms_reference(velocity, sample_time, alpha, k, sigma, s_0, s_inf, v_s, c, mu, z0=None, mode0=None,
                  slip_law="design"):
    """GMS friction by forward Euler; returns ``(friction, z_history, mode_history, z_end, mode_end)``.

    ``s_0``, ``s_inf``, ``v_s`` and ``mu`` are numbers, or pairs (positive
    motion, negative motion) for the direction-dependent model; at rest the
    positive curve is used (no element moves there).
    ``slip_law="design"`` is the slip law greybox implements (docs/friction-models.md),
    ``dz/dt = alpha_i C (sgn(v) - z / s_i)``. ``slip_law="sgn(1-z/s)"`` is
    the form ``sgn(v) alpha_i C (1 - z / s_i)`` found in several public
    implementations, which runs away for negative velocities.
    """
    n_el = len(alpha)
    z = [0.0] * n_el if z0 is None else [float(value) for value in z0]
    mode = [0] * n_el if mode0 is None else [int(value) for value in mode0]
    friction, z_history, mode_history = [], [], []
    s_0, s_inf, v_s, mu = (_per_direction(x) for x in (s_0, s_inf, v_s, mu))
    for v in velocity:
        v = float(v)
        d = (v > 0.0) - (v < 0.0)
        r = 1 if d < 0 else 0
        s = s_inf[r] + (s_0[r] - s_inf[r]) * math.exp(-abs(v) / v_s[r])
        z_history.append(list(z))
        mode_history.append(list(mode))
        f = mu[r] * v
        for i in range(n_el):
            f += k[i] * z[i]
        for i in range(n_el):
            s_i = alpha[i] * s
            if slip_law == "design":
                slip_rate = alpha[i] * c * (d - z[i] / s_i)
            else:
                slip_rate = d * alpha[i] * c * (1.0 - z[i] / s_i)
            if mode[i] != 0 and mode[i] != d:
                mode[i] = 0
            if mode[i] == 0:
                z_new = z[i] + v * sample_time
                if d != 0 and d * z_new >= s_i:
                    mode[i] = d
                    z_new = d * s_i if d * z[i] < s_i else z[i] + sample_time * slip_rate
            else:
                z_new = z[i] + sample_time * slip_rate
            f += alpha[i] * sigma * (z_new - z[i]) / sample_time
            z[i] = z_new
        friction.append(f)
    return friction, z_history, mode_history, z, mode


def lugre_reference(velocity, sample_time, sigma0, sigma1, sigma2, f_c, f_s, v_s, z0=0.0):
    """LuGre friction with the exact zero-order-hold step; returns ``(friction, z_history, z_end)``.

    ``sigma2``, ``f_c``, ``f_s`` and ``v_s`` are numbers, or pairs (positive
    motion, negative motion; levels as magnitudes) for the direction-dependent
    model; at rest the positive curve is used (the bristle rate is ``v`` there).
    """
    z = float(z0)
    friction, z_history = [], []
    sigma2, f_c, f_s, v_s = (_per_direction(x) for x in (sigma2, f_c, f_s, v_s))
    for v in velocity:
        v = float(v)
        r = 1 if v < 0.0 else 0
        g = f_c[r] + (f_s[r] - f_c[r]) * math.exp(-abs(v) / v_s[r])
        lam = sigma0 * abs(v) / g
        z_history.append(z)
        friction.append(sigma0 * z + sigma1 * (v - lam * z) + sigma2[r] * v)
        if lam > 0.0:
            decay = math.exp(-lam * sample_time)
            z = z * decay + v * (1.0 - decay) / lam
        else:
            z = z + v * sample_time
    return friction, z_history, z


def stribeck_reference(velocity, low, high, v_s):
    """The models' Stribeck curve ``low + (high - low) exp(-|v| / v_s)`` (``s(v)`` of GMS, ``g(v)`` of LuGre)."""
    return low + (high - low) * math.exp(-abs(velocity) / v_s)


def lugre_step_reference(z, v, sigma0, f_c, f_s, v_s, step):
    """Bristle deflection after one exact step of ``dz/dt = v - sigma0 |v| z / g(v)`` with ``v`` held.

    ``f_c``, ``f_s``, ``v_s`` are numbers or pairs (positive motion, negative motion) as in :func:`lugre_reference`.
    """
    r = 1 if v < 0.0 else 0
    f_c, f_s, v_s = (_per_direction(x)[r] for x in (f_c, f_s, v_s))
    lam = sigma0 * abs(v) / stribeck_reference(v, f_c, f_s, v_s)
    if lam == 0.0:
        return z + v * step
    decay = math.exp(-lam * step)
    return z * decay + v * (1.0 - decay) / lam


def backlash_gap_reference(position, force, width, threshold, gap_low, gap_high, loaded):
    """Samples inside the backlash gap, sample by sample; returns ``(in_gap, gap_low, gap_high, loaded)``.

    The gap opens where the force reaches the sign opposite to the last load
    (a load being a force of at least ``threshold``), at the motor position
    ``x``: ``[x - width, x]`` after a positive load, ``[x, x + width]`` after a
    negative one; the motor leaving that span closes it. ``gap_low`` NaN: in contact.
    """
    in_gap = []
    for x, f in zip(position, force):
        x, f = float(x), float(f)
        if not math.isnan(gap_low):
            if gap_low <= x <= gap_high:
                in_gap.append(True)
                continue
            gap_low, gap_high, loaded = math.nan, math.nan, 0
        if loaded != 0 and f * loaded < 0.0:
            gap_low, gap_high = (x - width, x) if loaded > 0 else (x, x + width)
            loaded = 0
            in_gap.append(True)
            continue
        if f >= threshold:
            loaded = 1
        elif f <= -threshold:
            loaded = -1
        in_gap.append(False)
    return in_gap, gap_low, gap_high, loaded


def play_operator_reference(position, widths, state, previous_position):
    """Play-operator states sample by sample; returns ``(rows, state_after)``.

    Each state follows the position from ``previous_position`` with slope
    ``1 / width`` and stays in ``[-1, 1]``.
    """
    state = [float(value) for value in state]
    rows, previous = [], float(previous_position)
    for present in position:
        step, previous = float(present) - previous, float(present)
        state = [min(1.0, max(-1.0, value + step / float(width))) for value, width in zip(state, widths)]
        rows.append(list(state))
    return rows, state
