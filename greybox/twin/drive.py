"""The drive train of the synthetic axes: the axis file that turns their process current into force.

A process force ``F`` on the table (the cutting load) reaches the motor
through the screw. Through a lossless drive train it would need the current
``F / K_0``, ``K_0 = k_t i 2 pi / h``; the losses that grow with the load are
written two ways in the twin, and each synthetic log's axis file
(``attrs["cutting"]["axis_config"]``, :meth:`AxisConfig.process_load
<greybox.data.axis_config.AxisConfig.process_load>`) converts its process
current back into ``F`` either way:

* the X and Y axes book them in the process current: ``truth_process_A`` is
  what the motor supplies for the process, ``F / (eta_d K_0)`` while it
  pushes against the load and ``eta_b F / K_0`` while the load back-drives
  the screw, with the efficiencies of ``examples/axis_x.toml``
  (:data:`AXIS_EFFICIENCIES`);
* a member of the truth family books them in its friction, which grows by
  ``g`` amperes per ampere of axial load in the friction's direction
  (:meth:`~greybox.twin.plant.PlantResponse.under_load`): ``truth_process_A``
  is ``F / K_0`` and the motor supplies ``(1 + g)`` times that while driving,
  ``(1 - g)`` times while back-driven; read as an axis file,
  ``eta_d = 1 / (1 + g)`` and ``eta_b = 1 - g`` (:func:`load_gain_efficiencies`).
  These hold in gross sliding at the law's peak friction; below it (the
  sliding level is 55-95 % of the peak, in pre-sliding the friction is on its
  way) the friction carries less of the load and the nominal values
  over-correct by up to ``g`` times that share, as a catalogue efficiency
  does on a real machine.
"""

from __future__ import annotations

from ..data.axis_config import AxisConfig

__all__ = ["TORQUE_CONSTANT_NM_PER_A", "GEAR_RATIO", "AXIS_EFFICIENCIES", "WORM_EFFICIENCIES",
           "load_gain_efficiencies", "drive_config"]

#: Motor torque constant of every synthetic axis [Nm/A] (that of examples/axis_x.toml).
TORQUE_CONSTANT_NM_PER_A = 1.35

#: Motor revolutions per screw revolution of every synthetic axis (motor coupled directly to the screw).
GEAR_RATIO = 1.0

#: Efficiencies (driving, back-driven) of the X and Y axes' screws (those of examples/axis_x.toml).
AXIS_EFFICIENCIES = (0.9, 0.85)

#: Efficiencies (driving, back-driven) of the rotary C axis's worm gear (those of examples/axis_c.toml):
#: a preloaded worm loses more than a ball screw, and more still when the table drives the worm.
WORM_EFFICIENCIES = (0.8, 0.7)


def load_gain_efficiencies(load_gain: float) -> tuple[float, float]:
    """Efficiencies (driving, back-driven) that friction rising by ``load_gain`` A per A of axial load implies.

    Parameters
    ----------
    load_gain : float
        ``g`` [A/A]: friction current added per ampere of axial load; gives ``(1 / (1 + g), 1 - g)``.
    """
    return 1.0 / (1.0 + load_gain), 1.0 - load_gain


def drive_config(lead_mm: float, efficiencies: tuple[float, float], name: str = "",
                 motion: str = "linear") -> AxisConfig:
    """The axis file of a synthetic axis.

    Parameters
    ----------
    lead_mm : float
        Axis travel per revolution of the driven element [mm]: the screw lead, or for a rotary
        axis the angle [deg] the table turns per revolution of the worm.
    efficiencies : (float, float)
        Driving and back-driven efficiency [-].
    name : str, default ""
        Axis name.
    motion : {"linear", "rotary"}, default "linear"
        Kind of axis.

    Returns
    -------
    AxisConfig
        With the twin's motor (:data:`TORQUE_CONSTANT_NM_PER_A`) and coupling (:data:`GEAR_RATIO`); a
        rotary axis's motor turns the worm directly, gear ratio ``360 / lead``.
    """
    if motion == "rotary":
        return AxisConfig(torque_constant_Nm_per_A=TORQUE_CONSTANT_NM_PER_A, screw_lead_mm=None,
                          gear_ratio=360.0 / float(lead_mm), efficiency_driving=float(efficiencies[0]),
                          efficiency_backdriven=float(efficiencies[1]), name=name, motion=motion,
                          source="greybox.twin")
    return AxisConfig(torque_constant_Nm_per_A=TORQUE_CONSTANT_NM_PER_A, screw_lead_mm=float(lead_mm),
                      gear_ratio=GEAR_RATIO, efficiency_driving=float(efficiencies[0]),
                      efficiency_backdriven=float(efficiencies[1]), name=name, source="greybox.twin")
