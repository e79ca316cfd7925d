"""Limits on the estimates, with a hold time: an alarm when a column stays beyond its limit that long.

``--limit force_process_N=1500 --limit-hold 20ms`` raises an alarm when ``|force_process_N|`` exceeds
1500 N at every sample of a stretch of at least 20 ms of log time (the first and the last sample of the
stretch that far apart). One alarm per stretch; the limit re-arms when the column comes back within it,
and at the start of each run.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from ..errors import GreyboxError

__all__ = ["Limit", "Alarm", "parse_limit", "parse_duration", "LimitWatch"]

_DURATION = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*(ms|s|us)?\s*$")


@dataclass(frozen=True)
class Limit:
    """A bound on the magnitude of one output column.

    Attributes
    ----------
    column : str
        Output column, e.g. "force_process_N" or "current_process_A".
    bound : float
        Largest allowed magnitude, in the column's unit.
    """

    column: str
    bound: float


@dataclass(frozen=True)
class Alarm:
    """A column beyond its limit for the hold time.

    Attributes
    ----------
    column : str
        The column.
    bound : float
        Its limit (column unit).
    value : float
        Largest magnitude in the stretch so far (column unit).
    since_s : float
        Time of the stretch's first sample [s].
    time_s : float
        Time of the sample that completed the hold [s].
    hold_s : float
        The hold time [s].
    """

    column: str
    bound: float
    value: float
    since_s: float
    time_s: float
    hold_s: float

    def message(self) -> str:
        """The alarm as JSON text (the alarm message of a sink)."""
        return json.dumps({"alarm": "limit", "column": self.column, "limit": self.bound, "value": self.value,
                           "since_s": self.since_s, "time_s": self.time_s, "hold_s": self.hold_s})

    def line(self) -> str:
        """The alarm in one line of text."""
        return (f"ALARM: |{self.column}| above {self.bound:g} since t = {self.since_s:.4f} s "
                f"({1e3 * (self.time_s - self.since_s):.1f} ms, hold {1e3 * self.hold_s:g} ms), "
                f"largest {self.value:.4g}")


def parse_limit(text: str) -> Limit:
    """The limit of ``COLUMN=VALUE``.

    Parameters
    ----------
    text : str
        E.g. "force_process_N=1500".

    Raises
    ------
    GreyboxError
        For text without ``=``, or a value that is not a positive number.
    """
    column, sep, value = text.partition("=")
    try:
        bound = float(value)
    except ValueError:
        bound = math.nan
    if not sep or not column.strip() or not (math.isfinite(bound) and bound > 0):
        raise GreyboxError(f"--limit {text}: give COLUMN=VALUE with a positive VALUE, e.g. force_process_N=1500")
    return Limit(column.strip(), bound)


def parse_duration(text: str) -> float:
    """Seconds of a duration such as "20ms", "0.02s" or "0.02" (seconds).

    Parameters
    ----------
    text : str
        The duration, non-negative, in s, ms or us.

    Raises
    ------
    GreyboxError
        For anything else.
    """
    match = _DURATION.match(text)
    if not match:
        raise GreyboxError(f"--limit-hold {text}: give a non-negative duration such as 20ms or 0.02s")
    scale = {"ms": 1e-3, "us": 1e-6}.get(match.group(2), 1.0)
    return float(match.group(1)) * scale


class LimitWatch:
    """Watches the estimates for columns beyond their limits.

    Parameters
    ----------
    limits : list of Limit
        The limits.
    hold_s : float, default 0.0
        How long [s] a column must stay beyond its limit before the alarm.
    """

    def __init__(self, limits: list[Limit], *, hold_s: float = 0.0):
        self.limits = list(limits)
        self.hold_s = float(hold_s)
        self._since: dict[str, float | None] = {limit.column: None for limit in self.limits}
        self._peak: dict[str, float] = {limit.column: 0.0 for limit in self.limits}
        self._raised: dict[str, bool] = {limit.column: False for limit in self.limits}
        self._checked = False

    def rearm(self) -> None:
        """Forget the stretches in progress (a new run starts)."""
        for column in self._since:
            self._since[column], self._peak[column], self._raised[column] = None, 0.0, False

    def check(self, columns: Mapping[str, np.ndarray]) -> list[Alarm]:
        """The alarms raised by the next samples.

        Parameters
        ----------
        columns : mapping of str to ndarray
            Output columns of consecutive samples, ``time_s`` among them.

        Raises
        ------
        GreyboxError
            When a limit names a column the output lacks (checked on the first call).
        """
        if not self._checked:
            missing = [limit.column for limit in self.limits if limit.column not in columns]
            if missing:
                names = ", ".join(name for name in columns if name != "time_s")
                raise GreyboxError(f"--limit {missing[0]}: no such output column; the columns are {names}"
                                   + ("" if "force_process_N" in columns or "torque_process_Nm" in columns
                                      else " (the force needs --axis-config)"))
            self._checked = True
        alarms = []
        time = columns["time_s"]
        for limit in self.limits:
            name = limit.column
            magnitude = np.abs(columns[name])
            for t, value in zip(time.tolist(), magnitude.tolist()):
                if not value > limit.bound:
                    self._since[name], self._peak[name], self._raised[name] = None, 0.0, False
                    continue
                if self._since[name] is None:
                    self._since[name] = t
                self._peak[name] = max(self._peak[name], value)
                if not self._raised[name] and t - self._since[name] >= self.hold_s * (1 - 1e-9):
                    self._raised[name] = True
                    alarms.append(Alarm(name, limit.bound, self._peak[name], self._since[name], t, self.hold_s))
        return alarms
