"""Axis metadata: the drive-train constants that turn a motor current into a force on the table.

One small TOML file per axis (see ``examples/axis_x.toml`` and, for a rotary
axis, ``examples/axis_c.toml``)::

    name = "X"                        # optional: axis name
    torque_constant_Nm_per_A = 1.35   # motor torque constant k_t [Nm/A]
    screw_lead_mm = 10.0              # table travel per screw revolution h [mm]
    gear_ratio = 1.0                  # motor revolutions per screw revolution i [-] (default 1)
    efficiency_driving = 0.92         # motor drives the table against the load, 0 < eta <= 1 [-]
    efficiency_backdriven = 0.88      # the load drives the table along, the motor brakes [-]

    inertia_kg_m2 = 0.0042            # optional: moment of inertia at the motor shaft [kg m^2]

    [channels]                        # optional: columns of the log if not named by convention
    position_mm = "X1_ActualPosition"
    current_A = "X1_CurrentFeedback"

A rotary axis (rotary table, swivel head) has no screw: its file says
``motion = "rotary"``, gives ``gear_ratio`` as motor revolutions per
revolution of the axis (e.g. 90 for a worm gear, 1 for a direct drive) and no
``screw_lead_mm``; the constants then turn the current into a torque on the
axis in Nm (``K_0 = k_t i``). Its ``[channels]`` name rotary columns
(``position_deg = "C_Angle"``).

Every quantity carries its unit in its key; only these units are accepted, and
a key naming another unit (``screw_lead_m``, ``torque_constant_mNm_per_A``) is
an error asking for the conversion rather than a silent factor of 1000. The
``efficiency = 0.9`` alone (the form of older files) gives both directions the
same efficiency. The ``[channels]`` table is the column mapping of ``greybox.data.io.read_log``
(``{canonical_name: name_in_file}``; the canonical name may carry any supported
unit, e.g. ``position_um``).

The optional ``inertia_kg_m2`` is the axis's whole moment of inertia as the
motor shaft sees it (motor, coupling, gear and screw, and the moved mass
reflected through the screw: ``m (h / 2 pi)^2 / i^2``), as the drive's
commissioning measures it or the data sheets add it up. It gives the inertia
``J`` a model of the axis should find (:meth:`AxisConfig.model_inertia`), which
``greybox train --axis-config`` compares with the fitted one and ``--model auto``
takes as known.

The load (force or torque) these constants give is derived in :mod:`greybox.predict.process`.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import tomllib
import warnings
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from ..errors import GreyboxError
from .quantities import MOTIONS, Motion
from .units import CANONICAL_NAMES, known_column, parse_column_name

__all__ = ["AxisConfig", "read_axis_config", "parse_axis_config", "check_channels", "read_toml", "QUANTITIES",
           "OPTIONAL_QUANTITIES", "INERTIA"]

#: Accepted keys: key -> (quantity in words, unit, hint for the missing key).
QUANTITIES = {
    "torque_constant_Nm_per_A": ("torque constant k_t", "Nm/A", "from the motor data sheet (k_T, torque per A)"),
    "screw_lead_mm": ("screw lead h", "mm", "table travel per screw revolution"),
    "gear_ratio": ("gear ratio i", "motor revolutions per screw (rotary axis: axis) revolution",
                   "1.0 for a motor coupled directly to the screw or the rotary axis"),
    "efficiency_driving": ("driving efficiency eta_d", "a fraction, 0 < eta <= 1",
                           "the motor pushes the table against the load; about 0.9 for a ball screw"),
    "efficiency_backdriven": ("back-driven efficiency eta_b", "a fraction, 0 < eta <= 1",
                              "the load pushes the table along, the motor brakes; about 0.85, below eta_d"),
}

#: Optional quantity: key -> (quantity in words, unit, hint).
INERTIA = "inertia_kg_m2"
OPTIONAL_QUANTITIES = {
    INERTIA: ("moment of inertia at the motor shaft J_m", "kg m^2",
              "motor, coupling, gear, screw and the moved mass reflected, from the drive's commissioning"),
}

#: One efficiency for both directions (older axis files): stands for both keys above.
SHARED_EFFICIENCY = "efficiency"
_EFFICIENCIES = ("efficiency_driving", "efficiency_backdriven")

#: Stems of the keys above: a key starting with one of these but naming another unit is a unit error.
_STEMS = {"torque_constant": "torque_constant_Nm_per_A", "screw_lead": "screw_lead_mm", "lead": "screw_lead_mm",
          "gear_ratio": "gear_ratio", "efficiency": "efficiency_driving", "inertia": INERTIA}

#: Optional keys besides the quantities.
_OPTIONAL = ("name", "motion")

#: The quantity a linear axis needs and a rotary axis must not give.
_SCREW = "screw_lead_mm"

#: Values of an efficiency that read as a percentage of a real drive train (write x / 100 instead) [%].
PERCENT_EFFICIENCY = (30.0, 100.0)

#: Smallest efficiency taken without a note [-]: a ball screw drives at 0.85-0.95 (back-driven a little
#: less), a planetary or belt stage at 0.9-0.98, so a drive train of a feed axis passes well over half the
#: motor's power; only sliding lead screws and worm gears go down to 0.3. Below it the value is most likely
#: a slip (0.009 for 0.9, a percentage divided twice) and the process force would come out that many times
#: too large or small.
MIN_PLAUSIBLE_EFFICIENCY = 0.3

#: Keys with a default: a motor coupled directly (gear ratio 1).
DEFAULTS = {"gear_ratio": 1.0}

#: Smallest plausible screw lead [mm]; a smaller value was most likely written in metres.
MIN_LEAD_MM = 0.1


@dataclass(frozen=True)
class AxisConfig:
    """Drive-train constants of one feed axis, linear or rotary.

    Parameters
    ----------
    torque_constant_Nm_per_A : float
        Motor torque constant ``k_t`` [Nm/A]: torque per ampere of the
        current the log records.
    screw_lead_mm : float or None
        Screw lead ``h`` [mm]: table travel per screw revolution; ``None``
        for a rotary axis.
    gear_ratio : float
        ``i`` = motor revolutions per screw revolution [-] (1 for a direct
        coupling, 2 for a belt that halves the speed); for a rotary axis motor
        revolutions per revolution of the axis.
    efficiency_driving : float
        ``eta_d`` [-], 0 < eta <= 1: share of the motor's mechanical power that
        reaches the table (gear and screw together) while the motor drives the
        table against the load (power flows from the motor to the table).
    efficiency_backdriven : float, optional
        ``eta_b`` [-], 0 < eta <= 1: share of the table's mechanical power that
        reaches the motor while the load drives the table along its motion and
        the motor brakes (a back-driven screw); default ``efficiency_driving``.
    inertia_kg_m2 : float, optional
        Moment of inertia of the whole axis at the motor shaft ``J_m`` [kg m^2]; None when not known.
    name : str, default ""
        Axis name.
    motion : {"linear", "rotary"}, default "linear"
        Kind of axis: a linear axis needs ``screw_lead_mm``, a rotary one must not have it.
    channels : mapping of str to str, optional
        Column mapping of the log, ``{canonical_name: name_in_file}``.
    source : str, default ""
        File the configuration was read from.
    """

    torque_constant_Nm_per_A: float
    screw_lead_mm: float | None
    gear_ratio: float
    efficiency_driving: float
    efficiency_backdriven: float | None = None
    inertia_kg_m2: float | None = None
    name: str = ""
    motion: str = "linear"
    channels: Mapping[str, str] = field(default_factory=dict)
    source: str = ""

    def __post_init__(self):
        where = self.source or "<axis config>"
        if self.efficiency_backdriven is None:
            object.__setattr__(self, "efficiency_backdriven", self.efficiency_driving)
        if self.motion not in MOTIONS:
            _fail(where, f"motion must be one of {', '.join(MOTIONS)}, got {self.motion!r}")
        rotary = self.motion == "rotary"
        if rotary and self.screw_lead_mm is not None:
            _fail(where, f"a rotary axis has no {_SCREW}; give gear_ratio as motor revolutions per axis revolution")
        values = {key: getattr(self, key) for key in self.quantities}
        _check_values(values, where)
        if self.inertia_kg_m2 is not None:
            _check_values({INERTIA: self.inertia_kg_m2}, where)
        object.__setattr__(self, "channels", dict(self.channels))

    @property
    def quantities(self) -> tuple[str, ...]:
        """The keys of :data:`QUANTITIES` this kind of axis needs (a rotary axis has no screw lead)."""
        return tuple(key for key in QUANTITIES if key != _SCREW or self.motion == "linear")

    @property
    def units(self) -> Motion:
        """Units of the axis: the load is a force [N] on a linear axis, a torque [Nm] on a rotary one."""
        return MOTIONS[self.motion]

    @property
    def lossless_load_constant(self) -> float:
        """Load per ampere through a lossless drive train: ``K_0 = k_t i 2 pi / h`` [N/A] (h in m) on a
        linear axis, ``K_0 = k_t i`` [Nm/A] on a rotary one."""
        if self.motion == "rotary":
            return self.torque_constant_Nm_per_A * self.gear_ratio
        return self.torque_constant_Nm_per_A * self.gear_ratio * 2.0 * math.pi / (self.screw_lead_mm * 1e-3)

    @property
    def load_constants(self) -> tuple[float, float]:
        """Load per ampere, driving (``eta_d K_0``) and back-driven (``K_0 / eta_b``) [N/A, or Nm/A rotary].

        Driving: the motor pushes the table against the load and the share
        ``eta_d`` of its power reaches the table. Back-driven: the load pushes
        the table along and the share ``eta_b`` of the table's power reaches
        the motor (:mod:`greybox.predict.process` derives both).
        """
        lossless = self.lossless_load_constant
        return lossless * self.efficiency_driving, lossless / self.efficiency_backdriven

    def model_inertia(self, effort_unit: str) -> float | None:
        """The inertia ``J`` a model of this axis should find, in its effort's unit per acceleration.

        ``J_m`` at the motor shaft, seen through the drive train: per ampere
        of current ``J = J_m (2 pi i / h) / k_t`` [A s^2/mm] (``h`` in mm) on a
        linear axis, ``J = J_m i (pi / 180) / k_t`` [A s^2/deg] on a rotary
        one; for an effort in the load's unit (N, Nm) that times the lossless
        load constant ``K_0`` (:attr:`lossless_load_constant`), e.g.
        ``J_m (2 pi i / h)^2`` [kg] / 1000 in N s^2/mm.

        Parameters
        ----------
        effort_unit : str
            Unit of the model's effort: ``"A"``, or the load's unit (``"N"`` linear, ``"Nm"`` rotary).

        Returns
        -------
        float or None
            ``J`` [effort_unit s^2/mm, or s^2/deg rotary]; None when the file gives no ``inertia_kg_m2``.

        Raises
        ------
        GreyboxError
            For an effort unit the axis does not carry.
        """
        if effort_unit not in self.units.effort_units:
            _fail(self.source or "<axis config>", f"a {self.motion} axis has no effort in {effort_unit!r}; "
                                                  f"expected one of {', '.join(self.units.effort_units)}")
        if self.inertia_kg_m2 is None:
            return None
        if self.motion == "rotary":
            per_current = self.inertia_kg_m2 * self.gear_ratio * math.pi / 180.0 / self.torque_constant_Nm_per_A
        else:
            per_current = (self.inertia_kg_m2 * 2.0 * math.pi * self.gear_ratio
                           / (self.screw_lead_mm * self.torque_constant_Nm_per_A))
        return per_current if effort_unit == "A" else per_current * self.lossless_load_constant

    def without_torque_constant(self) -> "AxisConfig":
        """The same drive train for a log whose effort is the motor torque [Nm], not the current: ``k_t = 1``."""
        return dataclasses.replace(self, torque_constant_Nm_per_A=1.0)

    def process_load(self, process_current_A, velocity):
        """Load the drive exerts on the axis for a process current [A], by the direction of power flow.

        Parameters
        ----------
        process_current_A : array_like
            Process share of the motor current [A].
        velocity : array_like
            Axis velocity [mm/s, or deg/s rotary], broadcast against the current; its sign
            against the current's tells driving (``I v >= 0``; at rest no power
            flows and the driving constant is used) from back-driven (``I v < 0``).

        Returns
        -------
        ndarray
            ``eta_d K_0 I`` where driving, ``K_0 I / eta_b`` where back-driven: force on
            the table [N], or torque on a rotary axis [Nm].
        """
        current = np.asarray(process_current_A, dtype=float)
        velocity = np.asarray(velocity, dtype=float)
        driving, backdriven = self.load_constants
        return np.where(current * velocity < 0.0, backdriven * current, driving * current)

    def to_dict(self) -> dict:
        """The constants (and name, motion and channels) as a JSON-able dict, the keys of an axis file."""
        inertia = {} if self.inertia_kg_m2 is None else {INERTIA: float(self.inertia_kg_m2)}
        return {"name": self.name, "motion": self.motion,
                **{key: float(getattr(self, key)) for key in self.quantities}, **inertia,
                "channels": dict(self.channels)}

    def to_toml(self) -> str:
        """The axis file's text (TOML), which :func:`read_axis_config` reads back to an equal configuration."""
        lines = [f"name = {json.dumps(self.name)}"] if self.name else []
        lines += [f"motion = {json.dumps(self.motion)}"] if self.motion != "linear" else []
        lines += [f"{key} = {float(getattr(self, key))!r}  # {QUANTITIES[key][0]} [{QUANTITIES[key][1]}]"
                  for key in self.quantities]
        if self.inertia_kg_m2 is not None:
            words, unit, _ = OPTIONAL_QUANTITIES[INERTIA]
            lines.append(f"{INERTIA} = {float(self.inertia_kg_m2)!r}  # {words} [{unit}]")
        if self.channels:
            lines += ["", "[channels]"] + [f"{key} = {json.dumps(value)}" for key, value in self.channels.items()]
        return "\n".join(lines) + "\n"


