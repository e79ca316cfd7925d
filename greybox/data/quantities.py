"""The two kinds of axis motion and the units greybox keeps each in.

A linear feed axis (a ball-screw drive) moves in mm and its drive pushes the
table with a force in N; a rotary axis (the A or C axis of a five-axis machine,
a rotary table) turns in degrees and its drive exerts a torque in Nm. The
models do not care: they see numbers for position, velocity and acceleration,
and a current in A (or the load itself). What changes is what the numbers
mean: column names, labels of tables and figures, the units of identified
parameters (``A s/mm`` or ``A s/deg``) and the load the process current
stands for. :class:`Motion` holds those names in one place; every label is
derived from it.

This module imports nothing else of greybox.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

__all__ = ["Motion", "LINEAR", "ROTARY", "MOTIONS", "motion_named"]


@dataclass(frozen=True)
class Motion:
    """Units and names of one kind of axis motion.

    Parameters
    ----------
    name : str
        ``"linear"`` or ``"rotary"``.
    length : str
        Unit of the position: ``"mm"`` or ``"deg"``.
    load : str
        What the drive exerts on the axis: ``"force"`` or ``"torque"``.
    load_unit : str
        Unit of the load: ``"N"`` or ``"Nm"``.
    """

    name: str
    length: str
    load: str
    load_unit: str

    @property
    def velocity_unit(self) -> str:
        """Unit of the velocity, e.g. ``"mm/s"``."""
        return f"{self.length}/s"

    @property
    def acceleration_unit(self) -> str:
        """Unit of the acceleration, e.g. ``"mm/s^2"``."""
        return f"{self.length}/s^2"

    @property
    def fine_unit(self) -> str:
        """A thousandth of the length unit, for tracking errors: ``"um"`` or ``"mdeg"``."""
        return "um" if self.length == "mm" else f"m{self.length}"

    @property
    def feed_unit(self) -> str:
        """Unit machinists give feeds in, e.g. ``"mm/min"``."""
        return f"{self.length}/min"

    @property
    def position_column(self) -> str:
        """Canonical column of the position, e.g. ``"position_mm"``."""
        return f"position_{self.length}"

    @property
    def velocity_column(self) -> str:
        """Canonical column of the velocity, e.g. ``"velocity_mm_s"``."""
        return f"velocity_{self.length}_s"

    @property
    def acceleration_column(self) -> str:
        """Canonical column of the acceleration, e.g. ``"acceleration_mm_s2"``."""
        return f"acceleration_{self.length}_s2"

    @property
    def load_column(self) -> str:
        """Canonical column of the load, ``"force_N"`` or ``"torque_Nm"``."""
        return f"{self.load}_{self.load_unit}"

    @property
    def effort_units(self) -> tuple[str, str]:
        """Effort units a log of this motion may carry: the current ``"A"`` or the load's unit."""
        return ("A", self.load_unit)

    def effort_column(self, effort_unit: str) -> str:
        """Canonical column of an effort in ``effort_unit``: ``"current_A"`` or the load column.

        Parameters
        ----------
        effort_unit : str
            ``"A"`` for a motor current; any other unit gives the load column.
        """
        return "current_A" if effort_unit == "A" else self.load_column

    def relabel(self, text: str) -> str:
        """A name or label written in mm, in this motion's length unit.

        Names of effect parameters and labels that the package writes in mm (``"period_mm"``,
        ``"slope_A_per_mm"``, ``"velocity [mm/s]"``) read ``"period_deg"``, ``"slope_A_per_deg"``,
        ``"velocity [deg/s]"`` for a rotary axis; a linear axis's text is returned as is.

        Parameters
        ----------
        text : str
            Name or label written for a linear axis; each ``mm`` that stands as a word is replaced.
        """
        return text if self.length == "mm" else _MM.sub(self.length, text)

    def effort_label(self, effort_unit: str) -> str:
        """Axis label of an effort, e.g. ``"motor current [A]"`` or ``"torque [Nm]"``.

        Parameters
        ----------
        effort_unit : str
            ``"A"`` for a motor current; any other unit gives the load's label.
        """
        return "motor current [A]" if effort_unit == "A" else f"{self.load} [{self.load_unit}]"


#: The length unit "mm" as a word of a name or label (not inside another word).
_MM = re.compile(r"(?<![A-Za-z])mm(?![A-Za-z])")

#: A ball-screw (or linear-motor) feed axis.
LINEAR = Motion("linear", "mm", "force", "N")

#: A rotary axis: rotary table, swivel head, robot joint.
ROTARY = Motion("rotary", "deg", "torque", "Nm")

#: The motions by name.
MOTIONS = {motion.name: motion for motion in (LINEAR, ROTARY)}


def motion_named(name: str) -> Motion:
    """Return the :class:`Motion` called ``name`` (``"linear"`` or ``"rotary"``).

    Parameters
    ----------
    name : str
        ``"linear"`` or ``"rotary"``.

    Raises
    ------
    ValueError
        For any other name.
    """
    try:
        return MOTIONS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown motion {name!r}; expected one of {', '.join(MOTIONS)}") from None
