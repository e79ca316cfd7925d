"""The linear parameters of a fitted base model, as regressor columns.

Every friction model of greybox is linear in some of its parameters once its
nonlinear *shape* is fixed (the identification exploits this, see
:mod:`greybox.identify.linear`): the inertia, the friction levels or
stiffnesses, the viscous coefficient, the offset. For a fitted model this
module returns those regressor columns over a run, so that added effect terms
can be refitted *jointly* with them by one least-squares solve, and writes
the jointly fitted values back into the model.

=========== ================================================ ==========================
model       columns                                          coefficients (attributes)
=========== ================================================ ==========================
Coulomb     ``a, sgn v, v (, 1)``                            ``J_, coulomb_*, viscous_*, offset_``
(asym.)     ``a, [v>0], -[v<0], v [v>0], v [v<0]``
Stribeck    ``a, sgn v (1-e), sgn v e, v (, 1)``             ``J_, coulomb_, static_, viscous_, offset_``
LuGre       ``dz/dt, v, a (, 1)``, fixed ``sigma0 z``        ``sigma1_, viscous_, J_, offset_``
GMS         ``z_1..z_N, w, v, a (, 1)``                      ``k_, sigma_, mu_, J_, offset_``
=========== ================================================ ==========================

(``e = exp(-|v|/v_s)``; ``z``, ``w`` the LuGre / GMS states at the fitted shape.)
The bounds are those of the models' own fits (non-negative where the model
requires it). Any other model is treated as a fixed prediction with no linear
part.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..data.log import AxisLog
from ..friction import CoulombModel, GMSModel, LuGreModel, StribeckModel
from ..friction.gms import gms_states
from ..friction.kernels import lugre_trajectory_kernel
from ..identify.static import stribeck_regressors

__all__ = ["LinearPart", "base_linear_part", "base_coefficients", "set_base_coefficients"]


@dataclass(frozen=True)
class LinearPart:
    """A prediction written as ``columns @ coefficients + fixed``.

    Attributes
    ----------
    columns : ndarray, shape (n, p)
        Regressors of the linear parameters.
    fixed : ndarray, shape (n,)
        The part of the prediction that is not linear in them [A].
    names : tuple of str
        Parameter names, one per column.
    lower, upper : ndarray, shape (p,)
        Bounds of the coefficients.
    """

    columns: np.ndarray
    fixed: np.ndarray
    names: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray


def _part(columns, names, non_negative: int, fixed=None) -> LinearPart:
    columns = np.column_stack(columns) if columns else np.empty((len(fixed), 0))
    lower = np.full(columns.shape[1], -np.inf)
    lower[:non_negative] = 0.0
    fixed = np.zeros(columns.shape[0]) if fixed is None else np.asarray(fixed, dtype=float)
    return LinearPart(columns, fixed, tuple(names), lower, np.full(columns.shape[1], np.inf))


def _coulomb(model: CoulombModel, run: AxisLog) -> LinearPart:
    v, a = run.velocity, run.acceleration
    if model.asymmetric:
        positive, negative = (v > 0.0).astype(float), (v < 0.0).astype(float)
        return _part([a, positive, -negative, v * positive, v * negative],
                     ["J", "coulomb_pos", "coulomb_neg", "viscous_pos", "viscous_neg"], 0)
    columns, names = [a, np.sign(v), v], ["J", "coulomb", "viscous"]
    if model.fit_offset:
        columns.append(np.ones(len(run)))
        names.append("offset")
    return _part(columns, names, 0)


def _stribeck(model: StribeckModel, run: AxisLog) -> LinearPart:
    matrix = stribeck_regressors(run.velocity, run.acceleration, model.v_s_, model.fit_offset)
    names = ["J", "coulomb", "static", "viscous"] + (["offset"] if model.fit_offset else [])
    return _part(list(matrix.T), names, 4)


def _lugre(model: LuGreModel, run: AxisLog) -> LinearPart:
    v = np.ascontiguousarray(run.velocity, dtype=float)
    z, z_dot = np.empty(v.size), np.empty(v.size)
    lugre_trajectory_kernel(v, float(run.sample_time), model.sigma0_, model.coulomb_, model.static_,
                            model.v_s_, 0.0, z, z_dot)
    columns, names = [z_dot, v, run.acceleration], ["sigma1", "viscous", "J"]
    if model.fit_offset:
        columns.append(np.ones(len(run)))
        names.append("offset")
    return _part(columns, names, 3, fixed=model.sigma0_ * z)


def _gms(model: GMSModel, run: AxisLog) -> LinearPart:
    z, _, w, _ = gms_states(run.velocity, run.sample_time, alpha=model.alpha_, C=model.C_, s_0=model.s0_,
                            s_inf=model.s_inf_, v_s=model.v_s_)
    n = z.shape[1]
    columns = list(z.T) + [w, run.velocity, run.acceleration]
    names = [f"k{i + 1}" for i in range(n)] + ["sigma", "mu", "J"]
    if model.fit_offset:
        columns.append(np.ones(len(run)))
        names.append("offset")
    return _part(columns, names, n + 3)


_BUILDERS = {CoulombModel: _coulomb, StribeckModel: _stribeck, LuGreModel: _lugre, GMSModel: _gms}


def base_linear_part(model, run: AxisLog) -> LinearPart:
    """Linear parameters of a fitted base model over one prepared run.

    ``columns @ base_coefficients(model) + fixed`` equals ``model.predict(run)``.

    Parameters
    ----------
    model : CurrentModel
        A fitted model. Coulomb, Stribeck, LuGre and GMS models give their
        linear parameters (module table); any other model gives no columns
        and its whole prediction as ``fixed``.
    run : AxisLog
        One prepared run.
    """
    builder = _BUILDERS.get(type(model))
    if builder is None:
        return _part([], [], 0, fixed=model.predict(run))
    return builder(model, run)


def base_coefficients(model) -> np.ndarray:
    """Present values of the linear parameters, in the order of :func:`base_linear_part`'s columns."""
    kind = type(model)
    if kind is CoulombModel:
        if model.asymmetric:
            return np.array([model.J_, model.coulomb_pos_, model.coulomb_neg_, model.viscous_pos_,
                             model.viscous_neg_])
        return np.array([model.J_, model.coulomb_pos_, model.viscous_pos_]
                        + ([model.offset_] if model.fit_offset else []))
    if kind is StribeckModel:
        return np.array([model.J_, model.coulomb_, model.static_, model.viscous_]
                        + ([model.offset_] if model.fit_offset else []))
    if kind is LuGreModel:
        return np.array([model.sigma1_, model.viscous_, model.J_] + ([model.offset_] if model.fit_offset else []))
    if kind is GMSModel:
        return np.concatenate((model.k_, [model.sigma_, model.mu_, model.J_],
                               [model.offset_] if model.fit_offset else []))
    return np.empty(0)


