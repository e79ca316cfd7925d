"""Feed-forward currents: inertia times reference acceleration plus a friction model on the reference.

A feed-forward is computed from the reference alone, before the loop runs:

    I_ff[k] = J_ff a_ref[k] + F_model(reference up to k) + I_0,

with the friction model under test evaluated on the reference motion (its
velocity, and for the GMS+SVR model its position). The dynamic models
(LuGre, GMS, GMS+SVR) are simulated along the reference velocity from rest,
their state carried from sample to sample by their own kernels; every
kernel is causal, so sample ``k`` depends on the reference up to ``k`` only,
exactly as if the model ran step by step beside the controller.

* :class:`InertiaFeedForward` -- no friction model (the row "none"), or no
  feed-forward at all with ``inertia_A_s2_mm=0``.
* :class:`ModelFeedForward` -- a fitted greybox current model: Coulomb,
  Stribeck, LuGre, GMS, SVR or GMS+SVR.
"""

from __future__ import annotations

import numpy as np

from ..errors import GreyboxError
from .references import Reference

__all__ = ["InertiaFeedForward", "ModelFeedForward"]


def _check_inertia(value, what: str) -> float:
    value = float(value)
    if not np.isfinite(value):
        raise GreyboxError(f"{what}: feed-forward inertia must be finite, got {value} A s^2/mm")
    return value


class InertiaFeedForward:
    """Feed-forward of the inertia alone: ``I_ff = J_ff a_ref`` [A].

    Parameters
    ----------
    inertia_A_s2_mm : float
        ``J_ff`` [A s^2/mm]; 0 for no feed-forward at all.
    name : str, default "none"
        Label in tables (the friction model is "none").
    """

    effort_unit = None

    def __init__(self, inertia_A_s2_mm: float, name: str = "none"):
        self.inertia_A_s2_mm = _check_inertia(inertia_A_s2_mm, name)
        self.name = name

    def friction(self, reference: Reference) -> np.ndarray:
        """Friction part of the feed-forward [A]: zero.

        Parameters
        ----------
        reference : Reference
            Position reference; only its length is used.

        Returns
        -------
        ndarray, shape (n,)
            Zeros, one per reference sample.
        """
        return np.zeros(len(reference))

    def current(self, reference: Reference) -> np.ndarray:
        """Feed-forward current [A] at every reference sample.

        Parameters
        ----------
        reference : Reference
            Position reference; its acceleration [mm/s^2] is scaled by the inertia.

        Returns
        -------
        ndarray, shape (n,)
            ``J_ff a_ref`` [A].
        """
        return self.inertia_A_s2_mm * reference.acceleration

    def describe(self) -> dict:
        """JSON-serialisable description."""
        return {"name": self.name, "kind": "inertia", "inertia": self.inertia_A_s2_mm}


class ModelFeedForward:
    """Feed-forward of a fitted current model: ``I_ff = J_ff a_ref + F_model(ref) + I_0`` [A].

    Parameters
    ----------
    model : CurrentModel
        A fitted greybox model (``greybox.models.registry`` kinds).
    inertia_A_s2_mm : float, optional
        ``J_ff`` [A s^2/mm]; default the model's own ``J_``. Giving every
        model the same (e.g. the plant's) inertia compares the friction
        models alone.
    name : str, optional
        Label in tables; default the model kind.
    """

    def __init__(self, model, inertia_A_s2_mm: float | None = None, name: str | None = None):
        from sklearn.utils.validation import check_is_fitted

        from ..models.registry import model_kind

        kind = model_kind(model)
        check_is_fitted(model)
        self.model = model
        self.kind = kind
        self.name = name or kind
        self.inertia_A_s2_mm = _check_inertia(model.J_ if inertia_A_s2_mm is None else inertia_A_s2_mm,
                                              self.name)
        self.effort_unit = model.effort_unit_

    def friction(self, reference: Reference) -> np.ndarray:
        """Friction current of the model along the reference, plus its offset [A].

        Parameters
        ----------
        reference : Reference
            Position reference; the model is simulated along its motion from rest.

        Returns
        -------
        ndarray, shape (n,)
            ``F_model(ref) + I_0`` [A] at every reference sample.
        """
        log = reference.to_log(motion=self.model.units_.name, effort_unit=self.effort_unit)
        return self.model.friction(log) + self.model.offset_

    def current(self, reference: Reference) -> np.ndarray:
        """Feed-forward current [A] at every reference sample.

        Parameters
        ----------
        reference : Reference
            Position reference the feed-forward is computed from.

        Returns
        -------
        ndarray, shape (n,)
            ``J_ff a_ref + F_model(ref) + I_0`` [A].
        """
        return self.inertia_A_s2_mm * reference.acceleration + self.friction(reference)

    def describe(self) -> dict:
        """JSON-serialisable description."""
        return {"name": self.name, "kind": self.kind, "inertia": self.inertia_A_s2_mm,
                "model_inertia": float(self.model.J_)}
