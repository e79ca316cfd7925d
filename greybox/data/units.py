"""Units of logged quantities and the mapping of named columns to an :class:`AxisLog`.

Every reader (CSV, Parquet, MCAP, MATLAB, TDMS) ends in :func:`log_from_columns`:
the file gives named numeric columns, this module finds the base channels among
them by their name and unit suffix, converts them to the canonical units and
keeps every other numeric column as an extra channel.

A column name is ``<quantity>_<unit>``, e.g. ``position_um`` or
``velocity_mm_min``. The quantities and the unit suffixes understood are listed
in :data:`UNIT_FACTORS`; the factor converts a value in that unit to the
canonical unit of its motion. The units also tell the kind of axis
(:mod:`greybox.data.quantities`): mm, m, um, N are a linear axis (canonical s,
mm, mm/s, mm/s^2, A or N); deg, rad, rev, rpm, Nm a rotary one (canonical s,
deg, deg/s, deg/s^2, A or Nm). The position's unit decides: beside a linear position a rotary velocity
or acceleration is the motor's (an extra channel), and a torque the motor torque (the effort of a log
without a current, :data:`MOTOR_TORQUE`); a rotary position with a linear velocity or a force is an error.
Export headers in words (``Lageistwert [mm]``) are renamed first (:mod:`greybox.data.headers`). A column whose
quantity is known but whose suffix looks like an unsupported unit
(``position_inch``) is an error rather than a silently ignored channel; a
suffix made of other words (``position_setpoint_mm``) makes the column an
ordinary extra.
"""

from __future__ import annotations

import functools
import math
import warnings
from typing import Mapping

import numpy as np

from ..errors import LogError, Setting
from .headers import canonical_table, datetime_seconds
from .log import AxisLog
from .quantities import LINEAR, ROTARY

__all__ = [
    "UNIT_FACTORS",
    "ROTARY_UNITS",
    "CANONICAL_NAMES",
    "EFFORT_QUANTITIES",
    "parse_column_name",
    "known_column",
    "resolve_columns",
    "resolve_table",
    "axes_in_columns",
    "select_axis",
    "several_axes_table",
    "unwrap_modulo",
    "log_from_columns",
    "MOTOR_TORQUE",
]

#: ``AxisLog.attrs`` key of a linear axis's log whose effort is the motor torque [Nm] read as a current with
#: ``k_t = 1 Nm/A``; its value names the column. The force then follows from the axis file without its ``k_t``.
MOTOR_TORQUE = "motor_torque_column"

_DEG_PER_RAD = 180.0 / math.pi

#: Conversion factors to the canonical unit of the motion, per quantity and unit suffix.
#: The first suffix of each quantity is the linear axis's canonical one.
UNIT_FACTORS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9},
    "position": {"mm": 1.0, "m": 1e3, "um": 1e-3, "µm": 1e-3, "deg": 1.0, "rad": _DEG_PER_RAD, "rev": 360.0},
    "velocity": {"mm_s": 1.0, "m_s": 1e3, "mm_min": 1.0 / 60.0, "m_min": 1e3 / 60.0,
                 "deg_s": 1.0, "rad_s": _DEG_PER_RAD, "rpm": 6.0, "deg_min": 1.0 / 60.0, "rev_s": 360.0},
    "acceleration": {"mm_s2": 1.0, "m_s2": 1e3, "deg_s2": 1.0, "rad_s2": _DEG_PER_RAD},
    "current": {"A": 1.0, "mA": 1e-3},
    "force": {"N": 1.0, "kN": 1e3},
    "torque": {"Nm": 1.0, "mNm": 1e-3, "kNm": 1e3},
}

#: Units (per quantity) that make a log a rotary axis's; the other position, velocity,
#: acceleration and force units are a linear axis's, time and current units fit both.
ROTARY_UNITS = {"position": {"deg", "rad", "rev"}, "velocity": {"deg_s", "rad_s", "rpm", "deg_min", "rev_s"},
                "acceleration": {"deg_s2", "rad_s2"}, "torque": set(UNIT_FACTORS["torque"])}