def _fail(where: str, problem: str):
    raise GreyboxError(f"{where}: {problem}")


def _check_values(values: Mapping[str, object], where: str, names: Mapping[str, str] | None = None) -> None:
    """Raise unless every quantity is a finite number in its plausible range.

    ``names`` maps a quantity to the key the user wrote, if another (the shared ``efficiency``).
    """
    names = names or {}
    for key, value in values.items():
        words, unit, _ = {**QUANTITIES, **OPTIONAL_QUANTITIES}[key]
        written = names.get(key, key)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            shown = f"the text {value!r}" if isinstance(value, str) else f"a {type(value).__name__}"
            _fail(where, f"{written} must be a number ({words} in {unit}), got {shown}; write the number only, "
                         "the unit is in the key")
        if not math.isfinite(value) or value <= 0:
            _fail(where, f"{written} must be a positive number ({words} in {unit}), got {value}")
    for key in (key for key in _EFFICIENCIES if key in values):
        efficiency = values[key]
        if efficiency > 1.0:
            if PERCENT_EFFICIENCY[0] <= efficiency <= PERCENT_EFFICIENCY[1]:
                hint = f"; {efficiency:g} looks like a percentage, write {efficiency / 100:g}"
            else:
                hint = ("; an efficiency above 1 would make the drive train create power: write the share that "
                        "arrives, about 0.9 for a ball screw")
            _fail(where, f"{names.get(key, key)} must be a fraction 0 < eta <= 1, got {efficiency:g}{hint}")
    lead = values.get(_SCREW, MIN_LEAD_MM)
    if lead < MIN_LEAD_MM:
        _fail(where, f"screw_lead_mm = {lead:g} mm is implausibly small (below {MIN_LEAD_MM:g} mm); "
                     f"was it written in metres? {lead:g} m is {lead * 1000:g} mm")


