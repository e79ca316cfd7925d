"""Velocity and acceleration of a stream as ``greybox predict`` derives them from the whole log.

Offline, a log lacking velocity or acceleration gets them from a zero-phase (forward-backward) low-pass
and central differences (:func:`greybox.data.prepare.derive`): the value at a sample depends on the
samples after it. The filter's memory decays geometrically; with
:func:`~greybox.data.prepare.derivative_margin` samples on each side of a stretch, the stretch comes out as
it does in the whole log (:func:`greybox.data.stream.prepared_blocks` rests on the same fact). A live
stream therefore gives a sample's estimate once that many samples after it have arrived: a delay of
``margin * sample_time`` (184 samples, 0.368 s at 2 ms with the default 50 Hz cut-off), the price of
the offline result. Messages that carry velocity and acceleration need no derivative and no delay.

At the end of a run (a gap, or the end of the stream) the samples still waiting are derived as the
end of a log is.
"""

from __future__ import annotations

from ..data.blocks import concatenate
from ..data.log import AxisLog
from ..data.prepare import derivative_margin, derive
from ..errors import LogError

__all__ = ["Lookahead"]


class Lookahead:
    """Prepares the samples of one run as they arrive, each once its look-ahead is in.

    Parameters
    ----------
    sample_time : float
        Nominal step of the run [s].
    cutoff_hz : float, optional
        Derivative-filter cut-off [Hz]; default :func:`~greybox.data.prepare.default_cutoff`.

    Attributes
    ----------
    margin : int
        Samples of look-ahead (and of history) a derived sample needs; 0 until a message shows that the
        stream lacks velocity or acceleration.
    """

    def __init__(self, *, sample_time: float, cutoff_hz: float | None = None):
        self.sample_time = float(sample_time)
        self.cutoff_hz = cutoff_hz
        self.margin = 0
        self._needs: bool | None = None
        self._before: AxisLog | None = None  # the last `margin` raw samples already given out
        self._pending: list[AxisLog] = []
        self._n_pending = 0

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
            self._needs = not log.is_prepared
            self.margin = derivative_margin(self.sample_time, cutoff_hz=self.cutoff_hz) if self._needs else 0
        self._pending.append(log)
        self._n_pending += len(log)
        ready = self._n_pending - self.margin
        return self._give(ready) if ready >= 2 else None

    def finish(self) -> AxisLog | None:
        """The samples still waiting, prepared as the end of a log; None when none are waiting.

        Raises
        ------
        LogError
            For a run shorter than the derivative filter needs (the samples are dropped).
        """
        if not self._n_pending:
            return None
        return self._give(self._n_pending)

    def _give(self, ready: int) -> AxisLog:
        raw = concatenate(self._pending)
        window = raw if self._before is None else concatenate([self._before, raw])
        first = 0 if self._before is None else len(self._before)
        if self._needs:
            try:
                window = derive(window, cutoff_hz=self.cutoff_hz, sample_time=self.sample_time)
            except LogError:
                self._pending, self._n_pending = [], 0
                raise
        out = window.select(slice(first, first + ready))
        given = concatenate([self._before, raw.select(slice(0, ready))]) if self._before is not None else \
            raw.select(slice(0, ready))
        self._before = given.select(slice(max(0, len(given) - self.margin), None)) if self.margin else None
        rest = raw.select(slice(ready, None))
        self._pending, self._n_pending = ([rest], len(rest)) if len(rest) else ([], 0)
        return out
