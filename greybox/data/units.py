"""Units of logged quantities and the mapping of named columns to an :class:`AxisLog`.

Every reader (CSV, Parquet, MCAP) ends in :func:`log_from_columns`: the file
gives named numeric columns, this module finds the base channels among them by
their name and unit suffix, converts them to the canonical units (s, mm, mm/s,
mm/s^2, A or N) and keeps every other numeric column as an extra channel.

A column name is ``<quantity>_<unit>``, e.g. ``position_um`` or
``velocity_mm_min``. The quantities and the unit suffixes understood are listed
in :data:`UNIT_FACTORS`; the factor converts a value in that unit to the
canonical unit (the first entry of each quantity). A column whose quantity is
known but whose suffix looks like an unsupported unit (``position_inch``) is an
error rather than a silently ignored channel; a suffix made of other words
(``position_setpoint_mm``) makes the column an ordinary extra.
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from ..errors import LogError
from .log import AxisLog

__all__ = [
    "UNIT_FACTORS",
    "CANONICAL_NAMES",
    "parse_column_name",
    "resolve_columns",
    "log_from_columns",
]

#: Conversion factors to the canonical unit, per quantity and unit suffix.
#: The first suffix of each quantity is the canonical one.
UNIT_FACTORS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9},
    "position": {"mm": 1.0, "m": 1e3, "um": 1e-3, "µm": 1e-3},
    "velocity": {"mm_s": 1.0, "m_s": 1e3, "mm_min": 1.0 / 60.0, "m_min": 1e3 / 60.0},
    "acceleration": {"mm_s2": 1.0, "m_s2": 1e3},
    "current": {"A": 1.0, "mA": 1e-3},
    "force": {"N": 1.0, "kN": 1e3},
}

#: Canonical column name of each quantity, e.g. ``"velocity" -> "velocity_mm_s"``.
CANONICAL_NAMES = {quantity: f"{quantity}_{next(iter(units))}" for quantity, units in UNIT_FACTORS.items()}

# Words that make up unit suffixes, supported or not. A multi-word suffix made
# only of these is taken as a unit (and rejected when unsupported); any other
# word makes the column an extra channel (``position_setpoint_mm``).
_UNIT_WORDS = frozenset(
    "m mm um µm cm dm km nm in inch inches ft mil s ms us ns sec min h hr s2 sec2 "
    "A mA kA uA N kN mN lbf deg rad rev rpm per".split()
)


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


def _unit_factor(quantity: str, unit: str | None, column: str, source) -> float:
    units = UNIT_FACTORS[quantity]
    if unit is None:
        raise LogError(
            source,
            f"column '{column}' has no unit suffix; name it e.g. '{CANONICAL_NAMES[quantity]}' "
            f"or map it with columns={{'{CANONICAL_NAMES[quantity]}': '{column}'}}",
        )
    if unit not in units:
        known = ", ".join(f"{quantity}_{u}" for u in units)
        raise LogError(
            source,
            f"unknown unit '{unit}' in column '{column}'; known: {known} (if '{column}' is not the {quantity}, "
            f"name the {quantity} column with columns={{'{CANONICAL_NAMES[quantity]}': ...}})",
        )
    return units[unit]


def resolve_columns(
    names,
    *,
    source,
    columns: Mapping[str, str] | None = None,
    with_time: bool = True,
    effort_unit: str | None = None,
) -> dict[str, tuple[str, float]]:
    """Find the base channels among named columns.

    Parameters
    ----------
    names : iterable of str
        Column names present in the file.
    source : str or path-like
        File name, used in error messages.
    columns : mapping of str to str, optional
        Explicit ``{canonical_name: name_in_file}`` pairs, e.g.
        ``{"position_mm": "X1_ActualPosition"}``. The key may carry any supported
        unit suffix (``{"position_um": "Pos"}`` reads ``Pos`` as micrometres).
    with_time : bool, default True
        Look for a time column; ``False`` when the format carries time itself (MCAP).
    effort_unit : {"A", "N"}, optional
        Effort unit recorded in the file's metadata; it decides between a
        current and a force column when both are present.

    Returns
    -------
    dict
        ``{quantity: (column_name, factor_to_canonical_unit)}`` for the
        quantities found, among ``time``, ``position``, ``velocity``,
        ``acceleration`` and one of ``current`` / ``force``.

    Raises
    ------
    LogError
        For a mapped column that is missing, an unknown quantity or unit,
        an ambiguous or missing required channel.
    """
    names = list(names)
    present = set(names)
    found: dict[str, tuple[str, float]] = {}
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

    if "current" in found and "force" in found:
        mapped = {parse_column_name(key)[0] for key in dict(columns or {})} & {"current", "force"}
        if len(mapped) == 2:
            raise LogError(source, "columns: map either a current or a force column as the effort, not both")
        if mapped:
            chosen = mapped.pop()
        elif effort_unit in ("A", "N"):
            chosen = "current" if effort_unit == "A" else "force"
        else:
            raise LogError(
                source,
                f"both a current column ('{found['current'][0]}') and a force column ('{found['force'][0]}'); "
                "choose the effort with columns={'current_A': ...} or columns={'force_N': ...}",
            )
        del found["force" if chosen == "current" else "current"]
    if "position" not in found:
        raise LogError(
            source,
            f"missing required column 'position_mm' (axis position; or position_m/position_um, "
            f"or map one with columns=); columns in the file: {_listing(names)}",
        )
    if "current" not in found and "force" not in found:
        raise LogError(
            source,
            f"missing required column 'current_A' (motor current; or force_N for force logs, "
            f"or map one with columns=); columns in the file: {_listing(names)}",
        )
    return found


def _listing(names, limit: int = 12) -> str:
    shown = ", ".join(f"'{n}'" for n in names[:limit])
    return shown + (f", ... ({len(names)} in all)" if len(names) > limit else "") if names else "(none)"


def _numeric(values) -> np.ndarray | None:
    array = np.asarray(values)
    if array.dtype.kind in "fiub":
        return array.astype(np.float64, copy=False)
    return None


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
    effort_unit : {"A", "N"}, optional
        Effort unit from the file's metadata (decides between current and force).
    axis, dataset : str
        Names stored in the log.
    attrs : mapping, optional
        Free-form metadata stored in the log.

    Returns
    -------
    AxisLog
        Base channels in canonical units (s, mm, mm/s, mm/s^2, A or N); every
        other numeric column, name unchanged, in ``extras``.
    """
    names = [n for n in table if n and not str(n).startswith("Unnamed: ")]
    found = resolve_columns(
        names, source=source, columns=columns, with_time=time is None, effort_unit=effort_unit
    )
    used = {column for column, _ in found.values()}

    def channel(quantity):
        if quantity not in found:
            return None
        column, factor = found[quantity]
        values = _numeric(table[column])
        if values is None:
            raise LogError(source, f"column '{column}' ({quantity}) is not numeric{_first_text(table[column])}")
        return values * factor if factor != 1.0 else values

    if time is not None:
        if sample_time is not None:
            raise LogError(source, "this format carries its own time stamps; "
                                   "sample_time applies only to files without a time column")
        time_s = np.asarray(time, dtype=np.float64)
    elif "time" in found:
        if sample_time is not None:
            raise LogError(
                source,
                f"the file has a time column ('{found['time'][0]}'); sample_time applies only to files without one",
            )
        time_s = channel("time")
    elif sample_time is not None:
        if not np.isfinite(sample_time) or sample_time <= 0:
            raise LogError(source, f"sample_time must be a positive number of seconds, got {sample_time!r}")
        n = len(np.asarray(table[found["position"][0]]))
        time_s = np.arange(n, dtype=np.float64) * float(sample_time)
    else:
        raise LogError(
            source,
            "no time column (time_s or time_ms, or map one with columns={'time_s': ...}); "
            "for logs without time stamps give the sample time (sample_time=, --sample-time)",
        )

    unit = "A" if "current" in found else "N"
    extras = {}
    for name in names:
        if name in used:
            continue
        values = _numeric(table[name])
        if values is not None:
            extras[str(name)] = values
    return AxisLog(
        time=time_s,
        position=channel("position"),
        effort=channel("current" if unit == "A" else "force"),
        velocity=channel("velocity"),
        acceleration=channel("acceleration"),
        effort_unit=unit,
        axis=axis,
        dataset=dataset,
        source=str(source),
        extras=extras,
        attrs=dict(attrs or {}),
    )


def _first_text(values) -> str:
    for row, value in enumerate(np.asarray(values, dtype=object)):
        try:
            float(value)
        except (TypeError, ValueError):
            return f": row {row} holds {value!r}"
    return ""
