"""Coulomb + viscous friction with inertia, fitted by linear least squares."""

from __future__ import annotations

import numpy as np

from ...base import EFFORT, LENGTH, LinearPart, Parameter
from ...errors import ParameterError, Setting
from ...identify.initial import check_motion, samples_at_speed
from ...identify.static import check_direction_settings, fit_coulomb
from ..estimator import CurrentModel

__all__ = ["CoulombModel", "coulomb_friction"]


def coulomb_friction(velocity, coulomb_pos, coulomb_neg, viscous_pos, viscous_neg) -> np.ndarray:
    """Coulomb + viscous friction, possibly with direction-dependent levels [A].

    ``F = F_c+ + F_v+ v`` for ``v > 0``, ``F = -F_c- + F_v- v`` for ``v < 0``
    and ``0`` at rest.

    Parameters
    ----------
    velocity : ndarray
        Velocity [mm/s].
    coulomb_pos, coulomb_neg : float
        Coulomb level magnitude for positive / negative motion [A].
    viscous_pos, viscous_neg : float
        Viscous coefficient for positive / negative motion [A s/mm].
    """
    v = np.asarray(velocity, dtype=float)
    return np.where(v > 0.0, coulomb_pos + viscous_pos * v,
                    np.where(v < 0.0, -coulomb_neg + viscous_neg * v, 0.0))


class CoulombModel(CurrentModel):
    """Inertia + Coulomb + viscous friction (+ offset): ``I = J a + F_c sgn(v) + F_v v + I_0``.

    Fitted by linear least squares of all samples jointly for ``J`` and the
    friction levels; on the EMPS benchmark this is the reference IDIM-LS
    estimator (with ``fit_offset=True``, or ``asymmetric=True`` for its
    asymmetric variant).

    Parameters
    ----------
    asymmetric : bool, default False
        Separate Coulomb level and viscous coefficient for positive and
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
        Inertia [A s^2/mm] (a mass [kg] = [N s^2/m] is ``1000 * J_`` for force logs).
    coulomb_pos_, coulomb_neg_ : float
        Coulomb level magnitude for positive / negative motion [A].
    viscous_pos_, viscous_neg_ : float
        Viscous coefficient for positive / negative motion [A s/mm].
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
        params = fit_coulomb(v, a, y, asymmetric=self.asymmetric, fit_offset=self.fit_offset)
        self.J_ = params["J"]
        self.coulomb_pos_ = params["coulomb_pos"]
        self.coulomb_neg_ = params["coulomb_neg"]
        self.viscous_pos_ = params["viscous_pos"]
        self.viscous_neg_ = params["viscous_neg"]
        self.offset_ = params["offset"]

    def _simulate(self, run, state, sample_time):
        return coulomb_friction(run.velocity, self.coulomb_pos_, self.coulomb_neg_,
                                self.viscous_pos_, self.viscous_neg_), None

    def _n_params(self) -> int:
        return (5 if self.asymmetric else 3) + int(self.fit_offset)

    def _own_parameters(self) -> list[Parameter]:
        return [
            Parameter("coulomb_pos", self.coulomb_pos_, EFFORT, "Coulomb level, positive motion"),
            Parameter("coulomb_neg", self.coulomb_neg_, EFFORT, "Coulomb level magnitude, negative motion"),
            Parameter("viscous_pos", self.viscous_pos_, f"{EFFORT} s/{LENGTH}", "viscous coefficient, positive motion"),
            Parameter("viscous_neg", self.viscous_neg_, f"{EFFORT} s/{LENGTH}", "viscous coefficient, negative motion"),
        ]

    # ---------------------------------------------------------------- linear part
    def linear_part(self, run) -> LinearPart:
        """Columns ``a, sgn v, v (, 1)``, or ``a, [v>0], -[v<0], v [v>0], v [v<0]`` if asymmetric.

        Parameters
        ----------
        run : AxisLog
            One prepared run (velocity and acceleration present), as in the base class.
        """
        v, a = run.velocity, run.acceleration
        if self.asymmetric:
            positive, negative = (v > 0.0).astype(float), (v < 0.0).astype(float)
            return LinearPart.from_columns([a, positive, -negative, v * positive, v * negative],
                                           ["J", "coulomb_pos", "coulomb_neg", "viscous_pos", "viscous_neg"],
                                           non_negative=1)
        columns, names = [a, np.sign(v), v], ["J", "coulomb", "viscous"]
        if self.fit_offset:
            columns.append(np.ones(len(run)))
            names.append("offset")
        return LinearPart.from_columns(columns, names, non_negative=1)  # J >= 0, as fit_coulomb holds it

    def linear_coefficients(self) -> np.ndarray:
        """``J, coulomb, viscous (, offset)``, or the five levels of the asymmetric model."""
        if self.asymmetric:
            return np.array([self.J_, self.coulomb_pos_, self.coulomb_neg_, self.viscous_pos_, self.viscous_neg_])
        return np.array([self.J_, self.coulomb_pos_, self.viscous_pos_] + ([self.offset_] if self.fit_offset else []))

    def set_linear_coefficients(self, values) -> None:
        """Write ``values`` (order of :meth:`linear_coefficients`) into the fitted model.

        Parameters
        ----------
        values : array_like, shape (p,)
            Values of the linear parameters, in the order of :meth:`linear_coefficients`.
        """
        x = [float(value) for value in np.asarray(values, dtype=float)]
        if self.asymmetric:
            self.J_, self.coulomb_pos_, self.coulomb_neg_, self.viscous_pos_, self.viscous_neg_ = x
            return
        self.J_, self.coulomb_pos_, self.viscous_pos_ = x[:3]
        self.coulomb_neg_, self.viscous_neg_ = self.coulomb_pos_, self.viscous_pos_
        self.offset_ = x[3] if self.fit_offset else 0.0
