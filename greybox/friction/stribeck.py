"""Stribeck + viscous friction with inertia, fitted by separable least squares."""

from __future__ import annotations

import numpy as np

from ..base import EFFORT, LinearPart, Parameter
from ..curves import stribeck_curve
from ..errors import ParameterError
from ..estimator import CurrentModel
from ..identify.initial import check_motion, samples_at_speed
from ..identify.static import fit_stribeck, stribeck_regressors

__all__ = ["StribeckModel", "stribeck_curve"]


class StribeckModel(CurrentModel):
    """Inertia + Stribeck + viscous friction (+ offset).

    ``I = J a + sgn(v) (F_c + (F_s - F_c) exp(-|v|/v_s)) + mu v + I_0``

    A static (memoryless) model: the friction is a function of the present
    velocity only. Fitted by separable nonlinear least squares of all samples:
    a log-grid search and bounded refinement of ``v_s``, with ``J``, ``F_c``,
    ``F_s``, ``mu`` (non-negative) and ``I_0`` solved by linear least squares
    at each trial ``v_s``.

    Parameters
    ----------
    fit_offset : bool, default False
        Fit a constant offset ``I_0`` [A].
    min_speed : float, default 0.0
        Samples slower than this [mm/s] are left out of the fit.

    Attributes
    ----------
    J_ : float
        Inertia [A s^2/mm].
    coulomb_ : float
        Coulomb level ``F_c`` [A].
    static_ : float
        Static level ``F_s`` [A] (friction just above zero speed).
    v_s_ : float
        Stribeck velocity [mm/s].
    viscous_ : float
        Viscous coefficient ``mu`` [A s/mm].
    offset_ : float
        Offset [A]; 0 when not fitted.
    effort_unit_ : str
        Unit of the effort the model was fitted on, "A" or "N".
    """

    def __init__(self, *, fit_offset: bool = False, min_speed: float = 0.0):
        self.fit_offset = fit_offset
        self.min_speed = min_speed

    def _check_params(self) -> None:
        self._check_flags("fit_offset")
        if not (np.isfinite(self.min_speed) and self.min_speed >= 0.0):
            raise ParameterError(f"min_speed must be a non-negative speed, got {self.min_speed} mm/s")

    def _fit_runs(self, runs, progress) -> None:
        check_motion(runs)
        v, a, y = samples_at_speed(runs, self.min_speed)
        params = fit_stribeck(v, a, y, fit_offset=self.fit_offset)
        self.J_ = params["J"]
        self.coulomb_ = params["coulomb"]
        self.static_ = params["static"]
        self.v_s_ = params["v_s"]
        self.viscous_ = params["viscous"]
        self.offset_ = params["offset"]

    def _simulate(self, run, state, sample_time):
        if not self.v_s_ > 0.0:
            raise ParameterError(f"Stribeck velocity v_s must be positive, got {self.v_s_} mm/s")
        v = run.velocity
        return np.sign(v) * stribeck_curve(v, self.static_, self.coulomb_, self.v_s_) + self.viscous_ * v, None

    def _n_params(self) -> int:
        return 5 + int(self.fit_offset)

    def _own_parameters(self) -> list[Parameter]:
        return [
            Parameter("coulomb", self.coulomb_, EFFORT, "Coulomb level F_c"),
            Parameter("static", self.static_, EFFORT, "static level F_s (just above zero speed)"),
            Parameter("v_s", self.v_s_, "mm/s", "Stribeck velocity"),
            Parameter("viscous", self.viscous_, f"{EFFORT} s/mm", "viscous coefficient"),
        ]

    # ---------------------------------------------------------------- linear part
    def linear_part(self, run) -> LinearPart:
        """Columns ``a, sgn v (1 - e), sgn v e, v (, 1)`` with ``e = exp(-|v|/v_s)`` at the fitted ``v_s``."""
        matrix = stribeck_regressors(run.velocity, run.acceleration, self.v_s_, self.fit_offset)
        names = ["J", "coulomb", "static", "viscous"] + (["offset"] if self.fit_offset else [])
        return LinearPart.from_columns(list(matrix.T), names, non_negative=4)

    def linear_coefficients(self) -> np.ndarray:
        """``J, coulomb, static, viscous (, offset)``."""
        return np.array([self.J_, self.coulomb_, self.static_, self.viscous_]
                        + ([self.offset_] if self.fit_offset else []))

    def set_linear_coefficients(self, values) -> None:
        """Write ``values`` (order of :meth:`linear_coefficients`) into the fitted model."""
        x = [float(value) for value in np.asarray(values, dtype=float)]
        self.J_, self.coulomb_, self.static_, self.viscous_ = x[:4]
        self.offset_ = x[4] if self.fit_offset else 0.0
