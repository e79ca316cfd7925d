"""What every truth friction law of the synthetic axis family answers.

A truth law turns a motion given on a fine time grid into the friction
current [A] at the log samples, and, where the law has mechanics of its own
(a gap between motor and table), the inertial current as well. The family
plant (:mod:`greybox.twin.family`) composes a law with the effects every
feed axis has (position dependence, load-dependent friction, motor cogging,
current noise, encoder quantisation). This module imports nothing else of
greybox.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import ClassVar

import numpy as np

__all__ = ["TruthLaw", "LawResponse", "log_uniform"]


def log_uniform(rng: np.random.Generator, low: float, high: float) -> float:
    """One draw, uniform in ``log`` between ``low`` and ``high`` (both positive).

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of randomness.
    low, high : float
        Ends of the range, both positive, in the unit of the drawn quantity.
    """
    return float(math.exp(rng.uniform(math.log(low), math.log(high))))


@dataclass(frozen=True)
class LawResponse:
    """Currents of a truth law at the log samples.

    Parameters
    ----------
    friction_A : ndarray
        Friction current [A] of the law, before the family's position factor.
    inertia_A : ndarray
        Inertial current [A].
    direction : ndarray
        Friction over its largest magnitude, in [-1, 1]: the sign and state of
        the friction the load-dependent part follows.
    """

    friction_A: np.ndarray
    inertia_A: np.ndarray
    direction: np.ndarray


@dataclass(frozen=True)
class TruthLaw:
    """Base class of the truth friction laws of the family.

    Subclasses are frozen dataclasses of their parameters (SI-like units of the
    package: mm, s, A) and implement :meth:`draw`, :meth:`friction_samples`
    and :attr:`peak_friction_A`; a law with its own mechanics overrides
    :meth:`respond`.
    """

    #: Name of the law in files and reports.
    name = "law"

    #: ``{parameter: (low, high, unit, how drawn)}``: the documented physical ranges of :meth:`draw`.
    RANGES: ClassVar[dict] = {}

    @classmethod
    def draw(cls, rng: np.random.Generator) -> "TruthLaw":  # pragma: no cover - abstract
        """A law with parameters drawn from :attr:`RANGES`.

        Parameters
        ----------
        rng : numpy.random.Generator
            Source of randomness.
        """
        raise NotImplementedError

    @property
    def peak_friction_A(self) -> float:  # pragma: no cover - abstract
        """Largest friction magnitude [A] the law can give (its static or breakaway level)."""
        raise NotImplementedError

    def friction_samples(self, position_mm, velocity_mm_s, step_s: float, stride: int) -> np.ndarray:
        """Friction [A] at every ``stride``-th point of a motion on a fine grid of step ``step_s`` [s].

        Parameters
        ----------
        position_mm, velocity_mm_s : ndarray, shape (n,)
            Motion [mm, mm/s] on the fine grid.
        step_s : float
            Fine integration step [s].
        stride : int
            Fine steps per log sample.

        Returns
        -------
        ndarray, shape ((n - 1) // stride + 1,)
            Friction current [A] at fine steps 0, stride, 2 stride, ...
        """
        raise NotImplementedError  # pragma: no cover - abstract

    def respond(self, position_mm, velocity_mm_s, acceleration_mm_s2, step_s: float, stride: int,
                inertia_A_s2_mm: float) -> LawResponse:
        """Friction and inertial current [A] at the log samples of a motion on the fine grid.

        Parameters
        ----------
        position_mm, velocity_mm_s, acceleration_mm_s2 : ndarray, shape (n,)
            Motion of the motor side [mm, mm/s, mm/s^2] at fine steps ``step_s`` [s].
        step_s : float
            Fine integration step [s].
        stride : int
            Fine steps per log sample.
        inertia_A_s2_mm : float
            Inertia of the whole axis [A s^2/mm].
        """
        friction = self.friction_samples(position_mm, velocity_mm_s, step_s, stride)
        inertia = inertia_A_s2_mm * np.asarray(acceleration_mm_s2, float)[::stride]
        return LawResponse(friction, inertia, np.clip(friction / self.peak_friction_A, -1.0, 1.0))

    def to_dict(self) -> dict:
        """JSON-serialisable parameters, with the law's name."""
        values = {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()}
        return {"law": self.name, **values}
