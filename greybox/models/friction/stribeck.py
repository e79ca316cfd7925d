"""Stribeck + viscous friction with inertia, fitted by separable least squares."""

from __future__ import annotations

import numpy as np

from ...base import EFFORT, LENGTH, LinearPart, Parameter
from ...errors import ParameterError, Setting
from ...identify.initial import check_motion, samples_at_speed
from ...identify.static import check_direction_settings, fit_stribeck, stribeck_curve, stribeck_regressors
from ..estimator import CurrentModel

__all__ = ["StribeckModel", "stribeck_curve"]


class StribeckModel(CurrentModel):
    """Inertia + Stribeck + viscous friction (+ offset).

    ``I = J a + sgn(v) (F_c + (F_s - F_c) exp(-|v|/v_s)) + mu v + I_0``

    or, with ``asymmetric=True``, a separate curve for each direction of motion
    (``F_c-``, ``F_s-`` are magnitudes):

    ``I = J a + [v>0] (F_c+ + (F_s+ - F_c+) exp(-v/v_s+) + mu+ v)
    - [v<0] (F_c- + (F_s- - F_c-) exp(-|v|/v_s-)) + [v<0] mu- v``

    A static (memoryless) model: the friction is a function of the present
    velocity only. Fitted by separable nonlinear least squares of all samples:
    a log-grid search and bounded refinement of ``v_s`` (of each direction in
    turn if asymmetric), with ``J``, the friction levels, the viscous
    coefficients (all non-negative) and ``I_0`` solved by linear least squares
    at each trial ``v_s``.

    Parameters
    ----------
    asymmetric : bool, default False
        Separate Stribeck curve and viscous coefficient for positive and
        negative motion.
    fit_offset : bool, default False
        Fit a constant offset ``I_0`` [A] (not together with ``asymmetric``).
    min_speed : float, default 0.0
        Samples slower than this [mm/s] are left out of the fit.
    inertia : float, optional
        Known inertia ``J`` [A s^2/mm] (e.g. from the drive's commissioning; 0 for an effort measured at the
        load, by a force or torque sensor on the device); identified from the runs when None.

    Attributes
    ----------
    J_ : float
        Inertia [A s^2/mm].
    coulomb_ : float
        Coulomb level ``F_c`` [A] (of positive motion if asymmetric).
    static_ : float
        Static level ``F_s`` [A] (friction just above zero speed; of positive
        motion if asymmetric).
    v_s_ : float
        Stribeck velocity [mm/s] (of positive motion if asymmetric).
    viscous_ : float
        Viscous coefficient ``mu`` [A s/mm] (of positive motion if asymmetric).
    coulomb_neg_ : float
        Coulomb level magnitude ``F_c-`` of negative motion [A]; only if asymmetric.
    static_neg_ : float
        Static level magnitude ``F_s-`` of negative motion [A]; only if asymmetric.
    v_s_neg_ : float
        Stribeck velocity of negative motion [mm/s]; only if asymmetric.
    viscous_neg_ : float
        Viscous coefficient ``mu-`` of negative motion [A s/mm]; only if asymmetric.
    offset_ : float
        Offset [A]; 0 when not fitted.
    effort_unit_ : str
        Unit of the effort the model was fitted on, "A" or "N".
    """

    def __init__(self, *, asymmetric: bool = False, fit_offset: bool = False, min_speed: float = 0.0,
                 inertia=None):
        self.inertia = inertia
        self.asymmetric = asymmetric
        self.fit_offset = fit_offset
        self.min_speed = min_speed

    def _check_params(self) -> None:
        self._check_flags("asymmetric", "fit_offset")
        check_direction_settings(self.asymmetric, self.fit_offset)
        if not (np.isfinite(self.min_speed) and self.min_speed >= 0.0):
            raise ParameterError(Setting("min_speed", assign=False),
                                 f" must be a non-negative speed, got {self.min_speed} mm/s")

    def _fit_runs(self, runs, progress) -> None:
        check_motion(runs)
        v, a, y = samples_at_speed(runs, self.min_speed)
        params = fit_stribeck(v, a, y, asymmetric=self.asymmetric, fit_offset=self.fit_offset)
        self.J_ = params["J"]
        self.coulomb_ = params["coulomb"]
        self.static_ = params["static"]
        self.v_s_ = params["v_s"]
        self.viscous_ = params["viscous"]
        if self.asymmetric:
            self.coulomb_neg_ = params["coulomb_neg"]
            self.static_neg_ = params["static_neg"]
            self.v_s_neg_ = params["v_s_neg"]
            self.viscous_neg_ = params["viscous_neg"]
        self.offset_ = params["offset"]

    def _stribeck_velocities(self):
        """``v_s`` [mm/s], or the pair ``(v_s+, v_s-)`` if asymmetric, checked positive."""
        v_s = (self.v_s_, self.v_s_neg_) if self.asymmetric else self.v_s_
        if not np.all(np.asarray(v_s) > 0.0):
            raise ParameterError(f"Stribeck velocity v_s must be positive, got {v_s} mm/s")
        return v_s

    def _simulate(self, run, state, sample_time):
        self._stribeck_velocities()
        v = run.velocity
        positive = stribeck_curve(v, self.static_, self.coulomb_, self.v_s_)
        if not self.asymmetric:
            return np.sign(v) * positive + self.viscous_ * v, None
        negative = stribeck_curve(v, self.static_neg_, self.coulomb_neg_, self.v_s_neg_)
        return np.where(v > 0.0, positive + self.viscous_ * v,
                        np.where(v < 0.0, -negative + self.viscous_neg_ * v, 0.0)), None

    def _n_params(self) -> int:
        return 9 if self.asymmetric else 5 + int(self.fit_offset)

    def _own_parameters(self) -> list[Parameter]:
        if not self.asymmetric:
            return [
                Parameter("coulomb", self.coulomb_, EFFORT, "Coulomb level F_c"),
                Parameter("static", self.static_, EFFORT, "static level F_s (just above zero speed)"),
                Parameter("v_s", self.v_s_, f"{LENGTH}/s", "Stribeck velocity"),
                Parameter("viscous", self.viscous_, f"{EFFORT} s/{LENGTH}", "viscous coefficient"),
            ]
        return [
            Parameter("coulomb", self.coulomb_, EFFORT, "Coulomb level F_c+, positive motion"),
            Parameter("coulomb_neg", self.coulomb_neg_, EFFORT, "Coulomb level magnitude F_c-, negative motion"),
            Parameter("static", self.static_, EFFORT, "static level F_s+ (just above zero speed), positive motion"),
            Parameter("static_neg", self.static_neg_, EFFORT,
                      "static level magnitude F_s- (just above zero speed), negative motion"),
            Parameter("v_s", self.v_s_, f"{LENGTH}/s", "Stribeck velocity, positive motion"),
            Parameter("v_s_neg", self.v_s_neg_, f"{LENGTH}/s", "Stribeck velocity, negative motion"),
            Parameter("viscous", self.viscous_, f"{EFFORT} s/{LENGTH}", "viscous coefficient, positive motion"),
            Parameter("viscous_neg", self.viscous_neg_, f"{EFFORT} s/{LENGTH}", "viscous coefficient, negative motion"),
        ]

    def interval_coordinates(self) -> dict[str, str]:
        """The Stribeck velocity (one per direction if asymmetric), on a log scale."""
        return {"v_s_": "log", **({"v_s_neg_": "log"} if self.asymmetric else {})}

    # ---------------------------------------------------------------- linear part
    def linear_part(self, run) -> LinearPart:
        """Columns at the fitted ``v_s`` (:func:`~greybox.identify.static.stribeck_regressors`).

        ``a, sgn v (1 - e), sgn v e, v (, 1)`` with ``e = exp(-|v|/v_s)``; if
        asymmetric ``a, [v>0] (1 - e+), [v>0] e+, -[v<0] (1 - e-), -[v<0] e-,
        v [v>0], v [v<0]`` with ``e+``, ``e-`` of ``v_s+``, ``v_s-``.

        Parameters
        ----------
        run : AxisLog
            One prepared run (velocity and acceleration present), as in the base class.
        """
        matrix = stribeck_regressors(run.velocity, run.acceleration, self._stribeck_velocities(), self.fit_offset)
        if self.asymmetric:
            names = ["J", "coulomb_pos", "static_pos", "coulomb_neg", "static_neg", "viscous_pos", "viscous_neg"]
        else:
            names = ["J", "coulomb", "static", "viscous"] + (["offset"] if self.fit_offset else [])
        return LinearPart.from_columns(list(matrix.T), names, non_negative=7 if self.asymmetric else 4)

    def linear_coefficients(self) -> np.ndarray:
        """Present values of the linear parameters, in the order of :meth:`linear_part`'s columns.

        ``J, coulomb, static, viscous (, offset)``, or if asymmetric
        ``J, coulomb, static, coulomb_neg, static_neg, viscous, viscous_neg``.
        """
        if self.asymmetric:
            return np.array([self.J_, self.coulomb_, self.static_, self.coulomb_neg_, self.static_neg_,
                             self.viscous_, self.viscous_neg_])
        return np.array([self.J_, self.coulomb_, self.static_, self.viscous_]
                        + ([self.offset_] if self.fit_offset else []))

    def set_linear_coefficients(self, values) -> None:
        """Write ``values`` (order of :meth:`linear_coefficients`) into the fitted model.

        Parameters
        ----------
        values : array_like, shape (p,)
            Values of the linear parameters, in the order of :meth:`linear_coefficients`.
        """
        x = [float(value) for value in np.asarray(values, dtype=float)]
        if self.asymmetric:
            (self.J_, self.coulomb_, self.static_, self.coulomb_neg_, self.static_neg_,
             self.viscous_, self.viscous_neg_) = x
            return
        self.J_, self.coulomb_, self.static_, self.viscous_ = x[:4]
        self.offset_ = x[4] if self.fit_offset else 0.0
