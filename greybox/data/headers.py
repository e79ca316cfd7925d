"""Headers as controller exports write them: ``position [mm]``, ``Lageistwert [mm]``, ``Zeit (ms)``.

A CNC or drive export names its columns in words with the unit in brackets,
often in the language of the controller. :func:`canonical_header` turns such a
header into greybox's ``<quantity>_<unit>`` name when both its words and its
unit are in a small vocabulary (:data:`QUANTITY_WORDS`, :data:`UNIT_SPELLINGS`,
listed in docs/log-formats.md); any other header is left as it is (an extra
channel, or mapped with ``columns=``). :func:`canonical_table` renames the
columns of a whole table that way, and :func:`datetime_seconds` reads ISO date-time
stamps as seconds from the first one.

This module imports nothing of greybox but the errors.
"""

from __future__ import annotations

import functools
import re
from typing import Mapping

import numpy as np

from ..errors import LogError, Setting

__all__ = ["QUANTITY_WORDS", "UNIT_SPELLINGS", "TIMESTAMP_WORDS", "canonical_header", "canonical_table",
           "datetime_seconds", "split_unit"]

#: Words (lower case, without blanks, ``_``, ``-`` and ``.``) that name a quantity, English and German.
QUANTITY_WORDS: dict[str, tuple[str, ...]] = {
    "time": ("time", "t", "zeit"),
    "position": ("position", "pos", "actualposition", "positionactual", "actpos", "lageistwert", "istposition",
                 "istlage", "lage", "achsposition", "axisposition"),
    "velocity": ("velocity", "speed", "actualvelocity", "actualspeed", "feedrate", "geschwindigkeit",
                 "geschwindigkeitsistwert", "istgeschwindigkeit", "vorschub", "motorspeed", "motorvelocity",
                 "drehzahl", "drehzahlistwert", "motordrehzahl", "istdrehzahl"),
    "acceleration": ("acceleration", "beschleunigung"),
    "current": ("current", "motorcurrent", "actualcurrent", "iq", "torquecurrent", "strom", "stromistwert",
                "motorstrom", "iststrom", "momentenbildenderstrom", "querstrom"),
    "force": ("force", "kraft", "driveforce", "antriebskraft"),
    "torque": ("torque", "motortorque", "actualtorque", "drehmoment", "moment", "motormoment",
               "drehmomentistwert", "istmoment"),
}

#: Unit spellings of exports -> greybox's unit suffix. Case matters where it tells units apart
#: (``Nm`` newton metre, ``nm`` nanometre is not accepted).
UNIT_SPELLINGS: dict[str, str] = {
    "s": "s", "sec": "s", "ms": "ms", "us": "us", "µs": "us", "ns": "ns",
    "mm": "mm", "m": "m", "um": "um", "µm": "um",
    "mm/s": "mm_s", "m/s": "m_s", "mm/min": "mm_min", "m/min": "m_min",
    "mm/s^2": "mm_s2", "mm/s²": "mm_s2", "mm/s2": "mm_s2", "m/s^2": "m_s2", "m/s²": "m_s2", "m/s2": "m_s2",
    "A": "A", "a": "A", "mA": "mA",
    "N": "N", "kN": "kN", "Nm": "Nm", "N m": "Nm", "N·m": "Nm", "mNm": "mNm", "kNm": "kNm",
    "deg": "deg", "°": "deg", "grad": "deg", "rad": "rad", "rev": "rev",
    "deg/s": "deg_s", "°/s": "deg_s", "rad/s": "rad_s", "deg/min": "deg_min", "°/min": "deg_min",
    "rpm": "rpm", "1/min": "rpm", "U/min": "rpm", "min^-1": "rpm", "min-1": "rpm", "min⁻¹": "rpm",
    "deg/s^2": "deg_s2", "deg/s²": "deg_s2", "°/s²": "deg_s2", "rad/s^2": "rad_s2", "rad/s²": "rad_s2",
}

#: Headers (normalised like :data:`QUANTITY_WORDS`) of a column of date-time stamps.
TIMESTAMP_WORDS = ("timestamp", "zeitstempel", "datetime", "datumzeit", "datum/zeit", "date/time", "datetime(utc)")

#: ``words [unit]``, ``words (unit)`` or ``words in unit``.
_BRACKETED = re.compile(r"^(?P<words>.*?)\s*(?:\[(?P<square>[^\]]*)\]|\((?P<round>[^)]*)\)|\s+in\s+(?P<in>\S+))$")


def _normalised(words: str) -> str:
    return re.sub(r"[\s_\-.]+", "", words).lower()


