"""Generalized Maxwell-Slip (GMS) friction with inertia, forward Euler at the log's step.

Model (see docs/friction-models.md), elements ``i = 1..N`` sharing the Stribeck
curve ``s(v) = s_inf + (s_0 - s_inf) exp(-|v|/v_s)`` scaled by ``alpha_i``:

- stick: ``z_i[k+1] = z_i[k] + T v[k]`` until ``|z_i|`` reaches ``alpha_i s(v)``
  in the direction of motion (the element breaks away, ``z_i`` is held at the
  limit);
- slip: ``z_i[k+1] = z_i[k] + T alpha_i C (sgn(v) - z_i[k] / (alpha_i s(v)))``
  until the velocity reverses or stops, then the element sticks again;
- ``I = J a + sum_i (k_i z_i + alpha_i sigma dz_i/dt) + mu v (+ I_0)``.

Units with positions in mm and velocities in mm/s: ``z_i``, ``s_0``,
``s_inf`` in mm (element deflections), ``k_i`` in A/mm, ``C`` in mm/s,
``sigma`` and ``mu`` in A s/mm, ``J`` in A s^2/mm (replace A by N for force
logs). In steady sliding every element sits at ``sgn(v) alpha_i s(v)``, so the
friction is ``sgn(v) K s(v) + mu v`` with ``K = sum_i k_i alpha_i``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from sklearn.base import clone
from sklearn.utils.validation import check_is_fitted

from ...base import EFFORT, LENGTH, LinearPart, Parameter
from ...errors import ParameterError, Setting
from ...identify.initial import (
    DEFAULT_DEFLECTION_MM,
    check_motion,
    direction_level_ratio,
    largest_friction,
    presliding_deflection,
    presliding_travels,
    static_initial_guess,
)
from ...identify.linear import bounded_lstsq
from ...identify.optimize import (
    Stall,
    check_search_settings,
    fixed_design,
    local_search,
    multistart,
    multistart_results,
)
from ...identify.static import check_direction_settings, velocity_range
from ..estimator import CurrentModel
from .directions import direction_pair, viscous_columns
from .kernels import direction_curves, gms_friction_kernel, gms_trajectory_kernel
from .plant_laws import gms_plant_law

__all__ = ["GMSModel", "GMSState", "ShapeLimits", "MAX_STRIBECK_RATIO", "BREAKAWAY_MARGIN", "check_gms_parameters",
           "simulate_gms", "gms_trajectory", "gms_trajectory_runner"]

#: Largest ``T C / min(s_0, s_inf)`` the identification allows: the slip step
#: then relaxes monotonically (no overshoot), well inside the stability limit 2.
MAX_SLIP_STEP_RATIO = 1.0

#: ``T C / min(s_0, s_inf)`` of the further, fixed starts of the pre-sliding stage (the first is at 0.5), a
#: decade apart down to the bound 1e-3: the cost has separate basins of fast and of slow slip (EMPS: 0.5 and
#: 0.05; the ARTS device: about 0.002), and a start in each makes the result independent of the seed of the
#: perturbed starts.
_SLOW_SLIP_RATIOS = (0.05, 0.005)

#: Residual evaluations of the least-squares polish after the joint Nelder-Mead search (Jacobians not counted).
_POLISH_EVALUATIONS = 100

#: An element whose share ``k_i alpha_i / sum_j k_j alpha_j`` of the sliding force is at most this is pruned
#: after the fit (it carries no force: a zero stiffness at the bound of the linear fit, or a negligible one).
PRUNE_SHARE = 1e-6

#: Relative difference of the training cost within which two joint fits count as equally good: of those within
#: it of the best, the one from the earliest start wins (the initial guess, then the fixed slow-slip starts,
#: then the perturbed ones), so that where the training data leave the shape nearly free (ARTS) the model does
#: not hang on the seed of the perturbed starts.
_COST_TIE = 0.01

#: When the Nelder-Mead searches of the staged fit (pre-sliding and joint) stop besides their own rules: once the
#: best cost fell by less than a hundredth of :data:`_COST_TIE` over the last 10 (p + 1) evaluations (about ten
#: replacements of every vertex of the simplex). The fit counts joint fits within :data:`_COST_TIE` of the best as
#: equally good, so a search need not resolve a hundredth of it; and each joint fit is polished by least squares
#: from where its simplex stopped. Without it every start ran to ``max_iter``: the simplex's own rule (a cost
#: spread of 1e-10, some 1e-8 of the cost) never held, and a start held at the shape limits (a flat cost) went
#: on for hundreds of evaluations at one cost.
SEARCH_STALL = Stall(tolerance=_COST_TIE / 100.0, window=10)

#: Ratio of the largest to the smallest element fraction of the initial guess.
_ALPHA_SPREAD = 20.0

#: Bounds of the element-fraction logits (alpha_i proportional to exp(u_i), u_1 = 0).
_LOGIT_BOUND = 6.0

#: ``n_starts`` of a fit that only scores a candidate on held-out runs (:meth:`GMSModel.held_out_search`): the
#: initial guess and the fixed slow-slip starts, whose basins decide the fit; the perturbed starts refine it.
HELD_OUT_STARTS = 1

#: Largest ``s_0 / s_inf`` whatever the runs allow: a break-away friction ten times the sliding one is beyond
#: lubricated guides and screws. The runs usually bound it tighter (:class:`ShapeLimits`).
MAX_STRIBECK_RATIO = 10.0

#: How far the break-away level ``K s_0`` may exceed the largest friction the runs measured [-]: a run that
#: never rests long enough, or a static fit whose Coulomb level is off, shows less than the full level.
BREAKAWAY_MARGIN = 2.0


class ShapeLimits(NamedTuple):
    """Bounds of a GMS shape that the training runs give (:meth:`GMSModel._shape` holds every trial to them).

    Attributes
    ----------
    ratio : float
        Largest ``s_0 / s_inf`` [-] per direction: :data:`BREAKAWAY_MARGIN` times the largest friction
        measured (:func:`~greybox.identify.initial.largest_friction`) over the static fit's Coulomb level, at
        least 1, at most :data:`MAX_STRIBECK_RATIO`. In steady sliding the friction is ``K s(v)``, so
        ``K s_inf`` is the Coulomb level and ``K s_0`` the break-away level, which no run exceeded by much:
        every run starts from rest, and the drive broke the axis free.
    deflection : float
        Largest break-away deflection of the largest element, ``max(alpha_i) s_0`` and ``max(alpha_i) s_inf``
        [mm]: the longest travel after a reversal from sliding within which the friction recovered 80 % of
        its new level (:func:`~greybox.identify.initial.presliding_travels`); the element that carries the
        most force cannot need more travel to break away than the runs showed. Infinite when the runs have
        no such reversal.
    """

    ratio: float
    deflection: float

    @classmethod
    def of_runs(cls, runs, static: dict) -> "ShapeLimits":
        """The limits the prepared ``runs`` and their static fit (``static_initial_guess``) give.

        Parameters
        ----------
        runs : list of AxisLog
            Prepared runs.
        static : dict
            :func:`~greybox.identify.initial.static_initial_guess` of the runs.
        """
        coulomb = float(static["coulomb"])
        ratio = BREAKAWAY_MARGIN * largest_friction(runs, static) / coulomb if coulomb > 0.0 else MAX_STRIBECK_RATIO
        travels = presliding_travels(runs, static)
        return cls(float(np.clip(ratio, 1.0, MAX_STRIBECK_RATIO)),
                   float(travels.max()) if travels.size else np.inf)

    def hold(self, s_0: np.ndarray, s_inf: np.ndarray, largest: float) -> tuple[np.ndarray, np.ndarray]:
        """``s_0`` and ``s_inf`` [mm] (one value per direction) held to the limits.

        Parameters
        ----------
        s_0, s_inf : ndarray
            Break-away deflections at rest and at high speed [mm].
        largest : float
            The largest element fraction ``max(alpha_i)`` [-].
        """
        most = self.deflection / largest
        s_inf = np.minimum(s_inf, most)
        return np.minimum(np.minimum(s_0, self.ratio * s_inf), most), s_inf


class GMSState(NamedTuple):
    """State of the GMS elements between two samples.

    Attributes
    ----------
    z : ndarray, shape (N,)
        Element deflections [mm].
    mode : ndarray of int8, shape (N,)
        0 sticking, +1 / -1 slipping in the positive / negative direction.
    """

    z: np.ndarray
    mode: np.ndarray

    @classmethod
    def at_rest(cls, n_elements: int) -> "GMSState":
        """All elements relaxed (``z = 0``) and sticking.

        Parameters
        ----------
        n_elements : int
            Number ``N`` of GMS elements.
        """
        return cls(np.zeros(n_elements), np.zeros(n_elements, dtype=np.int8))


def check_gms_parameters(alpha, k, C, sigma, s_0, s_inf, v_s, mu, sample_time=None) -> None:
    """Raise :class:`ParameterError` unless the GMS parameters are valid (and stable at ``sample_time``).

    Parameters
    ----------
    alpha : array_like, shape (N,)
        Element fractions, positive, summing to 1.
    k : array_like, shape (N,)
        Element stiffnesses [A/mm], non-negative.
    C : float
        Slip rate constant [mm/s], positive.
    sigma : float
        Micro-damping [A s/mm], non-negative.
    s_0, s_inf : float or (float, float)
        Stribeck curve of the break-away deflection at rest and at high speed
        [mm], positive; a pair gives positive and negative motion their own.
    v_s : float or (float, float)
        Stribeck velocity [mm/s], positive; one or one per direction.
    mu : float or (float, float)
        Viscous coefficient [A s/mm], non-negative; one or one per direction.
    sample_time : float, optional
        Forward-Euler step [s]; if given, the slip step must be stable:
        ``T C / min(s_0, s_inf) < 2`` over both directions (``C_i / s_i(v) =
        C / s(v)`` for every element and ``s(v)`` lies between ``s_0`` and ``s_inf``).
    """
    alpha = np.asarray(alpha, dtype=float)
    k = np.asarray(k, dtype=float)
    if alpha.ndim != 1 or alpha.size < 1 or k.shape != alpha.shape:
        raise ParameterError(f"GMS alpha and k must be 1-D of the same length N >= 1, got shapes "
                             f"{alpha.shape} and {k.shape}")
    if not np.all(np.isfinite(alpha)) or np.any(alpha <= 0.0):
        raise ParameterError(f"GMS element fractions alpha must be positive, got {alpha.tolist()}")
    if abs(alpha.sum() - 1.0) > 1e-9:
        raise ParameterError(f"GMS element fractions alpha must sum to 1, they sum to {alpha.sum():.12g}")
    if not np.all(np.isfinite(k)) or np.any(k < 0.0):
        raise ParameterError(f"GMS stiffnesses k must be non-negative (negative stiffness is unstable), "
                             f"got {k.tolist()} A/mm")
    if not (np.isfinite(C) and C > 0.0):
        raise ParameterError(f"GMS parameter C must be positive and finite, got {C} mm/s")
    for name, value, unit in (("s_0", s_0, "mm"), ("s_inf", s_inf, "mm"), ("v_s", v_s, "mm/s")):
        pair = direction_pair(value, f"GMS {name}")
        if not np.all(np.isfinite(pair) & (pair > 0.0)):
            raise ParameterError(f"GMS parameter {name} must be positive and finite, got {_shown(pair)} {unit}")
    for name, value in (("sigma", sigma), ("mu", mu)):
        pair = direction_pair(value, f"GMS {name}")
        if not np.all(np.isfinite(pair) & (pair >= 0.0)):
            raise ParameterError(f"GMS parameter {name} must be non-negative, got {_shown(pair)} A s/mm")
    if sample_time is not None:
        if not (np.isfinite(sample_time) and sample_time > 0.0):
            raise ParameterError(f"sample time must be positive, got {sample_time} s")
        smallest = float(min(direction_pair(s_0, "GMS s_0").min(), direction_pair(s_inf, "GMS s_inf").min()))
        ratio = sample_time * C / smallest
        if ratio >= 2.0:
            raise ParameterError(
                f"GMS forward-Euler slip step is unstable at T = {sample_time * 1e3:.4g} ms: "
                f"T*C/min(s_0, s_inf) = {ratio:.4g} >= 2 (C = {C:.6g} mm/s, min(s_0, s_inf) = "
                f"{smallest:.6g} mm); use a step below {2.0 * smallest / C * 1e3:.4g} ms "
                "or parameters identified at this step")


def _shown(pair: np.ndarray):
    """A pair as the user gave it: one number when both directions agree."""
    same = pair[0] == pair[1] or (np.isnan(pair[0]) and np.isnan(pair[1]))
    return float(pair[0]) if same else pair.tolist()


def _curves(s_0, s_inf, v_s) -> np.ndarray:
    """Kernel ``curves`` argument from one number or a pair per direction for each parameter."""
    return direction_curves(direction_pair(s_0, "GMS s_0"), direction_pair(s_inf, "GMS s_inf"),
                            direction_pair(v_s, "GMS v_s"))


def _as_state(state, n_elements: int) -> GMSState:
    if state is None:
        return GMSState.at_rest(n_elements)
    z = np.array(state[0], dtype=float)
    mode = np.array(state[1], dtype=np.int8)
    if z.shape != (n_elements,) or mode.shape != (n_elements,) or np.any(np.abs(mode) > 1):
        raise ParameterError(f"GMS state must hold {n_elements} deflections and modes in (-1, 0, 1)")
    return GMSState(z, mode)


def simulate_gms(velocity, sample_time, *, alpha, k, C, sigma, s_0, s_inf, v_s, mu, state=None):
    """GMS friction of one run, forward Euler at a constant step.

    Parameters
    ----------
    velocity : array_like, shape (n,)
        Velocity [mm/s].
    sample_time : float
        Step T [s].
    alpha, k, C, sigma, s_0, s_inf, v_s, mu
        Parameters, see :func:`check_gms_parameters` (``s_0``, ``s_inf``,
        ``v_s``, ``mu`` one number or a pair for positive and negative motion).
    state : GMSState or (z, mode), optional
        State before the first sample; all elements at rest by default.

    Returns
    -------
    friction : ndarray, shape (n,)
        Friction [A].
    state : GMSState
        State after the last sample (the initial state of a following chunk).
    """
    alpha = np.ascontiguousarray(alpha, dtype=float)
    k = np.ascontiguousarray(k, dtype=float)
    check_gms_parameters(alpha, k, C, sigma, s_0, s_inf, v_s, mu, sample_time)
    start = _as_state(state, alpha.size)
    friction, z, mode = gms_friction_kernel(np.ascontiguousarray(velocity, dtype=float), float(sample_time),
                                            alpha, k, float(sigma), _curves(s_0, s_inf, v_s), float(C),
                                            direction_pair(mu, "GMS mu"), start.z, start.mode)
    return friction, GMSState(z, mode)


def gms_trajectory(velocity, sample_time, *, alpha, C, s_0, s_inf, v_s, k=None, sigma=0.0, mu=0.0, state=None):
    """Element deflections, stick flags and friction of the GMS model over one run, in one pass.

    Parameters
    ----------
    velocity : array_like, shape (n,)
        Velocity [mm/s].
    sample_time : float
        Step T [s].
    alpha, C, s_0, s_inf, v_s
        Shape parameters, see :func:`check_gms_parameters` (the element states
        depend on these only; ``s_0``, ``s_inf``, ``v_s`` one number or a pair
        for positive and negative motion).
    k, sigma, mu : optional
        Stiffnesses [A/mm], micro-damping and viscous coefficient (one or a
        pair) [A s/mm] of the friction; zero by default (then the friction
        returned is zero).
    state : GMSState or (z, mode), optional
        State before the first sample; all elements at rest by default.

    Returns
    -------
    z : ndarray, shape (n, N)
        Deflection of each element at each sample [mm].
    stick : ndarray of bool, shape (n, N)
        True where the element sticks.
    w : ndarray, shape (n,)
        ``sum_i alpha_i dz_i/dt`` [mm/s] (the damping term is ``sigma * w``).
    friction : ndarray, shape (n,)
        Friction [A], equal to :func:`simulate_gms`'s.
    state : GMSState
        State after the last sample.
    """
    runner = gms_trajectory_runner(sample_time, alpha=alpha, C=C, s_0=s_0, s_inf=s_inf, v_s=v_s, k=k, sigma=sigma,
                                   mu=mu)
    return runner(velocity, state)


def gms_trajectory_runner(sample_time, *, alpha, C, s_0, s_inf, v_s, k=None, sigma=0.0, mu=0.0):
    """:func:`gms_trajectory` with its parameters checked and converted once, for the chunks of a stream.

    Parameters
    ----------
    sample_time : float
        Step T [s].
    alpha, C, s_0, s_inf, v_s, k, sigma, mu
        As in :func:`gms_trajectory`.

    Returns
    -------
    callable
        ``runner(velocity, state)`` [mm/s, GMSState or None] returning what :func:`gms_trajectory` returns.

    Raises
    ------
    ParameterError
        As :func:`check_gms_parameters`.
    """
    alpha = np.ascontiguousarray(alpha, dtype=float)
    k = np.zeros_like(alpha) if k is None else np.ascontiguousarray(k, dtype=float)
    check_gms_parameters(alpha, k, C, sigma, s_0, s_inf, v_s, mu, sample_time)
    step, sigma, C = float(sample_time), float(sigma), float(C)
    curves, mu = _curves(s_0, s_inf, v_s), direction_pair(mu, "GMS mu")

    handed = [None]  # the state the last call returned: made by the kernel (which copies it), it needs no check

    def runner(velocity, state=None):
        start = state if state is not None and state is handed[0] else _as_state(state, alpha.size)
        velocity = np.ascontiguousarray(velocity, dtype=float)
        z = np.empty((velocity.size, alpha.size))
        mode = np.empty((velocity.size, alpha.size), dtype=np.int8)
        w, friction = np.empty(velocity.size), np.empty(velocity.size)
        z_end, mode_end = gms_trajectory_kernel(velocity, step, alpha, k, sigma, curves, C, mu, start.z, start.mode,
                                                z, mode, w, friction)
        handed[0] = GMSState(z_end, mode_end)
        return z, mode == 0, w, friction, handed[0]

    return runner


class _Regression:
    """Separable least-squares problem of a GMS fit: regressors are rebuilt in place per trial shape.

    Columns of the regressor matrix: ``z_1..z_N`` (element deflections),
    ``w`` (damping term), ``v`` (or ``v [v > 0]``, ``v [v < 0]`` when the
    viscous term depends on the direction), ``a`` (and ``1``); coefficients
    ``k_1..k_N``, ``sigma``, ``mu`` (or ``mu+``, ``mu-``), ``J`` (and the offset).
    """

    def __init__(self, runs, n_elements: int, fit_offset: bool, asymmetric: bool):
        self.n_elements = n_elements
        self.steps = [run.sample_time for run in runs]
        self.velocities = [run.velocity for run in runs]
        self.rows = np.cumsum([0] + [len(run) for run in runs])
        velocity = np.concatenate(self.velocities)
        motion, _ = viscous_columns(velocity, asymmetric)
        acceleration = np.concatenate([run.acceleration for run in runs])
        fixed = np.column_stack(motion + [acceleration] + ([np.ones(velocity.size)] if fit_offset else []))
        n_cols = n_elements + 1 + fixed.shape[1]
        self.matrix = np.empty((self.rows[-1], n_cols))
        self.matrix[:, n_elements + 1:] = fixed
        self.modes = np.empty((self.rows[-1], n_elements), dtype=np.int8)
        self.no_friction = np.empty(self.rows[-1])
        self.zeros = np.zeros(n_elements)
        self.target = np.concatenate([run.effort for run in runs])
        self.norm = np.sqrt(self.target.size * max(np.var(self.target), np.finfo(float).tiny))
        self.lower = np.zeros(n_cols)
        if fit_offset:
            self.lower[-1] = -np.inf
        self.upper = np.full(n_cols, np.inf)

    def solve(self, shape):
        """Linear parameters and residuals over ``sqrt(n var(y))`` for ``shape = (alpha, s_0, s_inf, v_s, C)``."""
        alpha, s_0, s_inf, v_s, c = shape
        curves = _curves(s_0, s_inf, v_s)
        rest = GMSState.at_rest(self.n_elements)
        n = self.n_elements
        no_viscous = np.zeros(2)
        for step, velocity, r0, r1 in zip(self.steps, self.velocities, self.rows[:-1], self.rows[1:]):
            gms_trajectory_kernel(velocity, step, alpha, self.zeros, 0.0, curves, c, no_viscous, rest.z, rest.mode,
                                  self.matrix[r0:r1, :n], self.modes[r0:r1], self.matrix[r0:r1, n],
                                  self.no_friction[r0:r1])
        x, residual = bounded_lstsq(self.matrix, self.target, self.lower, self.upper)
        return x, residual / self.norm


def _alpha_from_logits(logits: np.ndarray) -> np.ndarray:
    e = np.exp(np.concatenate(([0.0], logits)) - max(0.0, float(np.max(logits, initial=0.0))))
    return e / e.sum()


class GMSModel(CurrentModel):
    """Inertia + Generalized Maxwell-Slip friction (+ offset), the physical part of the grey-box model.

    ``I = J a + sum_i (k_i z_i + alpha_i sigma dz_i/dt) + mu v + I_0``, forward
    Euler at the step of each log (see the module notes for the element law
    and units). Every run is simulated from rest.

    Identification (separable least squares): the element trajectories depend
    only on the *shape* parameters ``alpha``, ``s_0``, ``s_inf``, ``v_s``,
    ``C``, and the effort is linear in ``k_i``, ``sigma``, ``mu``, ``J``
    (non-negative) and ``I_0``, which are solved by linear least squares at
    every trial shape. The shape is searched in stages:

    1. static: Stribeck + viscous fit on the sliding samples (``s_0 / s_inf``,
       ``v_s``), pre-sliding deflection from the travel after reversals;
    2. pre-sliding: element fractions, a common scale of ``s_0`` and
       ``s_inf`` (and, when ``asymmetric``, the ratio of the two directions),
       and ``C``; multi-start from the initial guess, from the same guess
       with a ten and a hundred times slower slip, and from perturbations
       of it by a fixed design (:func:`~greybox.identify.optimize.fixed_design`),
       the same for every seed: seeded perturbations gave the asymmetric
       model on the ARTS device a different fit per seed (test RE 0.85
       points apart, docs/arts-benchmark.md);
    3. joint: all shape parameters, from every result of stage 2, each
       polished by least squares; of the
       fits within :data:`_COST_TIE` of the lowest training cost, the one from
       the earliest start (the initial guess, the fixed starts, then the
       perturbed ones) is the model. The fast- and the slow-slip starts reach
       the basins the cost has along ``C``, so the result no longer hangs on
       which perturbed start happens to win stage 2 (seed spread of the
       EMPS cross-test relerr from 0.22 to below 0.01 percentage points; the
       hundred times slower start for the ARTS device, whose slip is slower
       still, see docs/arts-benchmark.md).
    4. pruning: an element left with no share of the sliding force (its
       stiffness at the bound 0 of the linear fit) is dropped, the others
       kept as they are, and the linear part refitted (``n_pruned_``).

    ``C`` is searched as ``r = T C / min(s_0, s_inf)`` in ``(0, 1]`` (``T``
    the largest step of the runs), so the forward-Euler slip step is stable
    and free of overshoot for every trial.

    Parameters
    ----------
    n_elements : int, default 4
        Number of Maxwell-slip elements N.
    asymmetric : bool, default False
        Give positive and negative motion their own Stribeck curve of the
        break-away deflection (``s_0``, ``s_inf``, ``v_s``) and viscous
        coefficient; the elements (``alpha_i``, ``k_i``, ``C``, ``sigma``) are
        shared. Not together with ``fit_offset`` (the offset and the two
        sliding levels are not separately identifiable).
    fit_offset : bool, default False
        Fit a constant offset ``I_0`` [A].
    method : {"nelder-mead", "least-squares"}, default "nelder-mead"
        Local search (see :mod:`greybox.identify.optimize`).
    n_starts : int, default 4
        Starts of the pre-sliding stage besides the two slow-slip ones (the first from the initial guess,
        the others perturbed).
    random_state : int or None, default 0
        Seed of the perturbed starts of the unstaged search (``staged=False``); the staged search
        perturbs its starts by a fixed design and gives the same model for every seed.
    max_iter : int, default 400
        Iterations per start (Nelder-Mead) or residual evaluations (least squares).
    staged : bool, default True
        Run stage 2 before the joint search; if False, the multi-start search
        runs on all shape parameters directly.
    inertia : float, optional
        Known inertia ``J`` [A s^2/mm] (e.g. from the drive's commissioning; 0 for an effort measured at the
        load, by a force or torque sensor on the device); identified from the runs when None.

    Attributes
    ----------
    alpha_ : ndarray, shape (N,)
        Element fractions (sum 1).
    k_ : ndarray, shape (N,)
        Element stiffnesses [A/mm].
    slip_rate_ : float
        Slip rate constant ``C`` [mm/s].
    sigma_ : float
        Micro-damping [A s/mm].
    s_0_, s_inf_ : float
        Stribeck curve of the break-away deflection at rest and at high speed
        [mm] (of positive motion when ``asymmetric``).
    v_s_ : float
        Stribeck velocity [mm/s] (of positive motion when ``asymmetric``).
    viscous_ : float
        Viscous coefficient ``mu`` [A s/mm] (of positive motion when ``asymmetric``).
    s_0_neg_, s_inf_neg_, v_s_neg_, viscous_neg_ : float
        The same for negative motion [mm, mm, mm/s, A s/mm]; only when ``asymmetric``.
    J_ : float
        Inertia [A s^2/mm].
    offset_ : float
        Offset [A]; 0 when not fitted.
    cost_ : float
        Final cost: mean squared error over the effort variance (NMSE / 100).
    n_evaluations_ : int
        Number of simulations run by the identification.
    n_pruned_ : int
        Elements dropped after the search because they carried no force (see :data:`PRUNE_SHARE`):
        the model has ``n_elements - n_pruned_`` elements.
    effort_unit_ : str
        Unit of the effort the model was fitted on, "A" or "N".
    """

    def __init__(self, *, n_elements: int = 4, asymmetric: bool = False, fit_offset: bool = False,
                 method: str = "nelder-mead", n_starts: int = 4, random_state=0, max_iter: int = 400,
                 staged: bool = True, inertia=None):
        self.inertia = inertia
        self.n_elements = n_elements
        self.asymmetric = asymmetric
        self.fit_offset = fit_offset
        self.method = method
        self.n_starts = n_starts
        self.random_state = random_state
        self.max_iter = max_iter
        self.staged = staged

    # ---------------------------------------------------------------- identification
    def _shape(self, theta, max_step, limits: ShapeLimits):
        """``alpha, s_0, s_inf, v_s, C`` from the search vector ``theta``, the deflections held to ``limits``.

        ``theta = (u_2..u_N, log s_0, log s_inf, log v_s, log r)``, or with
        ``log s_0, log s_inf, log v_s`` of positive then of negative motion
        when ``asymmetric`` (then ``s_0``, ``s_inf``, ``v_s`` are pairs).
        """
        n = self.n_elements
        alpha = _alpha_from_logits(theta[: n - 1])
        curve = np.exp(theta[n - 1:-1]).reshape(-1, 3)
        curve[:, 0], curve[:, 1] = limits.hold(curve[:, 0], curve[:, 1], float(alpha.max()))
        s_0, s_inf, v_s = (curve[:, j] if self.asymmetric else float(curve[0, j]) for j in range(3))
        return alpha, s_0, s_inf, v_s, float(np.exp(theta[-1])) * float(curve[:, :2].min()) / max_step

    def _initial_shape(self, runs):
        """Stage 1: initial shape vector and its bounds from a static fit and the reversals.

        Returns ``theta`` (see :meth:`_shape`), its lower and upper bounds, and the :class:`ShapeLimits` of
        the runs.
        When ``asymmetric``, the deflections of the two directions start in
        the ratio of the two directions' sliding levels (their mean as in the
        symmetric model).
        """
        n = self.n_elements
        static = static_initial_guess(runs, fit_offset=self.fit_offset)
        delta = presliding_deflection(runs, static) or DEFAULT_DEFLECTION_MM
        v_lo, v_hi = velocity_range(np.concatenate([run.velocity for run in runs]))
        logits = np.linspace(0.0, np.log(_ALPHA_SPREAD), n)[1:]
        s_0 = delta / _alpha_from_logits(logits).max()  # the largest element breaks away after delta
        ratio = np.clip(static["coulomb"] / static["static"], 0.05, 20.0) if static["static"] > 0 else 1.0
        curve = np.log([s_0, s_0 * ratio, np.clip(static["v_s"], v_lo, v_hi)])
        curve_lower = np.array([curve[0] - np.log(1e3), curve[1] - np.log(1e3), np.log(v_lo)])
        curve_upper = np.array([curve[0] + np.log(1e3), curve[1] + np.log(1e3), np.log(v_hi)])
        if self.asymmetric:
            q = np.log(direction_level_ratio(runs))  # log(level of negative / positive motion)
            shift = np.array([q, q, 0.0])
            curve = np.concatenate((curve - shift / 2.0, curve + shift / 2.0))
            curve_lower = np.concatenate((curve_lower - shift / 2.0, curve_lower + shift / 2.0))
            curve_upper = np.concatenate((curve_upper - shift / 2.0, curve_upper + shift / 2.0))
        theta = np.concatenate((logits, curve, [np.log(0.5)]))
        lower = np.concatenate((np.full(n - 1, -_LOGIT_BOUND), curve_lower, [np.log(1e-3)]))
        upper = np.concatenate((np.full(n - 1, _LOGIT_BOUND), curve_upper, [np.log(MAX_SLIP_STEP_RATIO)]))
        return theta, lower, upper, ShapeLimits.of_runs(runs, static)

    def held_out_search(self) -> "GMSModel":
        """A copy searching from the initial guess and the fixed slow-slip starts only (no perturbed starts).

        Returns
        -------
        GMSModel
        """
        return clone(self).set_params(n_starts=min(self.n_starts, HELD_OUT_STARTS))

    def _check_params(self) -> None:
        n = self.n_elements
        if not (isinstance(n, (int, np.integer)) and not isinstance(n, bool) and n >= 1):
            raise ParameterError(Setting("n_elements", assign=False), f" must be a positive integer, got {n!r}")
        self._check_flags("asymmetric", "fit_offset", "staged")
        check_direction_settings(self.asymmetric, self.fit_offset)
        check_search_settings(self)

    def _fit_runs(self, runs, progress) -> None:
        n = self.n_elements
        check_motion(runs)
        regression = _Regression(runs, n, self.fit_offset, self.asymmetric)
        max_step = max(regression.steps)
        theta, full_lower, full_upper, limits = self._initial_shape(runs)
        n_curves = 2 if self.asymmetric else 1
        full_scale = np.concatenate((np.ones(n - 1), np.tile([0.5, 0.5, 0.5], n_curves), [1.0]))

        def search(held: ShapeLimits):
            """The shape search with every trial held to ``held``: ``(result, evaluations)``."""
            def full_residuals(t):
                return regression.solve(self._shape(t, max_step, held))[1]

            n_evaluations = 0
            if self.staged:
                # stage 2: fractions, common deflection scale (and the ratio of the directions), slip rate;
                # the Stribeck velocities and the ratio s_0 / s_inf of each direction kept
                deflections = np.zeros(theta.size, dtype=bool)
                deflections[n - 1:-1] = np.tile([True, True, False], n_curves)
                negative = np.zeros(theta.size, dtype=bool)
                negative[n + 2:-1] = self.asymmetric
                negative &= deflections

                def expand(p):
                    out = theta.copy()
                    out[: n - 1] = p[: n - 1]
                    out[deflections] += p[n - 1]
                    if self.asymmetric:
                        out[negative] += p[n]
                    out[-1] = p[-1]
                    return out

                extra = int(self.asymmetric)
                p0 = np.concatenate((theta[: n - 1], np.zeros(1 + extra), [theta[-1]]))
                lower = np.concatenate((np.full(n - 1, -_LOGIT_BOUND), np.full(1 + extra, -np.log(1e2)),
                                        [np.log(1e-3)]))
                upper = np.concatenate((np.full(n - 1, _LOGIT_BOUND), np.full(1 + extra, np.log(1e2)),
                                        [np.log(MAX_SLIP_STEP_RATIO)]))
                slower_slips = [np.concatenate((p0[:-1], [np.log(ratio)])) for ratio in _SLOW_SLIP_RATIOS]
                presliding = multistart_results(lambda p: full_residuals(expand(p)), p0, lower, upper,
                                                scale=np.concatenate((np.ones(n - 1), np.full(1 + extra, 0.5), [1.0])),
                                                n_starts=self.n_starts, method=self.method, max_iter=self.max_iter,
                                                stage="GMS pre-sliding", progress=progress, fixed_starts=slower_slips,
                                                deviates=fixed_design(self.n_starts - 1, p0.size), stall=SEARCH_STALL)
                # stage 3: all shape parameters from every pre-sliding fit; the best joint fit wins
                joints = []  # (result, start index)
                for index, start in enumerate(presliding):
                    n_evaluations += start.n_evaluations
                    joint = local_search(full_residuals, np.clip(expand(start.x), full_lower, full_upper), full_lower,
                                         full_upper, scale=full_scale, method=self.method, max_iter=self.max_iter,
                                         stage="GMS joint", progress=progress, start=index, n_starts=len(presliding),
                                         best_so_far=min((j.cost for j, _ in joints), default=np.inf),
                                         stall=SEARCH_STALL)
                    n_evaluations += joint.n_evaluations
                    joints.append((joint, index))
                if self.method == "nelder-mead":
                    # the simplex stalls short of the minimum in many dimensions: trust-region least squares ends it,
                    # from every joint fit (they stall at different points of one flat valley), so that a fit from a
                    # seed-independent start is compared with the others at its own minimum
                    for rank, (joint, index) in enumerate(joints):
                        polished = local_search(full_residuals, joint.x, full_lower, full_upper, scale=full_scale,
                                                method="least-squares", max_iter=_POLISH_EVALUATIONS, stage="GMS joint",
                                                progress=progress, best_so_far=min(j.cost for j, _ in joints))
                        n_evaluations += polished.n_evaluations
                        if polished.cost < joint.cost:
                            joints[rank] = (polished, index)
                best = min(joint.cost for joint, _ in joints)
                result = min((pair for pair in joints if pair[0].cost <= best * (1.0 + _COST_TIE)),
                             key=lambda pair: pair[1])[0]
                result.n_evaluations = 0  # counted above
            else:
                result = multistart(full_residuals, theta, full_lower, full_upper, scale=full_scale,
                                    n_starts=self.n_starts, random_state=self.random_state, method=self.method,
                                    max_iter=self.max_iter, stage="GMS", progress=progress)
            n_evaluations += result.n_evaluations
            return result, n_evaluations

        # the runs' limits only where the free fit breaks them: holding every trial to them flattens the cost
        # where a limit binds, which can stall a search whose optimum lies inside the limits
        free = ShapeLimits(np.inf, np.inf)
        result, n_evaluations = search(free)
        if any(not np.array_equal(a, b) for a, b in zip(self._shape(result.x, max_step, free)[1:3],
                                                        self._shape(result.x, max_step, limits)[1:3])):
            result, more = search(limits)
            n_evaluations += more

        shape = self._shape(result.x, max_step, limits)
        x, residual = regression.solve(shape)
        shape, x, residual, self.n_pruned_ = self._pruned(runs, shape, x, residual)
        alpha, s_0, s_inf, v_s, c = shape
        self.alpha_ = alpha
        self.set_linear_coefficients(x)
        self.slip_rate_ = float(c)
        curves = np.column_stack([direction_pair(s_0, "GMS s_0"), direction_pair(s_inf, "GMS s_inf"),
                                  direction_pair(v_s, "GMS v_s")])
        self.s_0_, self.s_inf_, self.v_s_ = (float(value) for value in curves[0])
        if self.asymmetric:
            self.s_0_neg_, self.s_inf_neg_, self.v_s_neg_ = (float(value) for value in curves[1])
        self.cost_ = float(residual @ residual)
        self.n_evaluations_ = int(n_evaluations)

    def _pruned(self, runs, shape, x, residual):
        """Drop the elements that carry no force (share at most :data:`PRUNE_SHARE`) and refit the linear part.

        The other elements keep their break-away deflections ``alpha_i s(v)`` and slip rates ``alpha_i C``:
        the fractions of those kept are scaled up to sum 1, ``s_0``, ``s_inf`` and ``C`` down by the same
        factor. The linear parameters (stiffnesses, damping, viscous, inertia, offset) are refitted, since a
        dropped element's deflection rate was part of the damping term. One element always stays.

        Returns ``(shape, linear coefficients, residuals, number of elements dropped)``.
        """
        alpha, s_0, s_inf, v_s, c = shape
        share = x[:alpha.size] * alpha
        keep = share > PRUNE_SHARE * np.sum(share)
        if keep.all() or not keep.any():
            return shape, x, residual, 0
        kept = float(alpha[keep].sum())
        shape = (alpha[keep] / kept, np.multiply(s_0, kept), np.multiply(s_inf, kept), v_s, c * kept)
        regression = _Regression(runs, int(keep.sum()), self.fit_offset, self.asymmetric)
        x, residual = regression.solve(shape)
        return shape, x, residual, int(alpha.size - keep.sum())

    # ---------------------------------------------------------------- prediction
    def _parameters(self) -> dict:
        """Keyword arguments of :func:`simulate_gms`: pairs per direction when ``asymmetric``."""
        curve = {"s_0": self.s_0_, "s_inf": self.s_inf_, "v_s": self.v_s_, "mu": self.viscous_}
        if self.asymmetric:
            curve = {"s_0": (self.s_0_, self.s_0_neg_), "s_inf": (self.s_inf_, self.s_inf_neg_),
                     "v_s": (self.v_s_, self.v_s_neg_), "mu": (self.viscous_, self.viscous_neg_)}
        return {"alpha": self.alpha_, "k": self.k_, "C": self.slip_rate_, "sigma": self.sigma_, **curve}

    def initial_state(self) -> GMSState:
        """All elements relaxed and sticking."""
        return GMSState.at_rest(len(self.alpha_))

    def _simulate(self, run, state, sample_time):
        return simulate_gms(run.velocity, sample_time, **self._parameters(), state=state)

    def _n_params(self) -> int:
        return 2 * len(self.alpha_) + 6 + 4 * int(self.asymmetric) + int(self.fit_offset)

    def _fit_statistics(self) -> dict:
        pruned = getattr(self, "n_pruned_", None)  # None: a file that predates the pruning
        return {"cost": self.cost_, "n_evaluations": self.n_evaluations_,
                **({} if pruned is None else {"n_pruned": pruned})}

    def _own_parameters(self) -> list[Parameter]:
        shared = [
            Parameter("alpha", self.alpha_, "-", "element fractions (sum 1)"),
            Parameter("k", self.k_, f"{EFFORT}/{LENGTH}", "element stiffnesses"),
            Parameter("slip_rate", self.slip_rate_, f"{LENGTH}/s", "slip rate constant C"),
            Parameter("sigma", self.sigma_, f"{EFFORT} s/{LENGTH}", "micro-damping"),
        ]
        curve = [("viscous", f"{EFFORT} s/{LENGTH}", "viscous coefficient mu", self.viscous_),
                 ("s_0", LENGTH, "break-away deflection at rest", self.s_0_),
                 ("s_inf", LENGTH, "break-away deflection at high speed", self.s_inf_),
                 ("v_s", f"{LENGTH}/s", "Stribeck velocity", self.v_s_)]
        if not self.asymmetric:
            return shared + [Parameter(name, value, unit, text) for name, unit, text, value in curve]
        negative = (self.viscous_neg_, self.s_0_neg_, self.s_inf_neg_, self.v_s_neg_)
        return shared + [row for (name, unit, text, value), value_neg in zip(curve, negative)
                         for row in (Parameter(name, value, unit, f"{text}, positive motion"),
                                     Parameter(f"{name}_neg", value_neg, unit, f"{text}, negative motion"))]

    def trajectory(self, log, state=None, *, sample_time=None):
        """Current and element states of one run or chunk, from one simulation.

        Parameters
        ----------
        log : AxisLog
            One prepared run or chunk.
        state : GMSState or (z, mode), optional
            State before the first sample; at rest by default.
        sample_time : float, optional
            Integration step [s]; default the log's own median step.

        Returns
        -------
        current : ndarray, shape (n,)
            ``J a + friction + offset`` [A], equal to :meth:`predict_chunk`'s.
        z : ndarray, shape (n, N)
            Deflection of each element at each sample [mm].
        stick : ndarray of bool, shape (n, N)
            True where the element sticks.
        state : GMSState
            State after the last sample.
        """
        (run,) = self._check_predict_runs(log)
        step = run.sample_time if sample_time is None else float(sample_time)
        return self.trajectory_runner(step)(run, state)

    def trajectory_runner(self, sample_time: float):
        """:meth:`trajectory` of the chunks of a stream, the parameters checked once here and not per chunk.

        Parameters
        ----------
        sample_time : float
            Integration step [s].

        Returns
        -------
        callable
            ``runner(run, state)``: for a prepared chunk (checked by the caller) and the state before it,
            what :meth:`trajectory` returns.
        """
        check_is_fitted(self)
        elements = gms_trajectory_runner(sample_time, **self._parameters())
        J, offset = self.J_, self.offset_

        def runner(run, state=None):
            z, stick, _, friction, end = elements(run.velocity, state)
            return J * run.acceleration + friction + offset, z, stick, end

        return runner

    def states(self, logs):
        """Element deflections and stick flags over one or several runs (each from rest).

        Parameters
        ----------
        logs : AxisLog or list of AxisLog
            Prepared runs.

        Returns
        -------
        z : ndarray, shape (n_samples, N)
            Deflection of each element at each sample [mm].
        stick : ndarray of bool, shape (n_samples, N)
            True where the element sticks.
        """
        parts = [self.trajectory(run) for run in self._check_predict_runs(logs)]
        return np.vstack([p[1] for p in parts]), np.vstack([p[2] for p in parts])

    def plant_law(self):
        """The fitted GMS law as the plant of a position loop (:func:`~.plant_laws.gms_plant_law`).

        Returns
        -------
        PlantLaw
            The element law with ``J_`` [A s^2/mm] and ``offset_`` [A] as constant load.
        """
        p = self._parameters()
        return gms_plant_law(alpha=p["alpha"], k=p["k"], sigma=p["sigma"], s_0=p["s_0"], s_inf=p["s_inf"],
                             v_s=p["v_s"], c=p["C"], mu=p["mu"], inertia=self.J_, offset=self.offset_)

    def interval_coordinates(self) -> dict[str, str]:
        """Element fractions (a simplex), slip rate and Stribeck curve (per direction if asymmetric)."""
        names = ["slip_rate_", "s_0_", "s_inf_", "v_s_"]
        if self.asymmetric:
            names += ["s_0_neg_", "s_inf_neg_", "v_s_neg_"]
        return {**({"alpha_": "simplex"} if len(self.alpha_) > 1 else {}), **dict.fromkeys(names, "log")}

    def interval_notes(self) -> dict[str, str]:
        """The fraction of a single element is 1 by definition."""
        return {"alpha": "fixed: a single element"} if len(self.alpha_) == 1 else {}

    # ---------------------------------------------------------------- linear part
    def linear_part(self, run) -> LinearPart:
        """Columns ``z_1..z_N, w, v, a (, 1)`` at the fitted element shape (``w = sum_i alpha_i dz_i/dt``).

        ``v`` is the two columns ``v [v > 0]``, ``v [v < 0]`` when ``asymmetric``.

        Parameters
        ----------
        run : AxisLog
            One prepared run (velocity and acceleration present), as in the base class.
        """
        p = self._parameters()
        z, _, w, _, _ = gms_trajectory(run.velocity, run.sample_time, alpha=p["alpha"], C=p["C"], s_0=p["s_0"],
                                       s_inf=p["s_inf"], v_s=p["v_s"])
        n = z.shape[1]
        motion, motion_names = viscous_columns(run.velocity, self.asymmetric)
        columns = list(z.T) + [w] + motion + [run.acceleration]
        names = [f"k{i + 1}" for i in range(n)] + ["sigma"] + motion_names + ["J"]
        if self.fit_offset:
            columns.append(np.ones(len(run)))
            names.append("offset")
        return LinearPart.from_columns(columns, names, non_negative=len(names) - int(self.fit_offset))

    def linear_coefficients(self) -> np.ndarray:
        """``k_1..k_N, sigma, mu, J (, offset)``; ``mu+, mu-`` for ``mu`` when ``asymmetric``."""
        viscous = [self.viscous_, self.viscous_neg_] if self.asymmetric else [self.viscous_]
        return np.concatenate((self.k_, [self.sigma_], viscous, [self.J_], [self.offset_] if self.fit_offset else []))

    def set_linear_coefficients(self, values) -> None:
        """Write ``values`` (order of :meth:`linear_coefficients`) into the model (``alpha_`` must be set).

        Parameters
        ----------
        values : array_like, shape (p,)
            Values of the linear parameters, in the order of :meth:`linear_coefficients`.
        """
        x = [float(value) for value in np.asarray(values, dtype=float)]
        n = len(self.alpha_)
        self.k_ = np.array(x[:n])
        self.sigma_, self.viscous_ = x[n:n + 2]
        if self.asymmetric:
            self.viscous_neg_ = x[n + 2]
        self.J_ = x[n + 2 + int(self.asymmetric)]
        self.offset_ = x[n + 3 + int(self.asymmetric)] if self.fit_offset else 0.0
