"""The machine file: the axes of a machine, their channels in a several-axis log and their mechanics.

One TOML file per machine (see ``examples/machine.toml``)::

    name = "five-axis mill"              # optional

    [channels]                           # optional: columns shared by every axis
    time_s = "Time"

    [axes.X]                             # one table per axis: an axis file (greybox.data.axis_config)
    torque_constant_Nm_per_A = 1.35
    screw_lead_mm = 10.0
    gear_ratio = 1.0
    efficiency_driving = 0.9
    efficiency_backdriven = 0.85
    [axes.X.channels]                    # optional: the axis's columns if not named X_position_mm, ...
    position_mm = "X1_ActualPosition"
    current_A = "X1_CurrentFeedback"

    [axes.C]
    motion = "rotary"
    torque_constant_Nm_per_A = 1.35
    gear_ratio = 90.0
    efficiency = 0.75

An axis table holds the keys of an axis file; it may give only ``channels``
(and ``motion``) when the mechanics are not known: the axis then trains and
predicts its process current, without force or torque. Without a
``channels`` table an axis's columns are found by their prefix
(``X_position_mm``, ``X_current_A``; :func:`greybox.data.units.select_axis`),
in MCAP files by the channel ``/axis/X``, in TDMS files by the group ``X``.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from typing import Mapping

from ..errors import GreyboxError
from .axis_config import QUANTITIES, SHARED_EFFICIENCY, AxisConfig, check_channels, parse_axis_config, read_toml
from .quantities import MOTIONS

__all__ = ["MachineAxis", "MachineConfig", "parse_machine_config", "read_machine_config"]

#: Keys of an axis table that describe mechanics (any of them makes the table a full axis file).
_MECHANICS = (*QUANTITIES, SHARED_EFFICIENCY)


@dataclass(frozen=True)
class MachineAxis:
    """One axis of a machine file.

    Parameters
    ----------
    name : str
        Axis name, e.g. ``"X"``: the prefix of its columns, its MCAP channel ``/axis/<name>``.
    motion : {"linear", "rotary"}
        Kind of axis.
    channels : mapping of str to str
        Column mapping of the axis (``{canonical_name: name_in_file}``), the machine's shared
        channels included; empty when the columns are found by their prefix.
    config : AxisConfig or None
        The axis's mechanics, None when the machine file gives none.
    """

    name: str
    motion: str
    channels: Mapping[str, str] = field(default_factory=dict)
    config: AxisConfig | None = None


@dataclass(frozen=True)
class MachineConfig:
    """The axes of a machine, in the order of the machine file.

    Parameters
    ----------
    axes : mapping of str to MachineAxis
        The axes by name.
    name : str, default ""
        Machine name.
    source : str, default ""
        File the configuration was read from.
    """

    axes: Mapping[str, MachineAxis]
    name: str = ""
    source: str = ""

    def axis(self, name: str) -> MachineAxis:
        """The axis called ``name``.

        Parameters
        ----------
        name : str
            Axis name as in the machine file's ``[axes.NAME]`` table (e.g. ``"X"``).

        Raises
        ------
        GreyboxError
            When the machine file has no such axis (the message lists its axes).
        """
        if name not in self.axes:
            raise GreyboxError(f"{self.source or '<machine config>'}: no axis '{name}'; the machine has "
                               f"{', '.join(self.axes)}")
        return self.axes[name]


def _fail(where: str, problem: str):
    raise GreyboxError(f"{where}: {problem}")


def parse_machine_config(document: Mapping[str, object], source: str = "") -> MachineConfig:
    """Build a :class:`MachineConfig` from a parsed TOML document.

    Parameters
    ----------
    document : mapping
        The TOML content as a dict (see the module docstring).
    source : str, default ""
        File name for error messages.

    Returns
    -------
    MachineConfig

    Raises
    ------
    GreyboxError
        For an unknown key, no axes, an axis table that is not a valid axis file (or channels and
        motion only), a bad channel mapping; the message names ``source`` and the axis.
    """
    where = source or "<machine config>"
    unknown = sorted(set(document) - {"name", "channels", "axes"})
    if unknown:
        _fail(where, f"unknown key '{unknown[0]}'; a machine file has name, [channels] and [axes.NAME] tables")
    name = document.get("name", "")
    if not isinstance(name, str):
        _fail(where, f"name must be text, got {name!r}")
    shared = check_channels(document.get("channels", {}), where)
    tables = document.get("axes")
    if not isinstance(tables, dict) or not tables:
        _fail(where, "no axes: give one [axes.NAME] table per axis, e.g. [axes.X]")
    axes = {}
    for axis, table in tables.items():
        inside = f"{where}: [axes.{axis}]"
        if not (axis[:1].isalpha() and axis.isalnum()):
            _fail(where, f"axis name '{axis}' must be letters and digits, starting with a letter (it prefixes "
                         "the axis's columns, e.g. X_position_mm)")
        if not isinstance(table, dict):
            _fail(where, f"axes.{axis} must be a table")
        motion = table.get("motion", "linear")
        if motion not in MOTIONS:
            _fail(inside, f"motion must be one of {', '.join(repr(m) for m in MOTIONS)}, got {motion!r}")
        channels = {**shared, **check_channels(table.get("channels", {}), inside)}
        config = None
        if any(key in table for key in _MECHANICS):
            config = parse_axis_config({"name": axis, **{k: v for k, v in table.items() if k != "name"}},
                                       source=inside)
            config = dataclasses.replace(config, channels=channels, source=source)
        else:
            extra = sorted(set(table) - {"motion", "channels"})
            if extra:
                _fail(inside, f"unknown key '{extra[0]}'; give the axis's mechanics as in an axis file "
                              f"({', '.join(QUANTITIES)}) or only motion and [channels]")
        axes[axis] = MachineAxis(axis, motion, channels, config)
    return MachineConfig(axes=axes, name=name, source=source)


def read_machine_config(path) -> MachineConfig:
    """Read a machine TOML file.

    Parameters
    ----------
    path : str or path-like
        TOML file (see the module docstring and ``examples/machine.toml``).

    Returns
    -------
    MachineConfig

    Raises
    ------
    GreyboxError
        For a missing or unreadable file, invalid TOML, or content :func:`parse_machine_config` refuses.
    """
    return parse_machine_config(read_toml(path, "machine"), source=os.fspath(path))
