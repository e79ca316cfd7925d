"""Coulomb + viscous friction with inertia, fitted by linear least squares."""

from __future__ import annotations

import numpy as np

from ..identify.initial import check_motion, samples_at_speed
from ..identify.static import fit_coulomb
from ..models.base import CurrentModel

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

    def __init__(self, asymmetric: bool = False, fit_offset: bool = False, min_speed: float = 0.0):
        self.asymmetric = asymmetric
        self.fit_offset = fit_offset
        self.min_speed = min_speed

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

    def _friction_run(self, run) -> np.ndarray:
        return coulomb_friction(run.velocity, self.coulomb_pos_, self.coulomb_neg_,
                                self.viscous_pos_, self.viscous_neg_)

    def _n_params(self) -> int:
        return (5 if self.asymmetric else 3) + int(self.fit_offset)