def _note_low_efficiencies(values: Mapping[str, float], where: str, names: Mapping[str, str]) -> None:
    """Warn once per key as written of an efficiency below :data:`MIN_PLAUSIBLE_EFFICIENCY` (taken as given)."""
    noted = set()
    for key in _EFFICIENCIES:
        efficiency, written = values[key], names.get(key, key)
        if efficiency >= MIN_PLAUSIBLE_EFFICIENCY or written in noted:
            continue
        noted.add(written)
        slip = (f"; {efficiency:g} reads like {efficiency * 100:g} divided by 100 once too often"
                if MIN_PLAUSIBLE_EFFICIENCY <= efficiency * 100 <= 1.0 else "")
        warnings.warn(f"{where}: {written} = {efficiency:g} is implausibly low for a feed axis (a ball screw passes "
                      f"0.85-0.95 of the motor's power, below {MIN_PLAUSIBLE_EFFICIENCY:g} only sliding screws and "
                      f"worm gears){slip}; the process force scales with it", stacklevel=3)


def check_channels(table, where: str) -> dict[str, str]:
    """A ``[channels]`` table checked: ``{canonical_name: name_in_log}``, each quantity mapped once.

    Parameters
    ----------
    table : object
        The parsed ``[channels]`` value; valid when a dict of canonical column name to the log's name.
    where : str
        What is being read (file name, and axis table), prefixed to error messages.

    Raises
    ------
    GreyboxError
        For a table that is not one, a key that is not a quantity with a known unit, a name that is
        not text, or a quantity mapped twice; the message names ``where``.
    """
    if not isinstance(table, dict):
        _fail(where, "[channels] must be a table of canonical_name = \"name in the log\" pairs")
    known = ", ".join(CANONICAL_NAMES.values())
    channels: dict[str, str] = {}
    quantities: dict[str, str] = {}
    for key, value in table.items():
        parsed = parse_column_name(key)
        if not known_column(key):
            _fail(where, f"[channels]: '{key}' is not a quantity with a known unit; use e.g. {known}")
        if not isinstance(value, str) or not value.strip():
            _fail(where, f"[channels]: {key} must name a column of the log as text, got {value!r}")
        if parsed[0] in quantities:
            _fail(where, f"[channels]: the {parsed[0]} is mapped twice ({quantities[parsed[0]]} and {key})")
        quantities[parsed[0]] = key
        channels[key] = value.strip()
    return channels


