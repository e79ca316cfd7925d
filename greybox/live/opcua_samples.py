"""The samples of an OPC UA server's axis variables: one value per variable, matched by their source time stamp.

A subscription delivers each variable's changes on its own, each with its own ``SourceTimestamp``. A controller
writes the variables of one sample (time, position, velocity, current) in one cycle: with one stamp, or (a server
that stamps each variable as it writes it) with stamps a little apart. The values whose stamps lie within
``tolerance_s`` of the first of them, one per variable, are one sample (a variable holding an array holds a
batch: the arrays of one stamp are one batch). :class:`SampleAssembler` collects the values as they come and gives
the samples in stamp order as message columns, ``{column: value}``, for the decoder every source's messages go
through: a value that is not a number (text, null, NaN) is then refused there in one line, as in a message of any
other source.

Without a time variable (no column ``time_s``, ``time_ms``, ...) a sample's ``time_s`` is the mean of its
variables' source time stamps [s since 1970]: time stamps that jitter by a fraction of the step, bridged by
``greybox live --max-gap`` as any jittered stream.

A value whose stamp is not later than the latest of the last sample given is that sample again (a subscription
made anew after a reconnection starts with the variables' current values) and is left out.

A sample some of whose variables never deliver its stamp (every such variable has delivered a later one) is
given as it is, without them: the decoder refuses it for the columns it lacks, in one line.
"""

from __future__ import annotations

import bisect
import datetime
import math
from typing import Hashable, Sequence

__all__ = ["MAX_PENDING", "SampleAssembler", "stamp_seconds"]

#: Most samples waiting for a variable's value; beyond, the oldest is given as it stands.
MAX_PENDING = 10_000


def _plain_number(value) -> bool:
    return type(value) in (int, float) and math.isfinite(value)


def stamp_seconds(stamp) -> float:
    """A source time stamp in seconds: a datetime (naive ones are UTC, as asyncua gives them) since 1970, or a number.

    Parameters
    ----------
    stamp : datetime.datetime or float
        The stamp.
    """
    if isinstance(stamp, datetime.datetime):
        if stamp.tzinfo is None:
            stamp = stamp.replace(tzinfo=datetime.timezone.utc)
        return stamp.timestamp()
    return float(stamp)


class SampleAssembler:
    """Values of named variables, each with a source time stamp, assembled into samples in stamp order.

    Parameters
    ----------
    columns : sequence of str
        The message column of each variable (``time_s``, ``position_mm``, ...).
    tolerance_s : float, default 0.0
        Largest difference between the stamps of one sample's variables [s]; 0: the same stamp. Keep it below
        half the sample time.
    max_pending : int, default :data:`MAX_PENDING`
        Most samples held waiting for a variable's value.
    """

    def __init__(self, columns: Sequence[str], *, tolerance_s: float = 0.0, max_pending: int = MAX_PENDING):
        if not tolerance_s >= 0.0:
            raise ValueError(f"tolerance_s must be 0 or more, got {tolerance_s!r}")
        self.columns = tuple(columns)
        self.tolerance_s = float(tolerance_s)
        self.max_pending = int(max_pending)
        self.timed = any(column == "time" or column.startswith("time_") for column in self.columns)
        self._keys: list[float] = []  # the pending samples' stamps [s], sorted
        self._pending: dict[float, tuple[Hashable, dict[str, object], list[float]]] = {}
        self._latest: dict[str, float] = {}
        self._given: float | None = None  # the latest stamp of the last sample given [s]

    @property
    def pending(self) -> int:
        """The samples waiting for a variable's value."""
        return len(self._pending)

    def add(self, column: str, stamp: Hashable, value) -> None:
        """Take one value of a variable.

        Parameters
        ----------
        column : str
            The variable's column.
        stamp : datetime.datetime or float
            Its source time stamp (those of one sample within ``tolerance_s`` of each other).
        value : object
            The value as the server gave it (a number, an array of numbers, or anything else).
        """
        seconds = stamp_seconds(stamp)
        if self._given is not None and not seconds > self._given:
            return
        same = self._pending.get(seconds)
        if same is not None and column in same[1]:  # a variable written twice with one stamp: the later value
            same[1][column] = value
            return
        key = self._sample_of(column, seconds)
        if key is None:
            key = seconds
            bisect.insort(self._keys, key)
            self._pending[key] = (stamp, {}, [])
        _, values, stamps = self._pending[key]
        values[column] = value
        stamps.append(seconds)
        if column not in self._latest or seconds > self._latest[column]:
            self._latest[column] = seconds

    def _sample_of(self, column: str, seconds: float) -> float | None:
        """The pending sample nearest ``seconds`` within the tolerance that lacks ``column``, or None."""
        low = bisect.bisect_left(self._keys, seconds - self.tolerance_s)
        high = bisect.bisect_right(self._keys, seconds + self.tolerance_s)
        free = [key for key in self._keys[low:high] if column not in self._pending[key][1]]
        return min(free, key=lambda key: abs(key - seconds)) if free else None

    def _dead(self, key: float, values: dict) -> bool:
        """Whether every variable missing from the sample has delivered a later stamp (it will not come)."""
        return all(column in self._latest and self._latest[column] > key + self.tolerance_s
                   for column in self.columns if column not in values)

    def take(self) -> list[tuple[Hashable, dict[str, object]]]:
        """The samples ready, in stamp order: consecutive ones of plain finite numbers joined into one batch.

        Returns
        -------
        list of (stamp, dict of str to object)
            The first sample's stamp (as its first value gave it) and the columns (lists of the values for a
            joined batch); without a time variable, ``time_s`` is the mean of the sample's stamps [s]. A sample
            holding anything but plain finite numbers, or lacking a variable, is one item of its own.
        """
        ready = []
        while self._keys:
            key = self._keys[0]
            stamp, values, stamps = self._pending[key]
            complete = len(values) == len(self.columns)
            if not (complete or self._dead(key, values) or len(self._pending) > self.max_pending):
                break
            del self._pending[key], self._keys[0]
            self._given = max(stamps)
            if not self.timed:
                values = {"time_s": math.fsum(stamps) / len(stamps), **values}
            ready.append((stamp, values, complete and all(map(_plain_number, values.values()))))
        out: list[tuple[Hashable, dict[str, object]]] = []
        batch = None
        for stamp, values, plain in ready:
            if not plain:
                out.append((stamp, values))
                batch = None
            elif batch is None:
                batch = {column: [value] for column, value in values.items()}
                out.append((stamp, batch))
            else:
                for column, value in values.items():
                    batch[column].append(value)
        return out