def set_base_coefficients(model, coefficients) -> None:
    """Write jointly fitted linear parameters into a fitted base model (in place).

    Parameters
    ----------
    model : CurrentModel
        The model whose :func:`base_linear_part` gave the columns.
    coefficients : array_like, shape (p,)
        New values, in the order of the columns.
    """
    x = [float(value) for value in np.asarray(coefficients, dtype=float)]
    kind = type(model)
    if kind is CoulombModel:
        if model.asymmetric:
            model.J_, model.coulomb_pos_, model.coulomb_neg_, model.viscous_pos_, model.viscous_neg_ = x
            return
        model.J_, model.coulomb_pos_, model.viscous_pos_ = x[:3]
        model.coulomb_neg_, model.viscous_neg_ = model.coulomb_pos_, model.viscous_pos_
        model.offset_ = x[3] if model.fit_offset else 0.0
    elif kind is StribeckModel:
        model.J_, model.coulomb_, model.static_, model.viscous_ = x[:4]
        model.offset_ = x[4] if model.fit_offset else 0.0
    elif kind is LuGreModel:
        model.sigma1_, model.viscous_, model.J_ = x[:3]
        model.offset_ = x[3] if model.fit_offset else 0.0
    elif kind is GMSModel:
        n = len(model.alpha_)
        model.k_ = np.array(x[:n])
        model.sigma_, model.mu_, model.J_ = x[n:n + 3]
        model.offset_ = x[n + 3] if model.fit_offset else 0.0
    elif x:
        raise ValueError(f"a {kind.__name__} has no linear parameters, got {len(x)} values")