def parse_axis_config(document: Mapping[str, object], source: str = "") -> AxisConfig:
    """Build an :class:`AxisConfig` from a parsed TOML document.

    Parameters
    ----------
    document : mapping
        The TOML content as a dict (see the module docstring for the keys).
    source : str, default ""
        File name for error messages.

    Returns
    -------
    AxisConfig

    Raises
    ------
    GreyboxError
        For a missing or unknown key, a key with another unit than the
        accepted one, a value that is not a number or out of range, or a bad
        ``[channels]`` table; the message names ``source``.
    """
    where = source or "<axis config>"
    values: dict[str, object] = {}
    motion = document.get("motion", "linear")
    if motion not in MOTIONS:
        _fail(where, f"motion must be one of {', '.join(repr(name) for name in MOTIONS)}, got {motion!r}")
    required = [key for key in QUANTITIES if key != _SCREW or motion == "linear"]
    if motion == "rotary" and _SCREW in document:
        _fail(where, f"a rotary axis (motion = \"rotary\") has no {_SCREW}; give gear_ratio as motor revolutions per "
                     "revolution of the axis")
    shared = document.get(SHARED_EFFICIENCY)
    given = [key for key in _EFFICIENCIES if key in document]
    if shared is not None and given:
        _fail(where, f"give either '{SHARED_EFFICIENCY}' (both directions) or {' and '.join(_EFFICIENCIES)}, "
                     f"not '{SHARED_EFFICIENCY}' and {' and '.join(given)}")
    for key, value in document.items():
        if key in QUANTITIES:
            values[key] = value
        elif key == SHARED_EFFICIENCY:
            values.update({name: value for name in _EFFICIENCIES})
        elif key == "channels" or key in OPTIONAL_QUANTITIES:
            continue
        elif key in _OPTIONAL:
            if not isinstance(value, str):
                _fail(where, f"{key} must be text, got {value!r}")
        else:
            stem = next((s for s in sorted(_STEMS, key=len, reverse=True) if key == s or key.startswith(s + "_")), None)
            if stem is not None:
                accepted = _STEMS[stem]
                words, unit, _ = {**QUANTITIES, **OPTIONAL_QUANTITIES}[accepted]
                problem = "no unit in the key" if key == stem else "unit not accepted"
                _fail(where, f"'{key}': {problem}; give the {words} as '{accepted}' (in {unit})")
            expected = ", ".join(list(QUANTITIES) + [SHARED_EFFICIENCY] + list(OPTIONAL_QUANTITIES) + list(_OPTIONAL)
                                 + ["[channels]"])
            _fail(where, f"unknown key '{key}'; expected {expected}")
    values = {**{key: value for key, value in DEFAULTS.items() if key in required}, **values}
    missing = [key for key in required if key not in values]
    if any(key in missing for key in _EFFICIENCIES) and not given:
        missing = [key for key in missing if key not in _EFFICIENCIES]
        _fail(where, "missing efficiency (the share of the motor's power reaching the table, about 0.9 for a ball "
                     "screw): give 'efficiency' for both directions, or efficiency_driving and efficiency_backdriven"
                     + (f"; also missing {', '.join(missing)}" if missing else "")
                     + (f" (for a rotary axis write motion = \"rotary\" instead of a {_SCREW})"
                        if _SCREW in missing and motion == "linear" else ""))
    if missing:
        lines = "; ".join(f"{key} ({QUANTITIES[key][0]} in {QUANTITIES[key][1]}: {QUANTITIES[key][2]})"
                          for key in missing)
        hint = (f" (for a rotary axis write motion = \"rotary\" instead of a {_SCREW})"
                if _SCREW in missing and motion == "linear" else "")
        _fail(where, f"missing {lines}{hint}")
    written = {key: SHARED_EFFICIENCY for key in _EFFICIENCIES} if shared is not None else {}
    _check_values(values, where, written or None)
    _note_low_efficiencies(values, where, written)
    channels = check_channels(document.get("channels", {}), where)
    constants = {_SCREW: None, **{key: float(values[key]) for key in required}}
    inertia = document.get(INERTIA)
    if inertia is not None:
        _check_values({INERTIA: inertia}, where)
        inertia = float(inertia)
    return AxisConfig(**constants, inertia_kg_m2=inertia, name=str(document.get("name", "")), motion=motion,
                      channels=channels, source=source)


