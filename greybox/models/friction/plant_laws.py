"""The dynamic friction models as plants of a position loop (:class:`greybox.base.PlantLaw`).

A position loop (:mod:`greybox.control.plants`) integrates ``J dv/dt = I - F
- I_0`` at a fine internal step ``h`` and asks the friction law two things,
through compiled functions it receives as arguments:

``friction(parameters, state, position_mm, velocity_mm_s) -> float``
    The friction [A] of the present state at the present velocity.
``advance(parameters, state, velocity_mm_s, step_s) -> None``
    The state (in place) after one internal step at the new velocity.

``parameters`` and ``state`` are float64 arrays in the layout of each law
(below). The element and bristle steps are the ones the models' run kernels
use (:mod:`greybox.models.friction.kernels`), so a plant follows its model's law,
now at the fine step ``h`` instead of the log's sample time. The friction
is explicit: it reads the deflections and the rate of the previous step.

GMS (``N`` elements)
    ``parameters = (mu+, mu-, sigma, C, curves, alpha_1..N, k_1..N)`` with ``curves`` the six
    numbers ``s_inf, s_0 - s_inf, 1 / v_s`` of positive, then of negative motion
    (:func:`greybox.models.friction.kernels.direction_curves`),
    ``state = (sum_i alpha_i dz_i/dt, z_1..N, mode_1..N)``;
    ``F = mu(v) v + sigma sum_i alpha_i dz_i/dt + sum_i k_i z_i``.
LuGre
    ``parameters = (sigma0, sigma1, sigma2+, sigma2-, curves)`` with ``curves`` the six
    numbers ``F_c, F_s - F_c, 1 / v_s`` of positive, then of negative motion
    (:func:`greybox.models.friction.kernels.direction_curves` of ``F_s, F_c, v_s``; levels are magnitudes),
    ``state = (z, dz/dt)``; ``F = sigma0 z + sigma1 dz/dt + sigma2(v) v``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ...base import PlantLaw
from .directions import direction_pair
from .kernels import direction_curves, gms_element_step, gms_sample, lugre_decay_rate, lugre_exact_step, viscous_at

__all__ = [
    "MAX_STEP_RATIO",
    "stable_step",
    "gms_plant_law",
    "gms_plant_friction",
    "gms_plant_advance",
    "lugre_plant_law",
    "lugre_plant_friction",
    "lugre_plant_advance",
]

#: Largest ``omega h`` (natural frequency of the stiffest friction spring with
#: the inertia, times the internal step) and ``c h / J`` (friction damping)
#: the internal step is chosen for; semi-implicit Euler is stable below 2.
MAX_STEP_RATIO = 0.25

_GMS_HEAD = 10  # mu+, mu-, sigma, C, then s_inf, s_0 - s_inf, 1 / v_s of positive and of negative motion


def stable_step(inertia: float, stiffness: float, damping: float) -> float:
    """Largest internal step [s] for a friction stiffness and damping on an inertia.

    Parameters
    ----------
    inertia : float
        ``J`` [A s^2/mm], positive.
    stiffness : float
        Total stiffness of the friction springs [A/mm].
    damping : float
        Total damping of the friction [A s/mm].

    Returns
    -------
    float
        ``MAX_STEP_RATIO`` times the smaller of ``sqrt(J / stiffness)`` and
        ``J / damping`` [s]; infinite without stiffness and damping.
    """
    limits = [np.inf]
    if stiffness > 0.0:
        limits.append(MAX_STEP_RATIO * math.sqrt(inertia / stiffness))
    if damping > 0.0:
        limits.append(MAX_STEP_RATIO * inertia / damping)
    return float(min(limits))


# ------------------------------------------------------------------ GMS
@njit(cache=True, error_model="numpy")
def gms_plant_friction(parameters, state, position_mm, velocity_mm_s):
    """GMS friction [A] ``mu(v) v + sigma w + sum_i k_i z_i`` of the present state (layout in the module doc).

    Parameters
    ----------
    parameters : ndarray of float64
        The law's parameters, in the layout of the module doc (GMS).
    state : ndarray of float64
        The law's state, in the layout of the module doc (GMS).
    position_mm : float
        Present position [mm].
    velocity_mm_s : float
        Present velocity [mm/s].
    """
    n = (parameters.shape[0] - _GMS_HEAD) // 2
    force = viscous_at(velocity_mm_s, parameters[0:2]) + parameters[2] * state[0]
    for i in range(n):
        force += parameters[_GMS_HEAD + n + i] * state[1 + i]
    return force


@njit(cache=True, error_model="numpy")
def gms_plant_advance(parameters, state, velocity_mm_s, step_s):
    """Move the GMS elements over one internal step ``step_s`` [s] at ``velocity_mm_s`` [mm/s] (in place).

    Every element takes :func:`greybox.models.friction.kernels.gms_element_step`;
    ``state[0]`` receives ``sum_i alpha_i dz_i/dt`` over the step [mm/s].

    Parameters
    ----------
    parameters : ndarray of float64
        The law's parameters, in the layout of the module doc (GMS).
    state : ndarray of float64
        The law's state, in the layout of the module doc (GMS) (updated in place).
    velocity_mm_s : float
        Velocity over the step [mm/s].
    step_s : float
        Internal step [s].
    """
    n = (parameters.shape[0] - _GMS_HEAD) // 2
    s, inv_s, d, v_dt = gms_sample(velocity_mm_s, step_s, parameters[4:_GMS_HEAD].reshape((2, 3)))
    c_dt = parameters[3] * step_s
    rate = 0.0
    for i in range(n):
        alpha_i = parameters[_GMS_HEAD + i]
        z_old = state[1 + i]
        z_new, mode = gms_element_step(z_old, int(state[1 + n + i]), d, v_dt, alpha_i * s, alpha_i, c_dt, inv_s)
        rate += alpha_i * (z_new - z_old) / step_s
        state[1 + i] = z_new
        state[1 + n + i] = mode
    state[0] = rate


def gms_plant_law(*, alpha, k, sigma, s_0, s_inf, v_s, c, mu, inertia, offset) -> PlantLaw:
    """The GMS law as a plant: elements relaxed and sticking at rest.

    Parameters
    ----------
    alpha, k : array_like, shape (N,)
        Element fractions and stiffnesses [A/mm].
    sigma : float
        Micro-damping [A s/mm].
    s_0, s_inf : float or (float, float)
        Break-away deflection at rest and at high speed [mm]; a pair gives
        positive and negative motion their own.
    v_s : float or (float, float)
        Stribeck velocity [mm/s], one or one per direction.
    c : float
        Slip rate constant [mm/s].
    mu : float or (float, float)
        Viscous coefficient [A s/mm], one or one per direction.
    inertia : float
        ``J`` [A s^2/mm].
    offset : float
        Constant load [A].

    Returns
    -------
    PlantLaw
        Its internal step is stable for ``sum k`` and ``sigma + max mu`` on the
        inertia and below ``min(s_0, s_inf) / C``, where the forward-Euler
        slip step relaxes without overshoot.
    """
    alpha = np.asarray(alpha, dtype=float)
    k = np.asarray(k, dtype=float)
    s_0, s_inf, v_s, mu = (direction_pair(x, f"GMS {name}") for x, name in ((s_0, "s_0"), (s_inf, "s_inf"),
                                                                          (v_s, "v_s"), (mu, "mu")))
    c = float(c)
    head = np.concatenate((mu, [float(sigma), c], direction_curves(s_0, s_inf, v_s).ravel()))
    parameters = np.ascontiguousarray(np.concatenate((head, alpha, k)))
    state = np.zeros(1 + 2 * alpha.size)
    slip_step = float(min(s_0.min(), s_inf.min())) / c
    step = min(stable_step(inertia, float(np.sum(k)), float(sigma + mu.max())), slip_step)
    return PlantLaw(gms_plant_friction, gms_plant_advance, parameters, state, step, float(inertia), float(offset))


# ------------------------------------------------------------------ LuGre
@njit(cache=True, error_model="numpy")
def lugre_plant_friction(parameters, state, position_mm, velocity_mm_s):
    """LuGre friction [A] ``sigma0 z + sigma1 dz/dt + sigma2(v) v`` of the present state (layout in the module doc).

    Parameters
    ----------
    parameters : ndarray of float64
        The law's parameters, in the layout of the module doc (LuGre).
    state : ndarray of float64
        The law's state, in the layout of the module doc (LuGre).
    position_mm : float
        Present position [mm].
    velocity_mm_s : float
        Present velocity [mm/s].
    """
    return parameters[0] * state[0] + parameters[1] * state[1] + viscous_at(velocity_mm_s, parameters[2:4])


@njit(cache=True, error_model="numpy")
def lugre_plant_advance(parameters, state, velocity_mm_s, step_s):
    """Move the bristles over one internal step ``step_s`` [s] at ``velocity_mm_s`` [mm/s] (in place).

    The exact step :func:`greybox.models.friction.kernels.lugre_exact_step`;
    ``state[1]`` receives ``dz/dt`` over the step [mm/s].

    Parameters
    ----------
    parameters : ndarray of float64
        The law's parameters, in the layout of the module doc (LuGre).
    state : ndarray of float64
        The law's state, in the layout of the module doc (LuGre) (updated in place).
    velocity_mm_s : float
        Velocity over the step [mm/s].
    step_s : float
        Internal step [s].
    """
    z = state[0]
    rate = lugre_decay_rate(velocity_mm_s, parameters[0], parameters[4:10].reshape((2, 3)))
    z_new = lugre_exact_step(z, velocity_mm_s, rate, step_s)
    state[1] = (z_new - z) / step_s
    state[0] = z_new


def lugre_plant_law(*, sigma0, sigma1, sigma2, coulomb, static, v_s, inertia, offset) -> PlantLaw:
    """The LuGre law as a plant: bristles relaxed at rest.

    Parameters
    ----------
    sigma0 : float
        Bristle stiffness [A/mm].
    sigma1 : float
        Bristle damping [A s/mm].
    sigma2 : float or (float, float)
        Viscous coefficient [A s/mm], one or one per direction (positive, negative motion).
    coulomb, static : float or (float, float)
        ``F_c`` and ``F_s`` [A], magnitudes; a pair gives positive and negative motion their own.
    v_s : float or (float, float)
        Stribeck velocity [mm/s], one or one per direction.
    inertia : float
        ``J`` [A s^2/mm].
    offset : float
        Constant load [A].

    Returns
    -------
    PlantLaw
        Its internal step is stable for ``sigma0`` and ``sigma1 + max sigma2`` on the inertia.
    """
    sigma2, coulomb, static, v_s = (direction_pair(x, f"LuGre {name}") for x, name in (
        (sigma2, "sigma2"), (coulomb, "Coulomb level"), (static, "static level"), (v_s, "v_s")))
    parameters = np.concatenate(([float(sigma0), float(sigma1)], sigma2,
                                 direction_curves(static, coulomb, v_s).ravel()))
    step = stable_step(inertia, float(sigma0), float(sigma1 + sigma2.max()))
    return PlantLaw(lugre_plant_friction, lugre_plant_advance, parameters, np.zeros(2), step, float(inertia),
                    float(offset))