#: Canonical column name of each quantity (a linear axis's; torque for a rotary axis's load).
CANONICAL_NAMES = {quantity: f"{quantity}_{next(iter(units))}" for quantity, units in UNIT_FACTORS.items()}

#: Quantities that can be the drive effort of a log: the motor current or the load.
EFFORT_QUANTITIES = ("current", "force", "torque")

_EFFORT_UNIT = {"current": "A", "force": LINEAR.load_unit, "torque": ROTARY.load_unit}
_MOTION_QUANTITIES = ("position", "velocity", "acceleration", "force", "torque")

# Words that make up unit suffixes, supported or not. A multi-word suffix made
# only of these is taken as a unit (and rejected when unsupported); any other
# word makes the column an extra channel (``position_setpoint_mm``).
_UNIT_WORDS = frozenset(
    "m mm um µm cm dm km nm in inch inches ft mil s ms us ns sec min h hr s2 sec2 "
    "A mA kA uA N kN mN lbf Nm mNm kNm Nmm deg rad rev rpm grad per".split()
)


@functools.lru_cache(maxsize=4096)  # a live stream asks for the same few names in every message
def parse_column_name(name: str) -> tuple[str, str | None] | None:
    """Split a column name into quantity and unit suffix.

    Parameters
    ----------
    name : str
        Column header or message field name.

    Returns
    -------
    tuple of (str, str or None) or None
        ``(quantity, unit)`` when the name is a known quantity followed by a
        unit-like suffix; ``unit`` is ``None`` for a bare quantity name such as
        ``"position"``. ``None`` when the name is not a base channel at all.
        The unit is returned as written, whether supported or not.
    """
    for quantity in UNIT_FACTORS:
        if name == quantity:
            return quantity, None
        prefix = quantity + "_"
        if name.startswith(prefix):
            suffix = name[len(prefix):]
            words = suffix.split("_")
            if len(words) == 1 or all(word in _UNIT_WORDS for word in words):
                return quantity, suffix
            return None
    return None


def known_column(name: str) -> bool:
    """True when ``name`` is a quantity with a supported unit, e.g. ``"position_deg"`` (a valid mapping key).

    Parameters
    ----------
    name : str
        Column name, ``<quantity>_<unit>``.
    """
    parsed = parse_column_name(name)
    return parsed is not None and parsed[1] in UNIT_FACTORS[parsed[0]]


#: The message of a log without time stamps or a sample time.
NO_TIME_COLUMN = ("no time column (time_s or time_ms, or map one with ", Setting("columns", {"time_s": ...}),
                  "); for logs without time stamps give the sample time (", Setting("sample_time"), ")")


def _unit_factor(quantity: str, unit: str | None, column: str, source) -> float:
    units = UNIT_FACTORS[quantity]
    if unit is None:
        raise LogError(
            source,
            f"column '{column}' has no unit suffix; name it e.g. '{CANONICAL_NAMES[quantity]}' or map it with ",
            Setting("columns", {CANONICAL_NAMES[quantity]: column}),
        )
    if unit not in units:
        known = ", ".join(f"{quantity}_{u}" for u in units)
        raise LogError(
            source,
            f"unknown unit '{unit}' in column '{column}'; known: {known} (if '{column}' is not the {quantity}, "
            f"name the {quantity} column with ", Setting("columns", {CANONICAL_NAMES[quantity]: ...}), ")",
        )
    return units[unit]


