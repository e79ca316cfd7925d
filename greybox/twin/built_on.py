"""A truth plant built on another: it changes the friction and keeps the rest of the plant it wraps.

:class:`~greybox.twin.ageing.AgedPlant` (play and a local defect) and
:class:`~greybox.twin.part_series.WarmPlant` (the warm-up law) alter only the friction of a
:class:`~greybox.twin.plant.PlantParameters`; the axis file and the process load they hand on unchanged
come from here.
"""

from __future__ import annotations

__all__ = ["BuiltOnPlant"]


class BuiltOnPlant:
    """Mix-in handing the axis file and the process load on to the wrapped plant :attr:`underlying`."""

    @property
    def underlying(self):
        """The wrapped plant (a :class:`~greybox.twin.plant.PlantParameters`)."""
        raise NotImplementedError

    def axis_config(self, name: str = ""):
        """The wrapped plant's axis file (:meth:`~greybox.twin.plant.PlantParameters.axis_config`).

        Parameters
        ----------
        name : str, default ""
            Axis name written into the axis file.
        """
        return self.underlying.axis_config(name)

    def process_load(self, process_A, velocity_mm_s):
        """Process force [N] behind a process current [A] (:meth:`~greybox.twin.plant.PlantParameters.process_load`).

        Parameters
        ----------
        process_A : array_like
            Process current [A].
        velocity_mm_s : array_like
            Axis velocity [mm/s].
        """
        return self.underlying.process_load(process_A, velocity_mm_s)
