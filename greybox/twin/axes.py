"""Geometry of the synthetic axes: the feed axes X and Y and the rotary table C.

The travels and measurement windows of X and Y follow Table 1 of Rüppel et al.
(2024), recorded on a Mazak VARIAXIS i-600: the random datasets A and C move
inside a 50 mm window in the middle of the travel, the constant-speed datasets
B and D cross the whole travel. The paper's machine is a five-axis machining
centre; its rotary table C is not in the paper's tables, and the synthetic C
axis is this package's own: a table turned through a worm gear, its angles in
degrees (travel one turn, -180 to 180 deg, random datasets inside a 50 deg
window). Lengths of a rotary axis are in deg wherever the twin says mm.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import GreyboxError

__all__ = ["AxisGeometry", "AXES", "axis_geometry"]


@dataclass(frozen=True)
class AxisGeometry:
    """Travel and measurement window of one axis.

    Parameters
    ----------
    name : str
        Axis name, e.g. ``"X"``.
    travel_mm : tuple of float
        Lower and upper end [mm] of the travel used by the constant-speed datasets.
    window_mm : tuple of float
        Lower and upper end [mm] of the window of the random datasets.
    motion : {"linear", "rotary"}, default "linear"
        Kind of axis; the travel and window of a rotary axis are in deg.
    """

    name: str
    travel_mm: tuple[float, float]
    window_mm: tuple[float, float]
    motion: str = "linear"

    @property
    def window_centre_mm(self) -> float:
        """Centre [mm] of the measurement window."""
        return 0.5 * (self.window_mm[0] + self.window_mm[1])


#: The two axes of the paper's Table 1, and a rotary table (angles in deg).
AXES = {
    "X": AxisGeometry("X", travel_mm=(-510.0, 0.0), window_mm=(-275.0, -225.0)),
    "Y": AxisGeometry("Y", travel_mm=(-910.0, 0.0), window_mm=(-475.0, -425.0)),
    "C": AxisGeometry("C", travel_mm=(-180.0, 180.0), window_mm=(-25.0, 25.0), motion="rotary"),
}


def axis_geometry(axis: str) -> AxisGeometry:
    """Return the geometry of ``axis`` (``"X"``, ``"Y"`` or ``"C"``, case-insensitive).

    Parameters
    ----------
    axis : str
        Axis name; surrounding blanks and the case are ignored.

    Raises
    ------
    GreyboxError
        If the axis is unknown.
    """
    key = str(axis).strip().upper()
    if key not in AXES:
        raise GreyboxError(f"unknown axis {axis!r}; the synthetic machine has axes {', '.join(AXES)}")
    return AXES[key]