def split_unit(header: str) -> tuple[str, str | None]:
    """A header's words and its bracketed unit: ``"position [mm]"`` -> ``("position", "mm")``.

    Parameters
    ----------
    header : str
        Column header as written in the file.

    Returns
    -------
    tuple of (str, str or None)
        The words before the unit (stripped) and the unit as written, or ``(header, None)`` when the
        header holds no unit in ``[...]``, ``(...)`` or after ``in``.
    """
    match = _BRACKETED.match(header.strip())
    if match is None or not match.group("words"):
        return header.strip(), None
    unit = next(group for group in (match.group("square"), match.group("round"), match.group("in"))
                if group is not None)
    return match.group("words").strip(), unit.strip()


@functools.lru_cache(maxsize=4096)  # a live stream asks for the same few headers in every message
def canonical_header(header: str) -> str | None:
    """greybox's column name for an export's header, or None when its words or unit are not in the vocabulary.

    Parameters
    ----------
    header : str
        Column header, e.g. ``"position [mm]"``, ``"Lageistwert [mm]"``, ``"Drehzahl [1/min]"``,
        ``"Zeitstempel"``.

    Returns
    -------
    str or None
        ``"position_mm"``, ``"position_mm"``, ``"velocity_rpm"``, ``"time_s"`` for the examples
        (a date-time column is named ``time_s``; its stamps are read by :func:`datetime_seconds`).
    """
    words, unit = split_unit(str(header))
    name = _normalised(words)
    if unit is None:
        return "time_s" if name in TIMESTAMP_WORDS else None
    suffix = UNIT_SPELLINGS.get(unit, UNIT_SPELLINGS.get(unit.replace(" ", "")))
    if suffix is None:
        return None
    for quantity, spellings in QUANTITY_WORDS.items():
        if name in spellings:
            return f"{quantity}_{suffix}"
    return None


def canonical_table(table: Mapping[str, object], *, source, keep=(), mapped=()) -> dict[str, object]:
    """A table with its export headers renamed to greybox's names where the vocabulary knows them.

    Parameters
    ----------
    table : mapping of str to array_like
        Columns under their headers, in file order.
    source : str or path-like
        File name for the error message.
    keep : iterable of str, optional
        Headers left as they are (those a ``columns=`` mapping names).
    mapped : iterable of str, optional
        Quantities a ``columns=`` mapping gives (``"position"``): headers of these stay as they are, extras.

    Returns
    -------
    dict
        The same columns in the same order; a header :func:`canonical_header` knows is renamed unless its
        new name is already a header of the table.

    Raises
    ------
    LogError
        When two headers read as the same column (``position [mm]`` and ``Lageistwert [mm]``); the message
        names both.
    """
    keep = set(keep)
    renamed: dict[str, str] = {}
    for header in table:
        if header in keep or header in renamed.values():
            continue
        name = canonical_header(str(header))
        if name is None or name == header or name in table or name.partition("_")[0] in mapped:
            continue
        if name in renamed.values():
            other = next(old for old, new in renamed.items() if new == name)
            raise LogError(source, f"the columns '{other}' and '{header}' both read as {name}; choose one with ",
                           Setting("columns", {name: ...}))
        renamed[header] = name
    return {renamed.get(header, header): values for header, values in table.items()}


def datetime_seconds(values, *, source, column: str) -> np.ndarray | None:
    """Seconds from the first of a column of ISO date-time stamps, or None when the column holds none.

    ``2026-11-27T06:00:00.002``, ``2026-11-27 06:00:00,002`` (a decimal comma) and a trailing time zone are
    read; the stamps must all parse.

    Parameters
    ----------
    values : array_like
        The column's text values.
    source : str or path-like
        File name for the error message.
    column : str
        The column's header, for the error message.

    Returns
    -------
    ndarray or None
        Time [s] from the first stamp, or None when the first value is not a date-time stamp.

    Raises
    ------
    LogError
        When the first value is a stamp but a later one is not; names the row.
    """
    import pandas as pd

    text = pd.Series(np.asarray(values, dtype=object)).astype(str).str.strip()
    if text.empty or not re.match(r"^\d{4}-\d{2}-\d{2}[T ]\d{2}:\d{2}", text.iloc[0]):
        return None
    text = text.str.replace(r"(:\d{2}),(\d+)", r"\1.\2", regex=True)
    stamps = pd.to_datetime(text, errors="coerce", format="ISO8601", utc=True)
    bad = np.flatnonzero(stamps.isna().to_numpy())
    if bad.size:
        raise LogError(source, f"column '{column}' (time) holds {text.iloc[bad[0]]!r} at row {bad[0]}, not an ISO "
                               "date-time stamp like the rows before it")
    return (stamps - stamps.iloc[0]).dt.total_seconds().to_numpy(dtype=np.float64)