def _motion(units: Mapping[str, tuple[str, str]], source) -> str:
    """The motion ("linear" or "rotary") the units of the found channels agree on; error if they disagree."""
    kinds = {quantity: ("rotary" if unit in ROTARY_UNITS.get(quantity, ()) else "linear", column)
             for quantity, (column, unit) in units.items() if quantity in _MOTION_QUANTITIES}
    if len({kind for kind, _ in kinds.values()}) > 1:
        listed = ", ".join(f"'{column}' ({kind})" for kind, column in kinds.values())
        raise LogError(source, f"the columns mix a linear and a rotary axis: {listed}; a linear axis logs mm, mm/s "
                               "and N, a rotary one deg (or rad, rev), deg/s (or rad/s, rpm) and Nm: give every "
                               "column its unit with ", Setting("columns"))
    return next(iter(kinds.values()))[0] if kinds else "linear"


def _motor_channels(found: dict, units: dict) -> None:
    """On a linear axis (a position in a length unit), read the motor's own channels as a servo trace logs them.

    A motor speed (``velocity_rpm``) or a rotary acceleration is not the table's: it stays an extra channel
    and the table's velocity is derived from the position. A motor torque (``torque_Nm``) is the effort of a
    log without a current, read as a current through ``k_t = 1 Nm/A`` (:data:`MOTOR_TORQUE`), and an extra
    beside a current.
    """
    if "position" not in units or units["position"][1] in ROTARY_UNITS["position"]:
        return
    for quantity in ("velocity", "acceleration"):
        if quantity in units and units[quantity][1] in ROTARY_UNITS[quantity]:
            del found[quantity], units[quantity]
    if "torque" in found:
        torque = found.pop("torque")
        del units["torque"]
        if "current" not in found and "force" not in found:
            found["current"] = torque


