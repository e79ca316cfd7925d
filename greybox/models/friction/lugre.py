"""LuGre friction with inertia, integrated exactly over each sample step."""

from __future__ import annotations

import numpy as np

from ...base import EFFORT, LENGTH, LinearPart, Parameter
from ...errors import LogError, ParameterError
from ...identify.initial import (
    DEFAULT_DEFLECTION_MM,
    check_motion,
    presliding_deflection,
    sliding_mask,
    static_initial_guess,
)
from ...identify.linear import bounded_lstsq
from ...identify.optimize import check_search_settings, local_search, multistart
from ...identify.static import check_direction_settings, fit_stribeck, velocity_range
from ..estimator import CurrentModel
from .directions import direction_pair, viscous_columns
from .kernels import direction_curves, lugre_trajectory_kernel
from .plant_laws import lugre_plant_law

__all__ = ["LuGreModel", "check_lugre_parameters", "simulate_lugre"]

#: Fraction of the sliding level reached after a reversal that is used to
#: relate the measured pre-sliding travel to the bristle stiffness.
_RECOVERY = 0.8

#: Fewest sliding samples of one direction for its initial Stribeck fit (asymmetric model); with fewer,
#: all samples moving in that direction are used.
_MIN_DIRECTION_SAMPLES = 50


def _curves(coulomb, static, v_s) -> np.ndarray:
    """The kernel's ``curves`` (rows ``F_c, F_s - F_c, 1 / v_s`` of positive, negative motion), shape (2, 3)."""
    return direction_curves(direction_pair(static, "LuGre static level"),
                            direction_pair(coulomb, "LuGre Coulomb level"), direction_pair(v_s, "LuGre v_s"))


def check_lugre_parameters(sigma0, sigma1, coulomb, static, v_s) -> None:
    """Raise :class:`ParameterError` unless the LuGre parameters are physical.

    Parameters
    ----------
    sigma0 : float
        Bristle stiffness [A/mm], positive.
    sigma1 : float
        Bristle damping [A s/mm], non-negative.
    coulomb, static : float or (float, float)
        Coulomb and static levels [A], positive magnitudes (``g(v)`` divides the
        bristle equation); a pair gives positive and negative motion their own.
    v_s : float or (float, float)
        Stribeck velocity [mm/s], positive; one or one per direction.
    """
    for name, value, unit in (("sigma0", sigma0, "A/mm"), ("Coulomb level", coulomb, "A"),
                              ("static level", static, "A"), ("v_s", v_s, "mm/s")):
        values = np.asarray(value, dtype=float)
        if not np.all(np.isfinite(values) & (values > 0.0)):
            raise ParameterError(f"LuGre {name} must be positive and finite, got {value} {unit}")
    if not (np.isfinite(sigma1) and sigma1 >= 0.0):
        raise ParameterError(f"LuGre bristle damping sigma1 must be non-negative, got {sigma1} A s/mm")


