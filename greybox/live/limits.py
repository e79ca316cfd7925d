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
from datetime import datetime, timezone
from typing import Iterable, Mapping

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
        Raised: time of the sample that completed the hold [s]. Cleared: time of the first sample back
        within the limit, or of the run's last sample when it ended at a gap [s].
    hold_s : float
        The hold time [s].
    state : {"raised", "cleared"}
        Whether the alarm is raised or cleared.
    """

    column: str
    bound: float
    value: float
    since_s: float
    time_s: float
    hold_s: float
    state: str = "raised"

    def message(self, seq=None) -> str:
        """The alarm as JSON text (the alarm message of a sink), with the wall-clock time it is sent.

        Parameters
        ----------
        seq : object, optional
            The ``"seq"`` of the input message whose samples raised or cleared it.
        """
        wall = datetime.now(timezone.utc).isoformat(timespec="milliseconds")
        return json.dumps({"alarm": "limit", "state": self.state, "column": self.column, "limit": self.bound,
                           "value": self.value, "since_s": self.since_s, "time_s": self.time_s,
                           "hold_s": self.hold_s, "wall_time": wall, "seq": seq})

    def line(self) -> str:
        """The alarm in one line of text."""
        if self.state == "cleared":
            return (f"ALARM CLEARED: |{self.column}| back within {self.bound:g} at t = {self.time_s:.4f} s "
                    f"(above since t = {self.since_s:.4f} s, largest {self.value:.4g})")
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

    def rearm(self, time_s: float = math.nan) -> list[Alarm]:
        """Forget the stretches in progress (a run ended at a gap); the alarms raised are cleared.

        Parameters
        ----------
        time_s : float, optional
            Time of the last sample of the run that ended [s].

        Returns
        -------
        list of Alarm
            The alarms cleared.
        """
        cleared = [self._cleared(limit, time_s) for limit in self.limits if self._raised[limit.column]]
        for column in self._since:
            self._since[column], self._peak[column], self._raised[column] = None, 0.0, False
        return cleared

    def end_run(self, time_s: float = math.nan) -> list[Alarm]:
        """The stream ended or went quiet: nothing to check; the alarms raised stay raised (:meth:`rearm` clears
        them when the next run starts).

        Parameters
        ----------
        time_s : float, optional
            Time of the last sample of the run [s].

        Returns
        -------
        list of Alarm
            None.
        """
        return []

    def _cleared(self, limit: Limit, time_s: float) -> Alarm:
        name = limit.column
        return Alarm(name, limit.bound, self._peak[name], self._since[name], time_s, self.hold_s, "cleared")

    def check_columns(self, columns: Iterable[str]) -> None:
        """Refuse a limit on a column the output lacks (at the start, with the columns of the output).

        Parameters
        ----------
        columns : iterable of str
            The output columns.

        Raises
        ------
        GreyboxError
            When a limit names a column not among them.
        """
        columns = list(columns)
        missing = [limit.column for limit in self.limits if limit.column not in columns]
        if missing:
            names = ", ".join(name for name in columns if name != "time_s")
            raise GreyboxError(f"--limit {missing[0]}: no such output column; the columns are {names}"
                               + ("" if "force_process_N" in columns or "torque_process_Nm" in columns
                                  else " (the force needs --axis-config)"))
        self._checked = True

    def check(self, columns: Mapping[str, np.ndarray]) -> list[Alarm]:
        """The alarms raised and cleared by the next samples, in time order per column.

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
            self.check_columns(columns)
        alarms = []
        time = columns["time_s"]
        for limit in self.limits:
            name = limit.column
            magnitude = np.abs(columns[name])
            for t, value in zip(time.tolist(), magnitude.tolist()):
                if not value > limit.bound:
                    if self._raised[name]:
                        alarms.append(self._cleared(limit, t))
                    self._since[name], self._peak[name], self._raised[name] = None, 0.0, False
                    continue
                if self._since[name] is None:
                    self._since[name] = t
                self._peak[name] = max(self._peak[name], value)
                if not self._raised[name] and t - self._since[name] >= self.hold_s * (1 - 1e-9):
                    self._raised[name] = True
                    alarms.append(Alarm(name, limit.bound, self._peak[name], self._since[name], t, self.hold_s))
        return alarms