def resolve_columns(
    names,
    *,
    source,
    columns: Mapping[str, str] | None = None,
    with_time: bool = True,
    effort_unit: str | None = None,
) -> tuple[dict[str, tuple[str, float]], str]:
    """Find the base channels among named columns, and the kind of axis their units tell.

    Parameters
    ----------
    names : iterable of str
        Column names present in the file.
    source : str or path-like
        File name, used in error messages.
    columns : mapping of str to str, optional
        Explicit ``{canonical_name: name_in_file}`` pairs, e.g.
        ``{"position_mm": "X1_ActualPosition"}``. The key may carry any supported
        unit suffix (``{"position_um": "Pos"}`` reads ``Pos`` as micrometres,
        ``{"position_rad": "C_angle"}`` as radians of a rotary axis).
    with_time : bool, default True
        Look for a time column; ``False`` when the format carries time itself (MCAP).
    effort_unit : {"A", "N", "Nm"}, optional
        Effort unit recorded in the file's metadata; it decides between a
        current and a load column when both are present.

    Returns
    -------
    found : dict
        ``{quantity: (column_name, factor_to_canonical_unit)}`` for the
        quantities found, among ``time``, ``position``, ``velocity``,
        ``acceleration`` and one of ``current`` / ``force`` / ``torque``.
    motion : {"linear", "rotary"}
        The kind of axis the units tell (linear when no unit tells).

    Raises
    ------
    LogError
        For a mapped column that is missing, an unknown quantity or unit,
        an ambiguous or missing required channel, units of a linear and a rotary axis together.
    """
    names = list(names)
    present = set(names)
    found: dict[str, tuple[str, float]] = {}
    units: dict[str, tuple[str, str]] = {}
    for key, column in dict(columns or {}).items():
        parsed = parse_column_name(key)
        if parsed is None or parsed[1] is None:
            known = ", ".join(CANONICAL_NAMES.values())
            raise LogError(source, f"columns: '{key}' is not a quantity with a unit; use one of {known}")
        quantity, unit = parsed
        if quantity == "time" and not with_time:
            raise LogError(source, "columns: this format carries its own time stamps; do not map 'time'")
        if quantity in found:
            raise LogError(source, f"columns: quantity '{quantity}' is mapped twice")
        if column not in present:
            raise LogError(source, f"column '{column}' (mapped to {key}) not found; "
                                   f"columns in the file: {_listing(names)}")
        found[quantity] = (column, _unit_factor(quantity, unit, key, source))
        units[quantity] = (column, unit)

    candidates: dict[str, list[tuple[str, str | None]]] = {}
    for name in names:
        parsed = parse_column_name(name)
        if parsed is None or parsed[0] in found or (parsed[0] == "time" and not with_time):
            continue
        candidates.setdefault(parsed[0], []).append((name, parsed[1]))

    for quantity, hits in candidates.items():
        if len(hits) > 1:
            listed = ", ".join(f"'{name}'" for name, _ in hits)
            raise LogError(
                source,
                f"several {quantity} columns ({listed}); "
                f"choose one with columns={{'{CANONICAL_NAMES[quantity]}': ...}}",
            )
        name, unit = hits[0]
        found[quantity] = (name, _unit_factor(quantity, unit, name, source))
        units[quantity] = (name, unit)

    _motor_channels(found, units)
    efforts = [quantity for quantity in EFFORT_QUANTITIES if quantity in found]
    if len(efforts) > 1:
        mapped = [quantity for quantity in efforts
                  if quantity in {parse_column_name(key)[0] for key in dict(columns or {})}]
        by_unit = [quantity for quantity in efforts if _EFFORT_UNIT[quantity] == effort_unit]
        if len(mapped) > 1:
            raise LogError(source, "columns: map one effort column (current, force or torque), not several")
        chosen = (mapped or by_unit or [None])[0]
        if chosen is None:
            listed = [f"a {quantity} column ('{found[quantity][0]}')" for quantity in efforts]
            listed = ", ".join(listed[:-1]) + " and " + listed[-1]
            raise LogError(source, f"both {listed}; choose the effort with ", Setting("columns", {"current_A": ...}),
                           " or ", Setting("columns", {CANONICAL_NAMES[efforts[-1]]: ...}))
        for quantity in efforts:
            if quantity != chosen:
                del found[quantity], units[quantity]
    axes = axes_in_columns(names)
    if "position" not in found and axes:
        raise LogError(source, f"the file holds several axes ({', '.join(axes)}); choose one with ",
                       Setting("axis", axes[0]))
    if "position" not in found:
        raise LogError(
            source,
            "missing required column 'position_mm' (axis position; or position_m/position_um, position_deg/"
            "position_rad for a rotary axis, or map one with ", Setting("columns"),
            f"); columns in the file: {_listing(names)}",
        )
    if not any(quantity in found for quantity in EFFORT_QUANTITIES):
        raise LogError(
            source,
            "missing required column 'current_A' (motor current; or force_N / torque_Nm for logs of the load, "
            "or map one with ", Setting("columns"), f"); columns in the file: {_listing(names)}",
        )
    return found, _motion(units, source)


def _axis_prefix(name: str) -> tuple[str, str] | None:
    """``("X", "position_mm")`` for a column ``X_position_mm``: an axis name, then a base channel with its unit."""
    head, _, rest = str(name).partition("_")
    if not head or not rest or not head[0].isalpha() or not head.isalnum():
        return None
    parsed = parse_column_name(rest)
    return (head, rest) if parsed is not None and parsed[1] is not None and parsed[0] != "time" else None


def axes_in_columns(names) -> list[str]:
    """The axes of a several-axis table: prefixes of base channels named ``<axis>_<quantity>_<unit>``.

    Parameters
    ----------
    names : iterable of str
        Column names, e.g. ``time_s, X_position_mm, X_current_A, Y_position_mm, Y_current_A``.

    Returns
    -------
    list of str
        The axis names in the order of their first column (``["X", "Y"]``); empty for a one-axis table.
    """
    found = [prefixed[0] for prefixed in map(_axis_prefix, names)
             if prefixed is not None and prefixed[1].startswith("position_")]  # an axis has a position
    return list(dict.fromkeys(found))


