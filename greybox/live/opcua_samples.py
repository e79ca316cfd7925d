"""The samples of an OPC UA server's axis variables: one value per variable, matched by their source time stamp.

A subscription delivers each variable's changes on its own. A controller writes the variables of one sample
(time, position, velocity, current) in one cycle, with one ``SourceTimestamp``; the values that share a source
time stamp are one sample (a variable holding an array holds a batch: the arrays of one stamp are one batch).
:class:`SampleAssembler` collects the values as they come and gives the samples in time-stamp order as message
columns, ``{column: value}``, for the decoder every source's messages go through: a value that is not a number
(text, null, NaN) is then refused there in one line, as in a message of any other source.

A value whose stamp is not later than that of the last sample given is that sample again (a subscription made
anew after a reconnection starts with the variables' current values) and is left out.

A sample some of whose variables never deliver its stamp (every such variable has delivered a later one) is
given as it is, without them: the decoder refuses it for the columns it lacks, in one line.
"""

from __future__ import annotations

import math
from typing import Hashable, Sequence

__all__ = ["MAX_PENDING", "SampleAssembler"]

#: Most samples waiting for a variable's value; beyond, the oldest is given as it stands.
MAX_PENDING = 10_000


def _plain_number(value) -> bool:
    return type(value) in (int, float) and math.isfinite(value)


class SampleAssembler:
    """Values of named variables, each with a source time stamp, assembled into samples in stamp order.

    Parameters
    ----------
    columns : sequence of str
        The message column of each variable (``time_s``, ``position_mm``, ...).
    max_pending : int, default :data:`MAX_PENDING`
        Most samples held waiting for a variable's value.
    """

    def __init__(self, columns: Sequence[str], *, max_pending: int = MAX_PENDING):
        self.columns = tuple(columns)
        self.max_pending = int(max_pending)
        self._pending: dict[Hashable, dict[str, object]] = {}
        self._latest: dict[str, Hashable] = {}
        self._given: Hashable | None = None  # the stamp of the last sample given

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
        stamp : orderable
            Its source time stamp (the values of one sample share it).
        value : object
            The value as the server gave it (a number, an array of numbers, or anything else).
        """
        if self._given is not None and not stamp > self._given:
            return
        self._pending.setdefault(stamp, {})[column] = value
        if column not in self._latest or stamp > self._latest[column]:
            self._latest[column] = stamp

    def _dead(self, stamp, values: dict) -> bool:
        """Whether every variable missing from the sample has delivered a later stamp (it will not come)."""
        return all(column in self._latest and self._latest[column] > stamp
                   for column in self.columns if column not in values)

    def take(self) -> list[tuple[Hashable, dict[str, object]]]:
        """The samples ready, in stamp order: consecutive ones of plain finite numbers joined into one batch.

        Returns
        -------
        list of (stamp, dict of str to object)
            The first sample's stamp and the columns (lists of the values for a joined batch). A sample holding
            anything but plain finite numbers, or lacking a variable, is one item of its own.
        """
        ready = []
        for stamp in sorted(self._pending):
            values = self._pending[stamp]
            complete = len(values) == len(self.columns)
            if not (complete or self._dead(stamp, values) or len(self._pending) > self.max_pending):
                break
            del self._pending[stamp]
            self._given = stamp
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
