"""Velocity and acceleration of a stream as ``greybox predict`` derives them from the whole log.

Offline, a log lacking velocity or acceleration gets them from a zero-phase (forward-backward) low-pass
and central differences (:func:`greybox.data.prepare.derive`): the value at a sample depends on the
samples after it. The filter's memory decays geometrically; with
:func:`~greybox.data.prepare.derivative_margin` samples after a sample, its value comes out as it does in
the whole log (:func:`greybox.data.stream.prepared_blocks` rests on the same fact). A live stream
therefore gives a sample's estimate once that many samples after it have arrived: a delay of
``margin * sample_time`` (184 samples, 0.368 s at 2 ms with the default 50 Hz cut-off), the price of
the offline result. Messages that carry velocity and acceleration need no derivative and no delay.

The forward pass of the filter runs once over each sample as it arrives, its state carried from
message to message; per message only the backward pass over the look-ahead runs
(:class:`~greybox.live.zerophase.ZeroPhaseStream`). At the end of a run (a gap, or the end of the
stream) the samples still waiting are derived as the end of a log is.

With ``latency="low"`` (``greybox live --latency low``) the derivatives are causal instead
(:class:`~greybox.live.causal.CausalStream`): no look-ahead, every sample given out as it arrives, its
derived channels delayed by the filter's group delay.
"""

from __future__ import annotations

import numpy as np

from ..data.log import AxisLog
from ..data.prepare import derivative_filter, derivative_margin
from ..errors import LogError
from .causal import CausalStream, causal_cutoff
from .zerophase import ZeroPhaseStream

__all__ = ["LATENCIES", "Lookahead"]

#: The derivative modes: the offline result after a look-ahead, or causal at once.
LATENCIES = ("exact", "low")

_CHANNELS = ("time", "position", "effort", "velocity", "acceleration")


class Lookahead:
    """Prepares the samples of one run as they arrive, each once its look-ahead is in.

    Parameters
    ----------
    sample_time : float
        Nominal step of the run [s].
    cutoff_hz : float, optional
        Derivative-filter cut-off [Hz]; default :func:`~greybox.data.prepare.default_cutoff` (that of
        ``greybox predict``), and with ``latency="low"`` :func:`~greybox.live.causal.causal_cutoff`.
    latency : {"exact", "low"}, default "exact"
        "exact": the zero-phase derivatives of ``greybox predict``, each sample given out once its look-ahead
        is in; "low": causal derivatives, every sample given out at once.

    Attributes
    ----------
    margin : int
        Samples of look-ahead (and of history) a derived sample needs; 0 until a message shows that the
        stream lacks velocity or acceleration, and always with ``latency="low"``.
    delay : float
        Group delay of the derived acceleration at low frequencies [samples]; 0 for the exact derivatives
        and for messages that carry velocity and acceleration.
    """

    def __init__(self, *, sample_time: float, cutoff_hz: float | None = None, latency: str = "exact"):
        if latency not in LATENCIES:
            raise ValueError(f"latency must be one of {', '.join(LATENCIES)}, got {latency!r}")
        self.sample_time = float(sample_time)
        self.cutoff_hz = cutoff_hz
        self.latency = latency
        self.margin = 0
        self.delay = 0.0
        self._needs: bool | None = None
        self._first: AxisLog | None = None  # the run's first samples: names, units, attrs
        self._filter: ZeroPhaseStream | CausalStream | None = None
        self._attrs: dict = {}
        self._pending: dict[str, np.ndarray] = {}  # per channel a buffer; its first _n_pending values wait
        self._n_pending = 0
        self._given = 0  # samples of the run given out

    @property
    def waiting(self) -> int:
        """Samples received but not yet given out."""
        return self._n_pending

    def push(self, log: AxisLog) -> AxisLog | None:
        """Take the kept samples of a message; return the prepared samples now complete (at least 2), or None.

        Parameters
        ----------
        log : AxisLog
            Consecutive samples of the run, not prepared (or carrying velocity and acceleration).
        """
        if self._needs is None:
            self._start(log)
        n, stop = self._n_pending, self._n_pending + len(log)
        for name, buffer in self._pending.items():
            if stop > buffer.size:  # room for twice as many: the buffers settle at twice the look-ahead
                buffer = self._pending[name] = np.concatenate((buffer[:n], np.empty(max(stop, 2 * n))))
            buffer[n:stop] = getattr(log, name) if name in _CHANNELS else log.extras[name]
        self._n_pending = stop
        if self._filter is not None:
            self._filter.push(log.position if log.velocity is None else log.velocity)
            if not self._filter.started:
                return None
        ready = self._n_pending - self.margin
        return self._give(ready, final=False) if ready >= 2 else None

    def finish(self) -> AxisLog | None:
        """The samples still waiting, prepared as the end of a log; None when none are waiting.

        Raises
        ------
        LogError
            For a run shorter than the derivative filter needs (the samples are dropped).
        """
        if not self._n_pending:
            return None
        if self._filter is not None and not self._filter.started:
            n = self._filter.received
            self._n_pending = 0
            raise LogError(self._first.source or None, f"the log has {n} samples; the 4th-order filter needs at "
                                                       f"least {self._filter.needed}")
        return self._give(self._n_pending, final=True)

    def _start(self, log: AxisLog) -> None:
        self._needs = not log.is_prepared
        self._first = log
        present = [name for name in _CHANNELS if getattr(log, name) is not None]
        self._pending = {name: np.empty(0) for name in [*present, *log.extras]}
        self._attrs = dict(log.attrs)
        if not self._needs:
            return
        cutoff_hz = causal_cutoff(self.sample_time) if self.latency == "low" and self.cutoff_hz is None \
            else self.cutoff_hz
        sos, cutoff = derivative_filter(self.sample_time, cutoff_hz=cutoff_hz, source=log.source or None)
        differences = 1 + (log.velocity is None)
        if self.latency == "low":
            self._filter = CausalStream(sos, sample_time=self.sample_time, differences=differences)
            self.delay = self._filter.delay
        else:
            self.margin = derivative_margin(self.sample_time, cutoff_hz=self.cutoff_hz)
            self._filter = ZeroPhaseStream(sos, sample_time=self.sample_time, differences=differences)
        derived = ["acceleration"] if log.velocity is not None else \
            ["velocity"] + (["acceleration"] if log.acceleration is None else [])
        self._attrs["derivative_filter"] = {"cutoff_hz": cutoff, "order": 4, "derived": derived}
        if self.latency == "low":
            self._attrs["derivative_filter"].update(causal=True, delay_samples=self.delay)

    def _give(self, ready: int, *, final: bool) -> AxisLog:
        columns = {}
        waiting = self._n_pending
        for name, buffer in self._pending.items():
            columns[name] = buffer[:ready].copy()
            buffer[:waiting - ready] = buffer[ready:waiting]  # the rest to the front (numpy copies overlaps safely)
        self._n_pending -= ready
        if self._filter is not None:
            derivatives = self._filter.derivatives(self._given, self._given + ready, final=final)
            if self._first.velocity is None:
                columns["velocity"] = derivatives[0]
                if self._first.acceleration is None:
                    columns["acceleration"] = derivatives[1]
            else:
                columns["acceleration"] = derivatives[0]
        self._given += ready
        first = self._first
        extras = {name: columns.pop(name) for name in first.extras}
        return AxisLog(**columns, effort_unit=first.effort_unit, axis=first.axis, dataset=first.dataset,
                       source=first.source, motion=first.motion, extras=extras, attrs=self._attrs)