def select_axis(table: Mapping[str, np.ndarray], axis: str, *, source,
                columns: Mapping[str, str] | None = None) -> dict[str, np.ndarray]:
    """The columns of one axis of a several-axis table, under their names without the axis prefix.

    A column ``<axis>_<rest>`` becomes ``<rest>`` (``X_position_mm`` -> ``position_mm``, and
    ``X_truth_friction_A`` -> ``truth_friction_A``); columns of the other axes are left out;
    columns without an axis prefix (``time_s``) are shared by all axes and kept, as are columns
    ``columns=`` maps by their name in the file.

    Parameters
    ----------
    table : mapping of str to array_like
        Columns of the file.
    axis : str
        Axis to take, e.g. ``"X"``.
    source : str or path-like
        File name for error messages.
    columns : mapping of str to str, optional
        Explicit mapping (its values are names in the file, kept as they are).

    Returns
    -------
    dict of str to array_like

    Raises
    ------
    LogError
        When no column carries the axis prefix and ``columns`` maps nothing either; the message
        lists the axes the file holds.
    """
    axes = axes_in_columns(table)
    mapped = set((columns or {}).values())
    if axis not in axes and not mapped:
        held = f"the axes in the file: {', '.join(axes)}" if axes else \
            "the file holds one axis (no column named <axis>_position_<unit>, e.g. X_position_mm)"
        raise LogError(source, f"no columns of axis '{axis}' (named {axis}_position_mm, {axis}_current_A, ...); "
                               f"{held}")
    selected: dict[str, np.ndarray] = {}
    for name, values in table.items():
        head, _, rest = str(name).partition("_")
        if name in mapped:
            selected[name] = values
        elif head == axis and rest:
            selected[rest] = values
        elif head not in axes or not rest:
            selected[name] = values
    return selected


def unwrap_modulo(angle_deg: np.ndarray, source) -> np.ndarray:
    """The angle of a rotary axis logged modulo a turn (0..360 deg, as a SINUMERIK modulo axis), unwrapped.

    A step of more than half a turn between two samples is a wrap of the display, not motion (it
    would be 90 000 deg/s at 2 ms); it is undone, with one warning naming the file and the count.

    Parameters
    ----------
    angle_deg : ndarray
        Logged angle [deg].
    source : str or path-like
        File, for the warning.

    Returns
    -------
    ndarray
        The continuous angle [deg]; the input itself when it does not wrap.
    """
    steps = np.diff(angle_deg)
    wraps = int(np.count_nonzero(np.abs(steps[np.isfinite(steps)]) > 180.0))
    if not wraps:
        return angle_deg
    warnings.warn(f"{source}: the rotary position wraps around a turn {wraps} time(s) (a modulo axis); "
                  "unwrapped so that the angle runs on", stacklevel=3)
    finite = np.isfinite(angle_deg)
    out = angle_deg.copy()
    out[finite] = np.unwrap(angle_deg[finite], period=360.0)
    return out


def several_axes_table(logs, *, source) -> dict[str, np.ndarray]:
    """The columns of one table holding one log, or several axes on the same time stamps.

    Parameters
    ----------
    logs : sequence of AxisLog
        One log (its canonical columns, :meth:`AxisLog.named_channels`), or several logs of
        different axes with equal time stamps: ``time_s`` once, then each log's columns prefixed
        with its axis name (``X_position_mm``, ``X_current_A``, ``X_truth_friction_A``, ...), which
        :func:`select_axis` reads back.
    source : str or path-like
        File to be written, for error messages.

    Returns
    -------
    dict of str to ndarray

    Raises
    ------
    LogError
        For several logs with an axis name that is not letters and digits, a repeated name, or
        time stamps that differ (write them to MCAP, a channel per axis, instead).
    """
    logs = list(logs)
    if len(logs) == 1:
        return dict(logs[0].named_channels(time=True))
    names = [log.axis for log in logs]
    bad = [name for name in names if not (name[:1].isalpha() and name.isalnum())]
    if bad:
        raise LogError(source, f"axis name {bad[0]!r} cannot prefix columns; several axes in one table need names "
                               "of letters and digits (X, Y, C, A1)")
    if len(set(names)) != len(names):
        raise LogError(source, f"several logs of axis {names[0]}; one table holds each axis once")
    time = logs[0].time
    for log in logs[1:]:
        if log.time.shape != time.shape or not np.array_equal(log.time, time):
            raise LogError(source, f"axes {logs[0].axis} and {log.axis} have different time stamps; one table holds "
                                   "axes sampled together (write them to .mcap, a channel per axis)")
    table = {"time_s": time}
    for log in logs:
        table.update({f"{log.axis}_{name}": values for name, values in log.named_channels()})
    return table


