"""Axis metadata: the drive-train constants that turn a motor current into a force on the table.

One small TOML file per axis (see ``examples/axis_x.toml``)::

    name = "X"                        # optional: axis name
    torque_constant_Nm_per_A = 1.35   # motor torque constant k_t [Nm/A]
    screw_lead_mm = 10.0              # table travel per screw revolution h [mm]
    gear_ratio = 1.0                  # motor revolutions per screw revolution i [-]
    efficiency = 0.9                  # efficiency of motor shaft -> table, 0 < eta <= 1 [-]

    [channels]                        # optional: columns of the log if not named by convention
    position_mm = "X1_ActualPosition"
    current_A = "X1_CurrentFeedback"

Every quantity carries its unit in its key; only these units are accepted, and
a key naming another unit (``screw_lead_m``, ``torque_constant_mNm_per_A``) is
an error asking for the conversion rather than a silent factor of 1000. The
``[channels]`` table is the column mapping of ``greybox.data.io.read_log``
(``{canonical_name: name_in_file}``; the canonical name may carry any supported
unit, e.g. ``position_um``).

The force these constants give is derived in :mod:`greybox.evaluate.process`.
"""

from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass, field
from typing import Mapping

from ..errors import GreyboxError
from .units import CANONICAL_NAMES, UNIT_FACTORS, parse_column_name

__all__ = ["AxisConfig", "read_axis_config", "parse_axis_config", "QUANTITIES"]

#: Accepted keys: key -> (quantity in words, unit, hint for the missing key).
QUANTITIES = {
    "torque_constant_Nm_per_A": ("torque constant k_t", "Nm/A", "from the motor data sheet (k_T, torque per A)"),
    "screw_lead_mm": ("screw lead h", "mm", "table travel per screw revolution"),
    "gear_ratio": ("gear ratio i", "motor revolutions per screw revolution",
                   "1.0 for a motor coupled directly to the screw"),
    "efficiency": ("efficiency eta", "fraction, 0 < eta <= 1", "about 0.9 for a ball screw"),
}

#: Stems of the keys above: a key starting with one of these but naming another unit is a unit error.
_STEMS = {"torque_constant": "torque_constant_Nm_per_A", "screw_lead": "screw_lead_mm", "lead": "screw_lead_mm",
          "gear_ratio": "gear_ratio", "efficiency": "efficiency"}

#: Optional keys besides the quantities.
_OPTIONAL = ("name",)

#: Smallest plausible screw lead [mm]; a smaller value was most likely written in metres.
MIN_LEAD_MM = 0.1


@dataclass(frozen=True)
class AxisConfig:
    """Drive-train constants of one feed axis.

    Parameters
    ----------
    torque_constant_Nm_per_A : float
        Motor torque constant ``k_t`` [Nm/A]: torque per ampere of the
        current the log records.
    screw_lead_mm : float
        Screw lead ``h`` [mm]: table travel per screw revolution.
    gear_ratio : float
        ``i`` = motor revolutions per screw revolution [-] (1 for a direct
        coupling, 2 for a belt that halves the speed).
    efficiency : float
        ``eta`` [-], 0 < eta <= 1: share of the motor's mechanical power that
        reaches the table (gear and screw together).
    name : str, default ""
        Axis name.
    channels : mapping of str to str, optional
        Column mapping of the log, ``{canonical_name: name_in_file}``.
    source : str, default ""
        File the configuration was read from.
    """

    torque_constant_Nm_per_A: float
    screw_lead_mm: float
    gear_ratio: float
    efficiency: float
    name: str = ""
    channels: Mapping[str, str] = field(default_factory=dict)
    source: str = ""

    def __post_init__(self):
        values = {key: getattr(self, key) for key in QUANTITIES}
        _check_values(values, self.source or "<axis config>")
        object.__setattr__(self, "channels", dict(self.channels))


def _fail(where: str, problem: str):
    raise GreyboxError(f"{where}: {problem}")


def _check_values(values: Mapping[str, object], where: str) -> None:
    """Raise unless every quantity is a finite number in its plausible range."""
    for key, value in values.items():
        words, unit, _ = QUANTITIES[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            shown = f"the text {value!r}" if isinstance(value, str) else f"a {type(value).__name__}"
            _fail(where, f"{key} must be a number ({words} in {unit}), got {shown}; write the number only, "
                         "the unit is in the key")
        if not math.isfinite(value) or value <= 0:
            _fail(where, f"{key} must be a positive number ({words} in {unit}), got {value}")
    efficiency = values["efficiency"]
    if efficiency > 1.0:
        hint = f"; {efficiency:g} looks like a percentage, write {efficiency / 100:g}" if efficiency <= 100 else ""
        _fail(where, f"efficiency must be a fraction 0 < eta <= 1, got {efficiency:g}{hint}")
    lead = values["screw_lead_mm"]
    if lead < MIN_LEAD_MM:
        _fail(where, f"screw_lead_mm = {lead:g} mm is implausibly small (below {MIN_LEAD_MM:g} mm); "
                     f"was it written in metres? {lead:g} m is {lead * 1000:g} mm")


def _check_channels(table, where: str) -> dict[str, str]:
    if not isinstance(table, dict):
        _fail(where, "[channels] must be a table of canonical_name = \"name in the log\" pairs")
    known = ", ".join(CANONICAL_NAMES.values())
    channels: dict[str, str] = {}
    quantities: dict[str, str] = {}
    for key, value in table.items():
        parsed = parse_column_name(key)
        if parsed is None or parsed[1] is None or parsed[1] not in UNIT_FACTORS[parsed[0]]:
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
    for key, value in document.items():
        if key in QUANTITIES:
            values[key] = value
        elif key == "channels":
            continue
        elif key in _OPTIONAL:
            if not isinstance(value, str):
                _fail(where, f"{key} must be text, got {value!r}")
        else:
            stem = next((s for s in sorted(_STEMS, key=len, reverse=True) if key == s or key.startswith(s + "_")), None)
            if stem is not None:
                accepted = _STEMS[stem]
                words, unit, _ = QUANTITIES[accepted]
                problem = "no unit in the key" if key == stem else "unit not accepted"
                _fail(where, f"'{key}': {problem}; give the {words} as '{accepted}' (in {unit})")
            expected = ", ".join(list(QUANTITIES) + list(_OPTIONAL) + ["[channels]"])
            _fail(where, f"unknown key '{key}'; expected {expected}")
    missing = [key for key in QUANTITIES if key not in values]
    if missing:
        lines = "; ".join(f"{key} ({QUANTITIES[key][0]} in {QUANTITIES[key][1]}: {QUANTITIES[key][2]})"
                          for key in missing)
        _fail(where, f"missing {lines}")
    _check_values(values, where)
    channels = _check_channels(document.get("channels", {}), where)
    return AxisConfig(**{key: float(values[key]) for key in QUANTITIES}, name=str(document.get("name", "")),
                      channels=channels, source=source)


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
    path = os.fspath(path)
    try:
        with open(path, "rb") as stream:
            document = tomllib.load(stream)
    except FileNotFoundError:
        _fail(path, "no such axis configuration file")
    except IsADirectoryError:
        _fail(path, "is a directory, not an axis configuration file")
    except OSError as exc:
        _fail(path, f"cannot read the axis configuration ({exc.strerror or exc})")
    except UnicodeDecodeError:
        _fail(path, "not a TOML file (not UTF-8 text)")
    except tomllib.TOMLDecodeError as exc:
        _fail(path, f"not valid TOML ({exc})")
    return parse_axis_config(document, source=path)
