"""Compiled time-stepping kernels of the dynamic friction models.

All kernels are compiled with numba (``@njit(cache=True, error_model="numpy")``, no fastmath, so
that results are reproducible and agree with the plain-Python references in
the tests). They take the velocity sequence [mm/s] of one run sampled at a
constant step ``sample_time`` [s], start from a given state and return the
state after the last sample, so that a long log can be processed in chunks
that carry the state across.

Sample ``j`` uses the state *before* its update (explicit output equation):
the friction reported at ``t_j`` is computed from ``z(t_j)`` and the rate
applied over the step ``[t_j, t_j + T]``.

GMS element modes (``int8``): ``0`` sticking, ``+1`` slipping in the positive
direction, ``-1`` slipping in the negative direction.

Each formula is written once, as a compiled step that the run kernels here
and the plant laws of the position loop (:mod:`greybox.models.friction.plant_laws`)
call: the Stribeck curve :func:`stribeck_at`, the GMS element step
:func:`gms_element_step` (with :func:`gms_sample`), the LuGre exact step
:func:`lugre_exact_step` (with :func:`lugre_decay_rate`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = [
    "stribeck_at",
    "gms_sample",
    "gms_element_step",
    "viscous_at",
    "direction_curves",
    "lugre_decay_rate",
    "lugre_exact_step",
    "gms_friction_kernel",
    "gms_trajectory_kernel",
    "lugre_trajectory_kernel",
    "backlash_gap_kernel",
    "play_operator_kernel",
]


# ------------------------------------------------------------------ shared steps (one copy each)
@njit(cache=True, error_model="numpy")
def stribeck_at(speed, low, drop, inv_v_s):
    """The models' Stribeck curve ``low + drop exp(-speed / v_s)`` at a speed ``|v|`` [mm/s].

    It is the break-away deflection ``s(v) = s_inf + (s_0 - s_inf) exp(-|v|/v_s)``
    [mm] of the GMS elements and the level ``g(v) = F_c + (F_s - F_c)
    exp(-|v|/v_s)`` [A] of the LuGre bristles. The callers pass ``1 / v_s``
    so that a kernel divides once per run.

    Parameters
    ----------
    speed : float
        ``|v|`` [mm/s], non-negative.
    low : float
        Level at high speed (``s_inf`` [mm] or ``F_c`` [A]).
    drop : float
        Excess at rest over ``low`` (``s_0 - s_inf`` [mm] or ``F_s - F_c`` [A]).
    inv_v_s : float
        ``1 / v_s`` [s/mm].

    Returns
    -------
    float
        The curve at ``speed``, in the unit of ``low``.
    """
    return low + drop * math.exp(-speed * inv_v_s)


@njit(cache=True, error_model="numpy")
def gms_element_step(z_old, mode, d, v_dt, s_i, alpha_i, c_dt, inv_s):
    """One forward-Euler step of one GMS element.

    Parameters
    ----------
    z_old : float
        Deflection before the step [mm].
    mode : int
        Mode before the step (0 stick, +1/-1 slip).
    d : int
        ``sgn(v)`` of the velocity held over the step.
    v_dt : float
        ``v T``: travel over the step [mm].
    s_i : float
        ``alpha_i s(v)``: break-away deflection of the element [mm].
    alpha_i : float
        Element fraction.
    c_dt : float
        ``C T`` [mm].
    inv_s : float
        ``1 / s(v)`` [1/mm].

    Returns
    -------
    z_new : float
        Deflection after the step [mm].
    mode : int
        Mode after the step.
    """
    fd = float(d)
    if mode != 0 and mode != d:
        mode = 0  # velocity reversed or stopped: the element sticks again
    if mode == 0:
        z_new = z_old + v_dt
        if d != 0 and fd * z_new >= s_i:
            mode = d  # break-away: the deflection reached s_i(v)
            if fd * z_old < s_i:
                z_new = fd * s_i
            else:
                z_new = z_old + c_dt * (alpha_i * fd - z_old * inv_s)
    else:
        # T C_i (sgn(v) - z / s_i) with C_i = alpha_i C, s_i = alpha_i s
        z_new = z_old + c_dt * (alpha_i * fd - z_old * inv_s)
    return z_new, mode


@njit(cache=True, error_model="numpy")
def gms_sample(v, sample_time, curves):
    """Quantities of one GMS step shared by all elements.

    Parameters
    ----------
    v : float
        Velocity held over the step [mm/s].
    sample_time : float
        Step T [s].
    curves : ndarray, shape (2, 3)
        Break-away curve of each direction of motion (row 0 positive, row 1
        negative motion): ``s_inf`` [mm], ``s_0 - s_inf`` [mm], ``1 / v_s``
        [s/mm] (:func:`direction_curves`).

    Returns
    -------
    s : float
        ``s(v) = s_inf + (s_0 - s_inf) exp(-|v| / v_s)`` of the direction of ``v`` [mm]
        (the positive curve at rest, where no element moves).
    inv_s : float
        ``1 / s(v)`` [1/mm].
    d : int
        ``sgn(v)``.
    v_dt : float
        ``v T``: travel over the step [mm].
    """
    d = 1 if v > 0.0 else (-1 if v < 0.0 else 0)
    row = 1 if d < 0 else 0
    s = stribeck_at(abs(v), curves[row, 0], curves[row, 1], curves[row, 2])
    return s, 1.0 / s, d, v * sample_time


@njit(cache=True, error_model="numpy")
def viscous_at(v, viscous):
    """Viscous friction ``mu(v) v`` [A], with the coefficient of the direction of motion.

    Parameters
    ----------
    v : float
        Velocity [mm/s].
    viscous : ndarray, shape (2,)
        ``(mu+, mu-)`` [A s/mm] for positive and negative motion.
    """
    return (viscous[1] if v < 0.0 else viscous[0]) * v


def direction_curves(s_0, s_inf, v_s) -> np.ndarray:
    """The ``curves`` argument of the GMS and LuGre kernels from the Stribeck curves of the two directions.

    Parameters
    ----------
    s_0, s_inf : (float, float)
        The curve at rest and at high speed for positive and negative motion:
        the GMS break-away deflection [mm] or the LuGre level ``F_s``, ``F_c`` [A].
    v_s : (float, float)
        Stribeck velocity for positive and negative motion [mm/s].

    Returns
    -------
    ndarray, shape (2, 3)
        Rows positive / negative motion: ``s_inf``, ``s_0 - s_inf``, ``1 / v_s``
        (the arguments ``low``, ``drop``, ``inv_v_s`` of :func:`stribeck_at`).
    """
    s_0, s_inf, v_s = (np.asarray(x, dtype=float) for x in (s_0, s_inf, v_s))
    return np.ascontiguousarray(np.column_stack((s_inf, s_0 - s_inf, 1.0 / v_s)))


@njit(cache=True, error_model="numpy")
def lugre_decay_rate(v, sigma0, curves):
    """Relaxation rate ``lambda = sigma0 |v| / g(v)`` [1/s] of the LuGre bristle equation.

    ``dz/dt = v - lambda z`` with the Stribeck curve of the direction of
    motion, ``g(v) = F_c + (F_s - F_c) exp(-|v|/v_s)`` (:func:`stribeck_at`);
    0 at rest, where ``g`` does not matter.

    Parameters
    ----------
    v : float
        Velocity [mm/s].
    sigma0 : float
        Bristle stiffness [A/mm].
    curves : ndarray, shape (2, 3)
        Stribeck curve of positive (row 0) and negative (row 1) motion:
        ``F_c`` [A], ``F_s - F_c`` [A], ``1 / v_s`` [s/mm] (levels are
        magnitudes; :func:`direction_curves` of ``F_s``, ``F_c``, ``v_s``;
        equal rows for the symmetric model).
    """
    row = 1 if v < 0.0 else 0
    speed = abs(v)
    return sigma0 * speed / stribeck_at(speed, curves[row, 0], curves[row, 1], curves[row, 2])


@njit(cache=True, error_model="numpy")
def lugre_exact_step(z, v, rate, step_s):
    """Bristle deflection [mm] after a step of ``dz/dt = v - lambda z`` with ``v`` and ``lambda`` held.

    The exact solution ``z e^{-lambda h} + v (1 - e^{-lambda h}) / lambda``,
    stable and accurate for any bristle stiffness (forward Euler diverges once
    ``lambda h > 2``); ``z + v h`` at rest (``lambda = 0``).

    Parameters
    ----------
    z : float
        Deflection before the step [mm].
    v : float
        Velocity held over the step [mm/s].
    rate : float
        ``lambda`` [1/s] (:func:`lugre_decay_rate`).
    step_s : float
        Step ``h`` [s].
    """
    x = rate * step_s
    if x > 0.0:
        return z * math.exp(-x) - v * math.expm1(-x) / rate
    return z + v * step_s


# ------------------------------------------------------------------ run kernels
@njit(cache=True, error_model="numpy")
def gms_friction_kernel(velocity, sample_time, alpha, k, sigma, curves, c, viscous, z0, mode0):
    """Friction of the Generalized Maxwell-Slip model, forward Euler at a constant step.

    Parameters
    ----------
    velocity : ndarray, shape (n,)
        Velocity [mm/s].
    sample_time : float
        Step T [s].
    alpha : ndarray, shape (N,)
        Element fractions, positive, summing to 1.
    k : ndarray, shape (N,)
        Element stiffnesses [A/mm].
    sigma : float
        Total micro-damping [A s/mm]; element i gets ``alpha_i * sigma``.
    curves : ndarray, shape (2, 3)
        Break-away deflection curve ``s(v)`` of positive and negative motion
        (:func:`direction_curves`; equal rows for the symmetric model).
    c : float
        Slip rate constant C [mm/s]; element i relaxes with ``alpha_i * C``.
    viscous : ndarray, shape (2,)
        Viscous coefficient of positive and negative motion [A s/mm].
    z0 : ndarray, shape (N,)
        Initial element deflections [mm].
    mode0 : ndarray of int8, shape (N,)
        Initial element modes.

    Returns
    -------
    friction : ndarray, shape (n,)
        ``mu(v) v + sum_i (k_i z_i + alpha_i sigma dz_i/dt)`` [A].
    z_end : ndarray, shape (N,)
        Deflections after the last step [mm].
    mode_end : ndarray of int8, shape (N,)
        Modes after the last step.
    """
    n = velocity.shape[0]
    z = z0.copy()
    mode = mode0.copy()
    damping = sigma * alpha
    friction = np.empty(n)
    c_dt = c * sample_time
    for j in range(n):
        v = velocity[j]
        s, inv_s, d, v_dt = gms_sample(v, sample_time, curves)
        f = viscous_at(v, viscous)
        for i in range(alpha.shape[0]):
            z_old = z[i]
            z_new, m = gms_element_step(z_old, mode[i], d, v_dt, alpha[i] * s, alpha[i], c_dt, inv_s)
            f += k[i] * z_old + damping[i] * ((z_new - z_old) / sample_time)
            z[i] = z_new
            mode[i] = m
        friction[j] = f
    return friction, z, mode


@njit(cache=True, error_model="numpy")
def gms_trajectory_kernel(velocity, sample_time, alpha, k, sigma, curves, c, viscous, z0, mode0,
                          z_out, mode_out, w_out, friction_out):
    """Element states and friction of the GMS model over a run (forward Euler, constant step).

    The element deflections do not depend on the stiffnesses ``k_i``, the
    damping ``sigma`` or the viscous coefficient, so the friction is linear in
    those given this trajectory: ``F = z_out @ k + sigma * w_out + mu(v) v``
    (the identification passes zeros for them and reads the states only).
    The outputs are written into arrays given by the caller (they may be
    column views of a regressor matrix). ``friction_out`` equals the output of
    :func:`gms_friction_kernel` bit for bit (the same sums in the same order).

    Parameters
    ----------
    velocity : ndarray, shape (n,)
        Velocity [mm/s].
    sample_time, alpha, k, sigma, curves, c, viscous, z0, mode0
        As in :func:`gms_friction_kernel`.
    z_out : ndarray, shape (n, N)
        Receives the deflection of each element at each sample, before its update [mm].
    mode_out : ndarray of int8, shape (n, N)
        Receives the mode of each element at each sample, before its update.
    w_out : ndarray, shape (n,)
        Receives ``sum_i alpha_i dz_i/dt`` over each step [mm/s].
    friction_out : ndarray, shape (n,)
        Receives the friction at each sample [A].

    Returns
    -------
    z_end : ndarray, shape (N,)
        Deflections after the last step [mm].
    mode_end : ndarray of int8, shape (N,)
        Modes after the last step.
    """
    n = velocity.shape[0]
    z = z0.copy()
    mode = mode0.copy()
    damping = sigma * alpha
    c_dt = c * sample_time
    for j in range(n):
        v = velocity[j]
        s, inv_s, d, v_dt = gms_sample(v, sample_time, curves)
        w = 0.0
        f = viscous_at(v, viscous)
        for i in range(alpha.shape[0]):
            z_old = z[i]
            z_out[j, i] = z_old
            mode_out[j, i] = mode[i]
            z_new, m = gms_element_step(z_old, mode[i], d, v_dt, alpha[i] * s, alpha[i], c_dt, inv_s)
            rate = (z_new - z_old) / sample_time
            w += alpha[i] * rate
            f += k[i] * z_old + damping[i] * rate
            z[i] = z_new
            mode[i] = m
        w_out[j] = w
        friction_out[j] = f
    return z, mode


@njit(cache=True, error_model="numpy")
def lugre_trajectory_kernel(velocity, sample_time, sigma0, curves, z0, z_out, z_dot_out):
    """Bristle deflection of the LuGre model, exact zero-order-hold step.

    With the velocity held at ``v`` over a step the bristle equation
    ``dz/dt = v - lambda z`` with ``lambda = sigma0 |v| / g(v)`` is linear with
    a constant coefficient, and its exact solution over the step is
    ``z(T) = z e^{-lambda T} + v (1 - e^{-lambda T}) / lambda``. It is stable
    and accurate for any bristle stiffness, unlike forward Euler, which
    diverges once ``lambda T > 2``.

    Parameters
    ----------
    velocity : ndarray, shape (n,)
        Velocity [mm/s].
    sample_time : float
        Step T [s].
    sigma0 : float
        Bristle stiffness [A/mm].
    curves : ndarray, shape (2, 3)
        Stribeck curve ``g(v) = F_c + (F_s - F_c) exp(-|v|/v_s)`` of positive
        and negative motion (:func:`lugre_decay_rate`; equal rows for the
        symmetric model).
    z0 : float
        Initial bristle deflection [mm].
    z_out : ndarray, shape (n,)
        Receives the bristle deflection at each sample, before its update [mm].
    z_dot_out : ndarray, shape (n,)
        Receives ``dz/dt = v - lambda z`` at each sample [mm/s].

    Returns
    -------
    z_end : float
        Deflection after the last step [mm].
    """
    n = velocity.shape[0]
    z = z0
    for j in range(n):
        v = velocity[j]
        lam = lugre_decay_rate(v, sigma0, curves)
        z_out[j] = z
        z_dot_out[j] = v - lam * z
        z = lugre_exact_step(z, v, lam, sample_time)
    return z


@njit(cache=True, error_model="numpy")
def backlash_gap_kernel(position, force, width, threshold, gap_low, gap_high, loaded, in_gap_out):
    """Where a backlash of ``width`` is crossed, given the force transmitted through it.

    The gap is crossed when the transmitted force changes sign: once the force
    has been at least ``threshold`` in one direction (``loaded`` = its sign)
    and then reaches the other sign, the contact opens at the present motor
    position ``x`` and the motor must travel ``width`` to the other face: the
    gap spans ``[x - width, x]`` after a positive load, ``[x, x + width]``
    after a negative one. The motor leaving the span on either side closes the
    contact (then ``loaded`` is 0 until the force reaches ``threshold`` again).

    Parameters
    ----------
    position : ndarray, shape (n,)
        Motor-side position [mm].
    force : ndarray, shape (n,)
        Force through the backlash [A or N] (not read inside a gap).
    width : float
        Backlash [mm], non-negative.
    threshold : float
        Force that counts as a load [A or N], non-negative.
    gap_low, gap_high : float
        Span of an open gap before the first sample [mm]; NaN when in contact.
    loaded : int
        Sign of the last load (+1, -1, or 0 for none yet).
    in_gap_out : ndarray of bool, shape (n,)
        Receives True for the samples inside the gap.

    Returns
    -------
    gap_low, gap_high : float
        Span of the gap after the last sample (NaN when in contact).
    loaded : int
        Sign of the last load after the last sample.
    """
    for j in range(position.shape[0]):
        x = position[j]
        if gap_low == gap_low:  # a gap is open
            if gap_low <= x <= gap_high:
                in_gap_out[j] = True
                continue
            gap_low = np.nan
            gap_high = np.nan
            loaded = 0
        f = force[j]
        if loaded != 0 and f * loaded < 0.0:
            if loaded > 0:
                gap_low, gap_high = x - width, x
            else:
                gap_low, gap_high = x, x + width
            loaded = 0
            in_gap_out[j] = True
            continue
        if f >= threshold:
            loaded = 1
        elif f <= -threshold:
            loaded = -1
        in_gap_out[j] = False
    return gap_low, gap_high, loaded


@njit(cache=True, error_model="numpy")
def play_operator_kernel(position, widths, state, previous_position, out):
    """States of a bank of play (elasto-plastic) operators driven by the position.

    Operator ``k`` follows the position with slope ``1 / widths[k]`` and is
    clamped to ``[-1, 1]``: ``s_k <- clip(s_k + (x_j - x_{j-1}) / widths[k], -1, 1)``.
    It is the deflection of a Maxwell-slip element of break-away displacement
    ``widths[k]`` over that displacement, rate independent; a weighted sum of
    such states spans rate-independent pre-sliding hysteresis (Prandtl-Ishlinskii).

    Parameters
    ----------
    position : ndarray, shape (n,)
        Position [mm].
    widths : ndarray, shape (m,)
        Break-away displacements [mm], positive.
    state : ndarray, shape (m,)
        States at ``previous_position``, each in ``[-1, 1]``; updated in place to the
        states at the last sample.
    previous_position : float
        Position [mm] the states belong to: the last sample of the previous chunk
        of the run, or ``position[0]`` at the start of a run.
    out : ndarray, shape (n, m)
        Receives the states at every sample.
    """
    previous = previous_position
    for j in range(position.shape[0]):
        step = position[j] - previous
        previous = position[j]
        for k in range(widths.shape[0]):
            s = state[k] + step / widths[k]
            if s > 1.0:
                s = 1.0
            elif s < -1.0:
                s = -1.0
            state[k] = s
            out[j, k] = s