def _listing(names, limit: int = 12) -> str:
    shown = ", ".join(f"'{n}'" for n in names[:limit])
    return shown + (f", ... ({len(names)} in all)" if len(names) > limit else "") if names else "(none)"


def _numeric(values) -> np.ndarray | None:
    array = np.asarray(values)
    if array.dtype.kind in "fiub":
        return array.astype(np.float64, copy=False)
    return None


def resolve_table(table: Mapping[str, object], *, source, columns: Mapping[str, str] | None = None,
                  with_time: bool = True, effort_unit: str | None = None, select: str | None = None):
    """The columns of a table under greybox's names, and the base channels among them.

    The work on the names alone that :func:`log_from_columns` does before it reads any value: the axis
    ``select`` taken (:func:`select_axis`), export headers renamed (:func:`~greybox.data.headers.canonical_table`),
    unnamed columns left out, the channels found (:func:`resolve_columns`). A live stream does it once for
    the column names its messages share.

    Parameters
    ----------
    table : mapping of str to object
        Columns under their names in the file (the values are passed through untouched).
    source : str or path-like
        File name for error messages.
    columns : mapping of str to str, optional
        Explicit ``{canonical_name: name_in_file}``; see :func:`resolve_columns`.
    with_time : bool, default True
        Look for a time column.
    effort_unit : {"A", "N", "Nm"}, optional
        Effort unit from the file's metadata.
    select : str, optional
        Axis to take from a several-axis table.

    Returns
    -------
    table : dict of str to object
        The columns under their new names, values as given.
    names : list of str
        The named columns, in order.
    found : dict
        ``{quantity: (column_name, factor_to_canonical_unit)}`` (:func:`resolve_columns`).
    motion : {"linear", "rotary"}
        The kind of axis.

    Raises
    ------
    LogError
        As :func:`select_axis`, :func:`~greybox.data.headers.canonical_table` and :func:`resolve_columns`.
    """
    if select is not None:
        table = select_axis(table, select, source=source, columns=columns)
    mapped = {parsed[0] for parsed in map(parse_column_name, columns or {}) if parsed is not None}
    table = canonical_table(table, source=source, keep=(columns or {}).values(), mapped=mapped)
    names = [n for n in table if n and not str(n).startswith("Unnamed: ")]
    found, motion = resolve_columns(names, source=source, columns=columns, with_time=with_time,
                                    effort_unit=effort_unit)
    return table, names, found, motion