def read_toml(path, what: str = "axis configuration") -> dict:
    """The parsed content of a TOML file.

    Parameters
    ----------
    path : str or path-like
        TOML file.
    what : str, default "axis configuration"
        What the file is, for the messages ("machine file").

    Raises
    ------
    GreyboxError
        For a missing or unreadable file, a directory, text that is not UTF-8 or not valid TOML;
        the message names the file.
    """
    path = os.fspath(path)
    try:
        with open(path, "rb") as stream:
            return tomllib.load(stream)
    except FileNotFoundError:
        _fail(path, f"no such {what} file")
    except IsADirectoryError:
        _fail(path, f"is a directory; expected a TOML {what} file")
    except OSError as exc:
        _fail(path, f"cannot read the {what} file ({exc.strerror or exc})")
    except UnicodeDecodeError:
        _fail(path, "not a TOML file (not UTF-8 text)")
    except tomllib.TOMLDecodeError as exc:
        _fail(path, f"not valid TOML ({exc})")


def read_axis_config(path) -> AxisConfig:
    """Read an axis metadata TOML file.

    Parameters
    ----------
    path : str or path-like
        TOML file (see the module docstring and ``examples/axis_x.toml``).

    Returns
    -------
    AxisConfig

    Raises
    ------
    GreyboxError
        For a missing or unreadable file, invalid TOML, or content that
        :func:`parse_axis_config` refuses; the message names the file.
    """
    return parse_axis_config(read_toml(path), source=os.fspath(path))
