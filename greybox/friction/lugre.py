"""LuGre friction with inertia, integrated exactly over each sample step."""

from __future__ import annotations

import numpy as np

from ..base import EFFORT, LinearPart, Parameter
from ..errors import ParameterError
from ..estimator import CurrentModel
from ..identify.initial import DEFAULT_DEFLECTION_MM, check_motion, presliding_deflection, static_initial_guess
from ..identify.linear import bounded_lstsq
from ..identify.optimize import check_search_settings, multistart
from ..identify.static import velocity_range
from .kernels import lugre_trajectory_kernel
from .plant_laws import lugre_plant_law

__all__ = ["LuGreModel", "check_lugre_parameters", "simulate_lugre"]

#: Fraction of the sliding level reached after a reversal that is used to
#: relate the measured pre-sliding travel to the bristle stiffness.
_RECOVERY = 0.8


def check_lugre_parameters(sigma0, sigma1, coulomb, static, v_s) -> None:
    """Raise :class:`ParameterError` unless the LuGre parameters are physical.

    Parameters
    ----------
    sigma0 : float
        Bristle stiffness [A/mm], positive.
    sigma1 : float
        Bristle damping [A s/mm], non-negative.
    coulomb, static : float
        Coulomb and static levels [A], positive (``g(v)`` divides the bristle equation).
    v_s : float
        Stribeck velocity [mm/s], positive.
    """
    for name, value, unit in (("sigma0", sigma0, "A/mm"), ("Coulomb level", coulomb, "A"),
                              ("static level", static, "A"), ("v_s", v_s, "mm/s")):
        if not (np.isfinite(value) and value > 0.0):
            raise ParameterError(f"LuGre {name} must be positive and finite, got {value} {unit}")
    if not (np.isfinite(sigma1) and sigma1 >= 0.0):
        raise ParameterError(f"LuGre bristle damping sigma1 must be non-negative, got {sigma1} A s/mm")


def simulate_lugre(velocity, sample_time, *, sigma0, sigma1, sigma2, coulomb, static, v_s, z0=0.0):
    """LuGre friction of one run, exact zero-order-hold step.

    ``dz/dt = v - sigma0 |v| z / g(v)``, ``g(v) = F_c + (F_s - F_c) exp(-|v|/v_s)``,
    ``F = sigma0 z + sigma1 dz/dt + sigma2 v``, with ``v`` held over each step.

    Parameters
    ----------
    velocity : array_like, shape (n,)
        Velocity [mm/s].
    sample_time : float
        Step [s].
    sigma0, sigma1, sigma2 : float
        Bristle stiffness [A/mm], bristle damping [A s/mm], viscous coefficient [A s/mm].
    coulomb, static : float
        ``F_c`` and ``F_s`` [A].
    v_s : float
        Stribeck velocity [mm/s].
    z0 : float, default 0.0
        Initial bristle deflection [mm].

    Returns
    -------
    friction : ndarray, shape (n,)
        Friction [A].
    z : ndarray, shape (n,)
        Bristle deflection at each sample [mm].
    z_end : float
        Deflection after the last step [mm].
    """
    check_lugre_parameters(sigma0, sigma1, coulomb, static, v_s)
    v = np.ascontiguousarray(velocity, dtype=float)
    z, z_dot = np.empty(v.size), np.empty(v.size)
    z_end = lugre_trajectory_kernel(v, float(sample_time), float(sigma0), float(coulomb), float(static),
                                    float(v_s), float(z0), z, z_dot)
    return sigma0 * z + sigma1 * z_dot + sigma2 * v, z, z_end


class _Regression:
    """Separable least-squares problem of a LuGre fit for trial ``(sigma0, F_c, F_s, v_s)``.

    Columns: ``dz/dt``, ``v``, ``a`` (and ``1``), coefficients ``sigma1``,
    ``sigma2``, ``J`` (and the offset); target ``y - sigma0 z``.
    """

    def __init__(self, runs, fit_offset: bool):
        self.steps = [run.sample_time for run in runs]
        self.velocities = [run.velocity for run in runs]
        self.rows = np.cumsum([0] + [len(run) for run in runs])
        n_cols = 3 + int(fit_offset)
        self.matrix = np.ones((self.rows[-1], n_cols))
        self.matrix[:, 1] = np.concatenate([run.velocity for run in runs])
        self.matrix[:, 2] = np.concatenate([run.acceleration for run in runs])
        self.z = np.empty(self.rows[-1])
        self.effort = np.concatenate([run.effort for run in runs])
        self.norm = np.sqrt(self.effort.size * max(np.var(self.effort), np.finfo(float).tiny))
        self.lower = np.zeros(n_cols)
        self.lower[3:] = -np.inf
        self.upper = np.full(n_cols, np.inf)

    def solve(self, sigma0, coulomb, static, v_s):
        """Linear parameters and residuals over ``sqrt(n var(y))``."""
        for step, velocity, r0, r1 in zip(self.steps, self.velocities, self.rows[:-1], self.rows[1:]):
            lugre_trajectory_kernel(velocity, step, sigma0, coulomb, static, v_s, 0.0, self.z[r0:r1],
                                    self.matrix[r0:r1, 0])
        x, residual = bounded_lstsq(self.matrix, self.effort - sigma0 * self.z, self.lower, self.upper)
        return x, residual / self.norm