def log_from_columns(
    table: Mapping[str, np.ndarray],
    *,
    source,
    columns: Mapping[str, str] | None = None,
    time=None,
    sample_time: float | None = None,
    effort_unit: str | None = None,
    axis: str = "",
    dataset: str = "",
    attrs: Mapping[str, object] | None = None,
    select: str | None = None,
) -> AxisLog:
    """Build an :class:`AxisLog` from named columns in their file units.

    Parameters
    ----------
    table : mapping of str to array_like
        Columns of equal length, in file order. Non-numeric columns are
        ignored unless they are needed as a base channel (then: error).
        Columns with an empty name or pandas' ``"Unnamed: k"`` (an unnamed
        row-index column) are dropped.
    source : str or path-like
        File name for the log and for error messages.
    columns : mapping of str to str, optional
        Explicit ``{canonical_name: name_in_file}``; see :func:`resolve_columns`.
    time : array_like, optional
        Sample times [s] when the format carries them outside the columns
        (MCAP ``log_time``); then no time column is looked for.
    sample_time : float, optional
        Sample time [s] for files without any time column: the time is then
        ``row_index * sample_time``, starting at 0 s.
    effort_unit : {"A", "N", "Nm"}, optional
        Effort unit from the file's metadata (decides between current and load).
    axis, dataset : str
        Names stored in the log.
    attrs : mapping, optional
        Free-form metadata stored in the log.
    select : str, optional
        Take one axis of a several-axis table, its columns named ``<select>_<quantity>_<unit>``
        (:func:`select_axis`); the log's axis name is then ``select``.

    Returns
    -------
    AxisLog
        Base channels in canonical units (s, mm, mm/s, mm/s^2, A or N; for a rotary
        axis s, deg, deg/s, deg/s^2, A or Nm); every other numeric column, name
        unchanged, in ``extras``.
    """
    table, names, found, motion = resolve_table(table, source=source, columns=columns, with_time=time is None,
                                                effort_unit=effort_unit, select=select)
    axis = select if select is not None else axis
    used = {column for column, _ in found.values()}

    def channel(quantity):
        if quantity not in found:
            return None
        column, factor = found[quantity]
        values = _numeric(table[column])
        if values is None and quantity == "time":
            values, factor = datetime_seconds(table[column], source=source, column=column), 1.0
        if values is None:
            raise LogError(source, f"column '{column}' ({quantity}) is not numeric{_first_text(table[column])}")
        return values * factor if factor != 1.0 else values

    if time is not None:
        if sample_time is not None:
            raise LogError(source, "this format carries its own time stamps; ", Setting("sample_time", assign=False),
                           " applies only to files without a time column")
        time_s = np.asarray(time, dtype=np.float64)
    elif "time" in found:
        if sample_time is not None:
            raise LogError(
                source,
                f"the file has a time column ('{found['time'][0]}'); ", Setting("sample_time", assign=False),
                " applies only to files without one",
            )
        time_s = channel("time")
    elif sample_time is not None:
        if not np.isfinite(sample_time) or sample_time <= 0:
            raise LogError(source, Setting("sample_time", assign=False),
                           f" must be a positive number of seconds, got {sample_time!r}")
        n = len(np.asarray(table[found["position"][0]]))
        time_s = np.arange(n, dtype=np.float64) * float(sample_time)
    else:
        raise LogError(
            source,
            *NO_TIME_COLUMN,
        )

    effort = next(quantity for quantity in EFFORT_QUANTITIES if quantity in found)
    attrs = dict(attrs or {})
    if parse_column_name(found[effort][0]) is not None and parse_column_name(found[effort][0])[0] == "torque" \
            and effort == "current":
        attrs[MOTOR_TORQUE] = found[effort][0]
    position = channel("position")
    if motion == "rotary":
        position = unwrap_modulo(position, source)
    extras = {}
    for name in names:
        if name in used:
            continue
        values = _numeric(table[name])
        if values is not None:
            extras[str(name)] = values
    return AxisLog(
        time=time_s,
        position=position,
        effort=channel(effort),
        velocity=channel("velocity"),
        acceleration=channel("acceleration"),
        effort_unit=_EFFORT_UNIT[effort],
        motion=motion,
        axis=axis,
        dataset=dataset,
        source=str(source),
        extras=extras,
        attrs=attrs,
    )


def _first_text(values) -> str:
    for row, value in enumerate(np.asarray(values, dtype=object)):
        try:
            float(value)
        except (TypeError, ValueError):
            return f": row {row} holds {value!r}"
    return ""
