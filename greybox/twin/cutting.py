"""Milling-like cutting load on the feed axis.

The tool is engaged while the axis feeds in the cutting direction across the
workpiece. The cutting force opposes the feed, so the drive supplies an extra
current in the direction of motion::

    I_p = sgn(v) * c(v) * e(x) * I_c * (|v| / v_ref)^p * (1 + q (pi/2 |sin(pi f_z t)| - 1))

* ``c(v)`` is 1 while moving in the cutting direction and ``r`` on the return
  stroke: 0 (default) makes it an air cut, ``r > 0`` a cut whose force opposes
  the motion as well, ``r < 0`` one whose force pushes the table along its
  motion (climb milling pulling the table), so that the screw is back-driven;
* ``e(x)`` is the engagement, rising from 0 to 1 with a ``sin^2`` ramp over the
  entry length at the workpiece edges (entry and exit ramps);
* ``(|v| / v_ref)^p`` scales the force with the chip thickness (feed per tooth);
* the last factor is the tooth-passing ripple of mean 1 at ``f_z = n z / 60``
  (spindle speed ``n`` [1/min], ``z`` teeth), relative depth ``q``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..errors import GreyboxError

__all__ = ["CuttingSpec", "cutting_current", "cut_segments"]


@dataclass(frozen=True)
class CuttingSpec:
    """Cutting conditions.

    Parameters
    ----------
    strength_A : float, default 0.5
        Mean process current ``I_c`` [A] at the reference feed, full engagement.
    reference_feed_mm_min : float, default 1000.0
        Feed ``v_ref`` [mm/min] at which the mean current is ``strength_A``.
    feed_exponent : float, default 0.75
        Exponent ``p`` of the feed dependence (1 - Kienzle's m_c).
    spindle_rpm : float, default 3000.0
        Spindle speed ``n`` [1/min].
    teeth : int, default 2
        Number of teeth ``z`` of the cutter.
    ripple : float, default 0.5
        Relative depth ``q`` of the tooth-passing ripple, in [0, 1].
    entry_length_mm : float, default 5.0
        Length [mm] of the entry and exit ramps of the engagement.
    workpiece_mm : tuple of float, optional
        Extent [mm] of the workpiece; default the central ``workpiece_fraction``
        of the positions the log covers.
    workpiece_fraction : float, default 0.6
        Share of the covered positions taken by the default workpiece.
    cutting_direction : {-1, 1}, default -1
        Feed direction in which the tool cuts.
    return_pass : float, default 0.0
        Process current on the return stroke relative to the cutting
        stroke's at the same feed, ``r`` in [-1, 1]: 0 an air cut, positive a
        force opposing the motion, negative one pushing the table along
        (back-driving the screw; the force behind the current then differs
        by the efficiencies, :mod:`greybox.twin.drive`).
    """

    strength_A: float = 0.5
    reference_feed_mm_min: float = 1000.0
    feed_exponent: float = 0.75
    spindle_rpm: float = 3000.0
    teeth: int = 2
    ripple: float = 0.5
    entry_length_mm: float = 5.0
    workpiece_mm: tuple | None = None
    workpiece_fraction: float = 0.6
    cutting_direction: int = -1
    return_pass: float = 0.0

    def __post_init__(self):
        if self.cutting_direction not in (-1, 1):
            raise GreyboxError(f"cutting: direction must be -1 or 1, got {self.cutting_direction}")
        if not -1.0 <= self.return_pass <= 1.0:
            raise GreyboxError(f"cutting: return pass must be in [-1, 1], got {self.return_pass}")
        if not 0.0 <= self.ripple <= 1.0:
            raise GreyboxError(f"cutting: ripple depth must be in [0, 1], got {self.ripple}")
        if self.spindle_rpm <= 0 or self.teeth < 1 or self.reference_feed_mm_min <= 0 or self.entry_length_mm <= 0:
            raise GreyboxError("cutting: spindle speed, teeth, reference feed and entry length must be positive")
        if not 0.0 < self.workpiece_fraction <= 1.0:
            raise GreyboxError(f"cutting: workpiece fraction must be in (0, 1], got {self.workpiece_fraction}")

    @property
    def tooth_frequency_hz(self) -> float:
        """Tooth-passing frequency ``n z / 60`` [Hz]."""
        return self.spindle_rpm * self.teeth / 60.0

    def workpiece(self, position_mm) -> tuple[float, float]:
        """Extent [mm] of the workpiece for a log covering ``position_mm``.

        Parameters
        ----------
        position_mm : array_like
            Positions [mm] the log covers; only their smallest and largest value count, and they
            are ignored when ``workpiece_mm`` is set.
        """
        if self.workpiece_mm is not None:
            return float(self.workpiece_mm[0]), float(self.workpiece_mm[1])
        low, high = float(np.min(position_mm)), float(np.max(position_mm))
        margin = 0.5 * (1.0 - self.workpiece_fraction) * (high - low)
        return low + margin, high - margin

    def to_dict(self) -> dict:
        """JSON-serialisable settings."""
        settings = asdict(self)
        if self.workpiece_mm is not None:
            settings["workpiece_mm"] = list(self.workpiece_mm)
        return settings


def _engagement(position_mm, workpiece, entry_length_mm):
    x = np.asarray(position_mm, dtype=float)
    low, high = workpiece
    entry = np.clip((x - low) / entry_length_mm, 0.0, 1.0)
    exit_ = np.clip((high - x) / entry_length_mm, 0.0, 1.0)
    return np.sin(0.5 * np.pi * entry) ** 2 * np.sin(0.5 * np.pi * exit_) ** 2


def cutting_current(spec: CuttingSpec, time_s, position_mm, velocity_mm_s) -> np.ndarray:
    """Process current [A] of the cutting load along a motion (zero outside the cut segments).

    Parameters
    ----------
    spec : CuttingSpec
        Cutting conditions.
    time_s : array_like, shape (n,)
        Sample times [s]; they set the phase of the tooth-passing ripple.
    position_mm : array_like, shape (n,)
        True axis position [mm]; sets the engagement and, by default, the workpiece extent.
    velocity_mm_s : array_like, shape (n,)
        True axis velocity [mm/s]; its sign picks the cutting or return stroke and that of the current,
        its magnitude the feed factor.
    """
    v = np.asarray(velocity_mm_s, dtype=float)
    share = np.where(v * spec.cutting_direction > 0.0, 1.0, np.where(v != 0.0, spec.return_pass, 0.0))
    engagement = _engagement(position_mm, spec.workpiece(position_mm), spec.entry_length_mm)
    feed = (np.abs(v) / (spec.reference_feed_mm_min / 60.0)) ** spec.feed_exponent
    tooth = np.abs(np.sin(np.pi * spec.tooth_frequency_hz * np.asarray(time_s, dtype=float)))
    ripple = 1.0 + spec.ripple * (0.5 * np.pi * tooth - 1.0)
    return np.where(share != 0.0, np.sign(v) * share * engagement * feed * spec.strength_A * ripple, 0.0)


def cut_segments(process_current_A) -> list[tuple[int, int]]:
    """Sample ranges ``[start, stop)`` during which the process current is non-zero.

    Parameters
    ----------
    process_current_A : array_like, shape (n,)
        Process current [A], e.g. from :func:`cutting_current`.
    """
    active = np.concatenate(([False], np.asarray(process_current_A) != 0.0, [False]))
    edges = np.flatnonzero(np.diff(active.astype(np.int8)))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])]