class LuGreModel(CurrentModel):
    """Inertia + LuGre friction (+ offset).

    ``I = J a + sigma0 z + sigma1 dz/dt + sigma2 v + I_0`` with the bristle
    deflection ``dz/dt = v - sigma0 |v| z / g(v)`` and the Stribeck curve
    ``g(v) = F_c + (F_s - F_c) exp(-|v|/v_s)``.

    The bristle equation is integrated exactly over each sample step with the
    velocity held (zero-order hold), which stays stable and accurate at a 2 ms
    step however stiff the bristles are; forward Euler would diverge once
    ``sigma0 |v| T / g(v) > 2``.

    Identification: a static Stribeck fit on the sliding samples gives the
    initial levels, the travel after reversals the initial stiffness; then a
    bounded multi-start search over ``sigma0``, ``F_c``, ``F_s``, ``v_s`` (log
    scale) with ``sigma1``, ``sigma2``, ``J`` (non-negative) and ``I_0`` solved
    by linear least squares at each trial.

    Parameters
    ----------
    fit_offset : bool, default False
        Fit a constant offset ``I_0`` [A].
    method : {"nelder-mead", "least-squares"}, default "nelder-mead"
        Local search (see :mod:`greybox.identify.optimize`).
    n_starts : int, default 3
        Number of starts of the search (the first from the initial guess).
    random_state : int or None, default 0
        Seed of the perturbed starts.
    max_iter : int, default 300
        Iterations per start (Nelder-Mead) or residual evaluations (least squares).

    Attributes
    ----------
    sigma0_ : float
        Bristle stiffness [A/mm].
    sigma1_ : float
        Bristle damping [A s/mm].
    viscous_ : float
        Viscous coefficient ``sigma2`` [A s/mm].
    coulomb_, static_ : float
        Coulomb and static levels ``F_c``, ``F_s`` [A].
    v_s_ : float
        Stribeck velocity [mm/s].
    J_ : float
        Inertia [A s^2/mm].
    offset_ : float
        Offset [A]; 0 when not fitted.
    cost_ : float
        Final cost: mean squared error over the effort variance (NMSE / 100).
    effort_unit_ : str
        Unit of the effort the model was fitted on, "A" or "N".
    """

    def __init__(self, *, fit_offset: bool = False, method: str = "nelder-mead", n_starts: int = 3,
                 random_state=0, max_iter: int = 300):
        self.fit_offset = fit_offset
        self.method = method
        self.n_starts = n_starts
        self.random_state = random_state
        self.max_iter = max_iter

    def _check_params(self) -> None:
        self._check_flags("fit_offset")
        check_search_settings(self)

    def _fit_runs(self, runs, progress) -> None:
        check_motion(runs)
        static = static_initial_guess(runs, fit_offset=self.fit_offset)
        delta = presliding_deflection(runs, static, fraction=_RECOVERY) or DEFAULT_DEFLECTION_MM
        regression = _Regression(runs, self.fit_offset)
        level = max(static["static"], static["coulomb"], 1e-6 * np.sqrt(np.mean(regression.effort ** 2)))
        coulomb = max(static["coulomb"], 1e-3 * level)
        peak = max(static["static"], 1e-3 * level)
        # single-spring travel to recover the level, expressed for the LuGre bristle
        sigma0 = np.log(2.0 / (1.0 - _RECOVERY)) / (1.0 + _RECOVERY) * peak / delta
        v_lo, v_hi = velocity_range(np.concatenate([run.velocity for run in runs]))
        theta0 = np.log([sigma0, coulomb, peak, min(max(static["v_s"], v_lo), v_hi)])
        lower = np.log([sigma0 * 1e-3, level * 1e-3, level * 1e-3, v_lo])
        upper = np.log([sigma0 * 1e3, level * 10.0, level * 10.0, v_hi])
        result = multistart(lambda theta: regression.solve(*np.exp(theta))[1], theta0, lower, upper,
                            scale=np.array([1.0, 0.3, 0.3, 1.0]), n_starts=self.n_starts,
                            random_state=self.random_state, method=self.method, max_iter=self.max_iter,
                            stage="LuGre", progress=progress)
        x, residual = regression.solve(*np.exp(result.x))
        self.sigma0_, self.coulomb_, self.static_, self.v_s_ = (float(value) for value in np.exp(result.x))
        self.sigma1_, self.viscous_, self.J_ = (float(value) for value in x[:3])
        self.offset_ = float(x[3]) if self.fit_offset else 0.0
        self.cost_ = float(residual @ residual)

    def initial_state(self) -> float:
        """Bristle deflection at the start of a run: ``0.0`` [mm]."""
        return 0.0

    def _simulate(self, run, state, sample_time):
        friction, _, z_end = simulate_lugre(run.velocity, sample_time, sigma0=self.sigma0_, sigma1=self.sigma1_,
                                            sigma2=self.viscous_, coulomb=self.coulomb_, static=self.static_,
                                            v_s=self.v_s_, z0=_as_deflection(state))
        return friction, float(z_end)

    def _n_params(self) -> int:
        return 7 + int(self.fit_offset)

    def _fit_statistics(self) -> dict:
        return {"cost": self.cost_}

    def _own_parameters(self) -> list[Parameter]:
        return [
            Parameter("sigma0", self.sigma0_, f"{EFFORT}/mm", "bristle stiffness"),
            Parameter("sigma1", self.sigma1_, f"{EFFORT} s/mm", "bristle damping"),
            Parameter("viscous", self.viscous_, f"{EFFORT} s/mm", "viscous coefficient sigma2"),
            Parameter("coulomb", self.coulomb_, EFFORT, "Coulomb level F_c"),
            Parameter("static", self.static_, EFFORT, "static level F_s"),
            Parameter("v_s", self.v_s_, "mm/s", "Stribeck velocity"),
        ]

    def plant_law(self):
        """The fitted LuGre law as the plant of a position loop (:func:`greybox.friction.plant_laws.lugre_plant_law`).

        Returns
        -------
        PlantLaw
            The bristle law with ``J_`` [A s^2/mm] and ``offset_`` [A] as constant load.
        """
        return lugre_plant_law(sigma0=self.sigma0_, sigma1=self.sigma1_, sigma2=self.viscous_, coulomb=self.coulomb_,
                               static=self.static_, v_s=self.v_s_, inertia=self.J_, offset=self.offset_)

    # ---------------------------------------------------------------- linear part
    def linear_part(self, run) -> LinearPart:
        """Columns ``dz/dt, v, a (, 1)`` at the fitted bristle law; ``sigma0 z`` is the fixed part."""
        v = np.ascontiguousarray(run.velocity, dtype=float)
        z, z_dot = np.empty(v.size), np.empty(v.size)
        lugre_trajectory_kernel(v, float(run.sample_time), self.sigma0_, self.coulomb_, self.static_,
                                self.v_s_, 0.0, z, z_dot)
        columns, names = [z_dot, v, run.acceleration], ["sigma1", "viscous", "J"]
        if self.fit_offset:
            columns.append(np.ones(len(run)))
            names.append("offset")
        return LinearPart.from_columns(columns, names, non_negative=3, fixed=self.sigma0_ * z)

    def linear_coefficients(self) -> np.ndarray:
        """``sigma1, viscous, J (, offset)``."""
        return np.array([self.sigma1_, self.viscous_, self.J_] + ([self.offset_] if self.fit_offset else []))

    def set_linear_coefficients(self, values) -> None:
        """Write ``values`` (order of :meth:`linear_coefficients`) into the fitted model."""
        x = [float(value) for value in np.asarray(values, dtype=float)]
        self.sigma1_, self.viscous_, self.J_ = x[:3]
        self.offset_ = x[3] if self.fit_offset else 0.0


def _as_deflection(state) -> float:
    """The LuGre state (a bristle deflection [mm]) as a float, or raise :class:`ParameterError`."""
    try:
        z = float(state)
    except (TypeError, ValueError):
        raise ParameterError(f"LuGre state must be a bristle deflection in mm, got {state!r}") from None
    if not np.isfinite(z):
        raise ParameterError(f"LuGre state must be a finite bristle deflection, got {z} mm")
    return z