def simulate_lugre(velocity, sample_time, *, sigma0, sigma1, sigma2, coulomb, static, v_s, z0=0.0):
    """LuGre friction of one run, exact zero-order-hold step.

    ``dz/dt = v - sigma0 |v| z / g(v)``, ``g(v) = F_c + (F_s - F_c) exp(-|v|/v_s)``,
    ``F = sigma0 z + sigma1 dz/dt + sigma2 v``, with ``v`` held over each step.
    ``sigma2``, ``F_c``, ``F_s`` and ``v_s`` may depend on the direction of
    motion (a pair: positive, negative motion; the levels are magnitudes).

    Parameters
    ----------
    velocity : array_like, shape (n,)
        Velocity [mm/s].
    sample_time : float
        Step [s].
    sigma0, sigma1 : float
        Bristle stiffness [A/mm], bristle damping [A s/mm].
    sigma2 : float or (float, float)
        Viscous coefficient [A s/mm], one or one per direction.
    coulomb, static : float or (float, float)
        ``F_c`` and ``F_s`` [A], one or one per direction.
    v_s : float or (float, float)
        Stribeck velocity [mm/s], one or one per direction.
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
    sigma2 = direction_pair(sigma2, "LuGre sigma2")
    check_lugre_parameters(sigma0, sigma1, coulomb, static, v_s)
    v = np.ascontiguousarray(velocity, dtype=float)
    z, z_dot = np.empty(v.size), np.empty(v.size)
    z_end = lugre_trajectory_kernel(v, float(sample_time), float(sigma0), _curves(coulomb, static, v_s), float(z0),
                                    z, z_dot)
    return sigma0 * z + sigma1 * z_dot + np.where(v < 0.0, sigma2[1], sigma2[0]) * v, z, z_end


def _search_point(theta):
    """``sigma0`` [A/mm] and the rows ``F_c`` [A], ``F_s`` [A], ``v_s`` [mm/s] of positive, negative motion.

    ``theta`` is ``log(sigma0, F_c, F_s, v_s)``, or ``log(sigma0)`` then
    ``log(F_c, F_s, v_s)`` of positive and of negative motion (asymmetric model).
    """
    values = np.exp(theta)
    return values[0], np.broadcast_to(values[1:].reshape(-1, 3), (2, 3))


class _Regression:
    """Separable least-squares problem of a LuGre fit for a trial stiffness and Stribeck curves.

    Columns: ``dz/dt``, ``v`` (or ``v [v > 0]``, ``v [v < 0]`` when the viscous
    coefficient depends on the direction), ``a`` (and ``1``); coefficients
    ``sigma1``, ``sigma2`` (or ``sigma2+``, ``sigma2-``), ``J`` (and the
    offset); target ``y - sigma0 z``.
    """

    def __init__(self, runs, fit_offset: bool, asymmetric: bool):
        self.steps = [run.sample_time for run in runs]
        self.velocities = [run.velocity for run in runs]
        self.rows = np.cumsum([0] + [len(run) for run in runs])
        velocity = np.concatenate(self.velocities)
        viscous, _ = viscous_columns(velocity, asymmetric)
        columns = [np.empty(velocity.size)] + viscous + [np.concatenate([run.acceleration for run in runs])]
        if fit_offset:
            columns.append(np.ones(velocity.size))
        self.matrix = np.column_stack(columns)
        self.z = np.empty(self.rows[-1])
        self.effort = np.concatenate([run.effort for run in runs])
        self.norm = np.sqrt(self.effort.size * max(np.var(self.effort), np.finfo(float).tiny))
        self.lower = np.zeros(len(columns))
        if fit_offset:
            self.lower[-1] = -np.inf
        self.upper = np.full(len(columns), np.inf)

    def solve(self, sigma0, levels):
        """Linear parameters and residuals over ``sqrt(n var(y))``.

        Parameters
        ----------
        sigma0 : float
            Bristle stiffness [A/mm].
        levels : ndarray, shape (2, 3)
            ``F_c`` [A], ``F_s`` [A], ``v_s`` [mm/s] of positive and of negative motion.
        """
        curves = _curves(levels[:, 0], levels[:, 1], levels[:, 2])
        for step, velocity, r0, r1 in zip(self.steps, self.velocities, self.rows[:-1], self.rows[1:]):
            lugre_trajectory_kernel(velocity, step, sigma0, curves, 0.0, self.z[r0:r1], self.matrix[r0:r1, 0])
        x, residual = bounded_lstsq(self.matrix, self.effort - sigma0 * self.z, self.lower, self.upper)
        return x, residual / self.norm


def _direction_guesses(runs) -> list[dict[str, float]]:
    """Initial Stribeck curves of positive and of negative motion.

    A Stribeck + viscous fit (:func:`greybox.identify.static.fit_stribeck`)
    of the sliding samples of each direction (all samples moving in that
    direction if fewer than 50 slide).

    Returns
    -------
    list of dict
        Fits of positive, then negative motion: ``coulomb`` and ``static``
        [A] (magnitudes), ``v_s`` [mm/s], among the other keys of ``fit_stribeck``.

    Raises
    ------
    LogError
        If the runs do not move in both directions.
    """
    sliding = [sliding_mask(run) for run in runs]
    guesses = []
    for sign, word in ((1.0, "positive"), (-1.0, "negative")):
        moving = [sign * run.velocity > 0.0 for run in runs]
        if not any(np.any(m) for m in moving):
            raise LogError(runs[0].source or None, f"no {word} motion: an asymmetric LuGre model needs motion "
                                                   "in both directions")
        masks = [m & s for m, s in zip(moving, sliding)]
        if sum(int(m.sum()) for m in masks) < _MIN_DIRECTION_SAMPLES:
            masks = moving
        guesses.append(fit_stribeck(*(np.concatenate([getattr(run, name)[m] for run, m in zip(runs, masks)])
                                      for name in ("velocity", "acceleration", "effort"))))
    return guesses


class LuGreModel(CurrentModel):
    """Inertia + LuGre friction (+ offset).

    ``I = J a + sigma0 z + sigma1 dz/dt + sigma2 v + I_0`` with the bristle
    deflection ``dz/dt = v - sigma0 |v| z / g(v)`` and the Stribeck curve
    ``g(v) = F_c + (F_s - F_c) exp(-|v|/v_s)``.

    With ``asymmetric=True`` the single bristle (``sigma0``, ``sigma1``) is
    kept, but the Stribeck curve and the viscous coefficient depend on the
    direction of motion: ``g(v) = F_c+ + (F_s+ - F_c+) exp(-v/v_s+)`` and
    ``sigma2 = sigma2+`` for ``v > 0``, ``g(v) = F_c- + (F_s- - F_c-)
    exp(-|v|/v_s-)`` and ``sigma2 = sigma2-`` for ``v < 0`` (levels are
    magnitudes); at rest ``dz/dt = 0`` whatever ``g``.

    The bristle equation is integrated exactly over each sample step with the
    velocity held (zero-order hold), which stays stable and accurate at a 2 ms
    step however stiff the bristles are; forward Euler would diverge once
    ``sigma0 |v| T / g(v) > 2``.

    Identification: a static Stribeck fit on the sliding samples gives the
    initial levels, the travel after reversals the initial stiffness; then a
    bounded multi-start search over ``sigma0``, ``F_c``, ``F_s``, ``v_s`` (log
    scale) with ``sigma1``, ``sigma2``, ``J`` (non-negative) and ``I_0`` solved
    by linear least squares at each trial. When ``asymmetric``, the initial
    curves come from a static fit per direction of motion; the multi-start
    search moves ``sigma0`` and shifts of ``F_c``, ``F_s``, ``v_s`` common to
    both directions, then one local search from its best point frees the
    curves of the two directions (seven parameters), with ``sigma2+``,
    ``sigma2-`` in the linear least squares.

    Parameters
    ----------
    asymmetric : bool, default False
        Give positive and negative motion their own Stribeck curve (``F_c``,
        ``F_s``, ``v_s``) and viscous coefficient; the bristle (``sigma0``,
        ``sigma1``) is shared. Not together with ``fit_offset`` (the offset
        and the levels of the two directions are not separately identifiable).
    fit_offset : bool, default False
        Fit a constant offset ``I_0`` [A].
    method : {"nelder-mead", "least-squares"}, default "nelder-mead"
        Local search (see :mod:`greybox.identify.optimize`).
    n_starts : int, default 3
        Number of starts of the search (the first from the initial guess).
    random_state : int or None, default 0
        Seed of the perturbed starts.
    max_iter : int, default 300
        Iterations per start (Nelder-Mead) or residual evaluations (least
        squares); the same for the per-direction search of the asymmetric model.
    inertia : float, optional
        Known inertia ``J`` [A s^2/mm] (e.g. from the drive's commissioning; 0 for an effort measured at the
        load, by a force or torque sensor on the device); identified from the runs when None.

    Attributes
    ----------
    sigma0_ : float
        Bristle stiffness [A/mm].
    sigma1_ : float
        Bristle damping [A s/mm].
    viscous_ : float
        Viscous coefficient ``sigma2`` [A s/mm] (of positive motion when ``asymmetric``).
    coulomb_, static_ : float
        Coulomb and static levels ``F_c``, ``F_s`` [A] (of positive motion when ``asymmetric``).
    v_s_ : float
        Stribeck velocity [mm/s] (of positive motion when ``asymmetric``).
    coulomb_neg_, static_neg_ : float
        Coulomb and static level magnitudes of negative motion [A]; only when ``asymmetric``.
    v_s_neg_ : float
        Stribeck velocity of negative motion [mm/s]; only when ``asymmetric``.
    viscous_neg_ : float
        Viscous coefficient of negative motion [A s/mm]; only when ``asymmetric``.
    J_ : float
        Inertia [A s^2/mm].
    offset_ : float
        Offset [A]; 0 when not fitted.
    cost_ : float
        Final cost: mean squared error over the effort variance (NMSE / 100).
    effort_unit_ : str
        Unit of the effort the model was fitted on, "A" or "N".
    """

    def __init__(self, *, asymmetric: bool = False, fit_offset: bool = False, method: str = "nelder-mead",
                 n_starts: int = 3, random_state=0, max_iter: int = 300, inertia=None):
        self.inertia = inertia
        self.asymmetric = asymmetric
        self.fit_offset = fit_offset
        self.method = method
        self.n_starts = n_starts
        self.random_state = random_state
        self.max_iter = max_iter

    def held_out_search(self) -> "LuGreModel":
        """A copy searching from the initial guess only (no perturbed starts), for scoring on held-out runs.

        Returns
        -------
        LuGreModel
        """
        return super().held_out_search().set_params(n_starts=1)

    def _check_params(self) -> None:
        self._check_flags("fit_offset", "asymmetric")
        check_direction_settings(self.asymmetric, self.fit_offset)
        check_search_settings(self)

    def _fit_runs(self, runs, progress) -> None:
        check_motion(runs)
        static = static_initial_guess(runs, fit_offset=self.fit_offset)
        delta = presliding_deflection(runs, static, fraction=_RECOVERY) or DEFAULT_DEFLECTION_MM
        regression = _Regression(runs, self.fit_offset, self.asymmetric)
        curves = _direction_guesses(runs) if self.asymmetric else [static]
        level = max([c[key] for c in [static] + curves for key in ("static", "coulomb")]
                    + [1e-6 * np.sqrt(np.mean(regression.effort ** 2))])
        # single-spring travel to recover the level, expressed for the LuGre bristle
        peak = max(static["static"], 1e-3 * level)
        sigma0 = np.log(2.0 / (1.0 - _RECOVERY)) / (1.0 + _RECOVERY) * peak / delta
        v_lo, v_hi = velocity_range(np.concatenate([run.velocity for run in runs]))
        theta0 = np.log([sigma0] + [value for c in curves for value in (
            max(c["coulomb"], 1e-3 * level), max(c["static"], 1e-3 * level), min(max(c["v_s"], v_lo), v_hi))])
        lower = np.log([sigma0 * 1e-3] + [level * 1e-3, level * 1e-3, v_lo] * len(curves))
        upper = np.log([sigma0 * 1e3] + [level * 10.0, level * 10.0, v_hi] * len(curves))
        scale = np.array([1.0, 0.3, 0.3, 1.0])

        def residuals(theta):
            return regression.solve(*_search_point(theta))[1]

        if self.asymmetric:
            # stage 1: stiffness and log-shifts of F_c, F_s, v_s common to both directions (the ratios of the
            # directions' static fits kept), a 4-parameter search as in the symmetric model
            def expand(p):
                return np.clip(theta0 + np.concatenate((p, p[1:])), lower, upper)

            width = (upper - lower)[:4]
            common = multistart(lambda p: residuals(expand(p)), np.zeros(4), -width, width, scale=scale,
                                n_starts=self.n_starts, random_state=self.random_state, method=self.method,
                                max_iter=self.max_iter, stage="LuGre", progress=progress)
            # stage 2: every curve parameter of each direction from the best common fit
            result = local_search(residuals, expand(common.x), lower, upper, scale=np.concatenate((scale, scale[1:])),
                                  method=self.method, max_iter=self.max_iter, stage="LuGre per direction",
                                  progress=progress, best_so_far=common.cost)
        else:
            result = multistart(residuals, theta0, lower, upper, scale=scale, n_starts=self.n_starts,
                                random_state=self.random_state, method=self.method, max_iter=self.max_iter,
                                stage="LuGre", progress=progress)
        sigma0, levels = _search_point(result.x)
        x, residual = regression.solve(sigma0, levels)
        self.sigma0_ = float(sigma0)
        self.coulomb_, self.static_, self.v_s_ = (float(value) for value in levels[0])
        if self.asymmetric:
            self.coulomb_neg_, self.static_neg_, self.v_s_neg_ = (float(value) for value in levels[1])
        self.set_linear_coefficients(x)
        self.cost_ = float(residual @ residual)

    def _law(self) -> dict:
        """Keyword arguments of :func:`simulate_lugre` and of the plant law: pairs per direction when ``asymmetric``."""
        law = {"sigma0": self.sigma0_, "sigma1": self.sigma1_, "sigma2": self.viscous_, "coulomb": self.coulomb_,
               "static": self.static_, "v_s": self.v_s_}
        if self.asymmetric:
            law.update(sigma2=(self.viscous_, self.viscous_neg_), coulomb=(self.coulomb_, self.coulomb_neg_),
                       static=(self.static_, self.static_neg_), v_s=(self.v_s_, self.v_s_neg_))
        return law

    def initial_state(self) -> float:
        """Bristle deflection at the start of a run: ``0.0`` [mm]."""
        return 0.0

    def _simulate(self, run, state, sample_time):
        friction, _, z_end = simulate_lugre(run.velocity, sample_time, **self._law(), z0=_as_deflection(state))
        return friction, float(z_end)

    def _n_params(self) -> int:
        return 7 + 4 * int(self.asymmetric) + int(self.fit_offset)

    def _fit_statistics(self) -> dict:
        return {"cost": self.cost_}

    def _own_parameters(self) -> list[Parameter]:
        bristle = [
            Parameter("sigma0", self.sigma0_, f"{EFFORT}/{LENGTH}", "bristle stiffness"),
            Parameter("sigma1", self.sigma1_, f"{EFFORT} s/{LENGTH}", "bristle damping"),
        ]
        curve = [("viscous", f"{EFFORT} s/{LENGTH}", "viscous coefficient sigma2", self.viscous_),
                 ("coulomb", EFFORT, "Coulomb level F_c", self.coulomb_),
                 ("static", EFFORT, "static level F_s", self.static_),
                 ("v_s", f"{LENGTH}/s", "Stribeck velocity", self.v_s_)]
        if not self.asymmetric:
            return bristle + [Parameter(name, value, unit, text) for name, unit, text, value in curve]
        negative = (self.viscous_neg_, self.coulomb_neg_, self.static_neg_, self.v_s_neg_)
        return bristle + [row for (name, unit, text, value), value_neg in zip(curve, negative)
                          for row in (Parameter(name, value, unit, f"{text}, positive motion"),
                                      Parameter(f"{name}_neg", value_neg, unit, f"{text}, negative motion"))]

    def plant_law(self):
        """The fitted LuGre law as the plant of a position loop (:func:`~.plant_laws.lugre_plant_law`).

        Returns
        -------
        PlantLaw
            The bristle law with ``J_`` [A s^2/mm] and ``offset_`` [A] as constant load.
        """
        return lugre_plant_law(**self._law(), inertia=self.J_, offset=self.offset_)

    def interval_coordinates(self) -> dict[str, str]:
        """Bristle stiffness and the Stribeck curve (per direction if asymmetric), on a log scale."""
        names = ["sigma0_", "coulomb_", "static_", "v_s_"]
        if self.asymmetric:
            names += ["coulomb_neg_", "static_neg_", "v_s_neg_"]
        return dict.fromkeys(names, "log")

    # ---------------------------------------------------------------- linear part
    def linear_part(self, run) -> LinearPart:
        """Columns ``dz/dt, v, a (, 1)`` at the fitted bristle law; ``sigma0 z`` is the fixed part.

        ``v`` is the two columns ``v [v > 0]``, ``v [v < 0]`` when ``asymmetric``.

        Parameters
        ----------
        run : AxisLog
            One prepared run (velocity and acceleration present), as in the base class.
        """
        law = self._law()
        v = np.ascontiguousarray(run.velocity, dtype=float)
        z, z_dot = np.empty(v.size), np.empty(v.size)
        lugre_trajectory_kernel(v, float(run.sample_time), self.sigma0_,
                                _curves(law["coulomb"], law["static"], law["v_s"]), 0.0, z, z_dot)
        viscous, viscous_names = viscous_columns(v, self.asymmetric)
        columns, names = [z_dot] + viscous + [run.acceleration], ["sigma1"] + viscous_names + ["J"]
        if self.fit_offset:
            columns.append(np.ones(len(run)))
            names.append("offset")
        return LinearPart.from_columns(columns, names, non_negative=len(names) - int(self.fit_offset),
                                       fixed=self.sigma0_ * z)

    def linear_coefficients(self) -> np.ndarray:
        """``sigma1, viscous, J (, offset)``; ``viscous_pos, viscous_neg`` for ``viscous`` when ``asymmetric``."""
        viscous = [self.viscous_, self.viscous_neg_] if self.asymmetric else [self.viscous_]
        return np.array([self.sigma1_] + viscous + [self.J_] + ([self.offset_] if self.fit_offset else []))

    def set_linear_coefficients(self, values) -> None:
        """Write ``values`` (order of :meth:`linear_coefficients`) into the model.

        Parameters
        ----------
        values : array_like, shape (p,)
            Values of the linear parameters, in the order of :meth:`linear_coefficients`.
        """
        x = [float(value) for value in np.asarray(values, dtype=float)]
        self.sigma1_, self.viscous_ = x[:2]
        if self.asymmetric:
            self.viscous_neg_ = x[2]
        self.J_ = x[2 + int(self.asymmetric)]
        self.offset_ = x[3 + int(self.asymmetric)] if self.fit_offset else 0.0


def _as_deflection(state) -> float:
    """The LuGre state (a bristle deflection [mm]) as a float, or raise :class:`ParameterError`."""
    try:
        z = float(state)
    except (TypeError, ValueError):
        raise ParameterError(f"LuGre state must be a bristle deflection in mm, got {state!r}") from None
    if not np.isfinite(z):
        raise ParameterError(f"LuGre state must be a finite bristle deflection, got {z} mm")
    return z
