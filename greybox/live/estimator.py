"""The process current and force of a stream, message by message, as ``greybox predict`` gives them.

:class:`LiveEstimator` takes the samples of each message, checks their time stamps
(:class:`~greybox.live.timeline.Timeline`), derives velocity and acceleration as the whole log would get
them (:class:`~greybox.live.lookahead.Lookahead`), and runs the model over the samples now complete from
the state the previous ones left, through the same code that ``greybox predict`` streams a log with
(:func:`greybox.predict.process.process_blocks`): process current, force, training-region flags. Fed
the samples of a log, the estimates equal the table ``greybox predict`` writes for it.

A gap in the time stamps ends the run: the samples waiting are finished as the end of a log, and the
next run starts from the model's initial state, as the readers split a log at gaps. With ``max_gap`` the
samples are resampled onto the nominal grid and only steps longer than ``max_gap`` steps are gaps, as
``greybox predict --resample --max-gap`` treats a log. With ``latency="low"`` the derivatives are causal:
each message's estimates go out with it (:mod:`greybox.live.causal`).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Iterator

import numpy as np

from ..data.axis_config import AxisConfig
from ..data.log import AxisLog
from ..data.prepare import derivative_margin
from ..errors import GreyboxError, LogError
from ..models.chunked import DEFAULT_CHUNK_S
from ..predict.process import ProcessResult, ProcessTally, check_process_inputs, process_blocks
from .lookahead import Lookahead
from .timeline import Dropped, Gap, Timeline

__all__ = ["Lost", "RunStart", "StepOutput", "LiveEstimator"]


@dataclass(frozen=True)
class Lost:
    """Samples received but never estimated.

    Attributes
    ----------
    count : int
        Samples lost.
    time_s : float
        Time of the first one [s].
    reason : str
        Why, in words.
    """

    count: int
    time_s: float
    reason: str


@dataclass(frozen=True)
class RunStart:
    """A run starts: the model's state is (re-)initialised.

    Attributes
    ----------
    time_s : float
        Time of the run's first sample [s].
    index : int
        Runs before it (0 for the first).
    sample_time : float
        Nominal step [s].
    lookahead : int
        Samples of look-ahead of the derivatives (0 when the messages carry them, or they are causal).
    delay : float, default 0.0
        Group delay of the causal derivatives at low frequencies [samples] (0 for the exact ones).
    """

    time_s: float
    index: int
    sample_time: float
    lookahead: int
    delay: float = 0.0


@dataclass
class StepOutput:
    """What one message (or the end of the stream) gave.

    Attributes
    ----------
    results : list of ProcessResult
        Estimates of the samples completed, in time order (empty while their look-ahead is missing).
    events : list
        :class:`~greybox.live.timeline.Dropped`, :class:`~greybox.live.timeline.Gap`, :class:`Lost` and
        :class:`RunStart`, in order.
    runs : list of int
        The run (0 for the first) of each result.
    """

    results: list = field(default_factory=list)
    events: list = field(default_factory=list)
    runs: list = field(default_factory=list)

    @property
    def n_samples(self) -> int:
        """Samples estimated."""
        return sum(len(result.time) for result in self.results)


class _Run:
    """One run: its look-ahead, and the process blocks fed one block at a time.

    The model and the stream are checked at the run's first block (:meth:`CurrentModel.stream_view`);
    the blocks' samples were checked as they arrived, so each chunk is not checked again.
    """

    def __init__(self, model, *, index: int, sample_time: float, axis_config, cutoff_hz, chunk_s, tally, latency):
        self.index = index
        self.lookahead = Lookahead(sample_time=sample_time, cutoff_hz=cutoff_hz, latency=latency)
        self.model = model
        self.sample_time = sample_time
        self.axis_config = axis_config
        self.chunk_s = chunk_s
        self.tally = tally
        self._box: deque = deque()
        self._results: Iterator[ProcessResult] | None = None

    def _mailbox(self) -> Iterator[AxisLog]:
        while True:
            yield self._box.popleft()

    def estimate(self, block: AxisLog) -> ProcessResult:
        if self._results is None:
            check_process_inputs([block], self.axis_config)
            view = self.model.stream_view(block, sample_time=self.sample_time)
            self._results = process_blocks(view, self._mailbox(), sample_time=self.sample_time,
                                           axis_config=self.axis_config, chunk_s=self.chunk_s, tally=self.tally)
        self._box.append(block)
        return next(self._results)


class LiveEstimator:
    """The estimates of a stream of messages, with the model's state carried from message to message.

    Parameters
    ----------
    model : CurrentModel
        A fitted model (trained on air cuts) of a registered kind.
    axis_config : AxisConfig, optional
        Drive-train constants; gives the process force (torque on a rotary axis).
    sample_time : float, optional
        Nominal step [s]; default the median step of the first samples
        (:data:`~greybox.live.timeline.SETTLE_SAMPLES`).
    tolerance : float, default 0.25
        Time-step tolerance, a fraction of the nominal step: a longer step is a gap, a shorter one drops
        the sample.
    cutoff_hz : float, optional
        Derivative-filter cut-off [Hz] (default as ``greybox predict``).
    chunk_s : float, default 60.0
        Chunk length [s] of the model within a message (as ``greybox predict --chunk-s``).
    keep_tally : bool, default False
        Keep the running figures of every sample estimated (:attr:`tally`); their sums of squares cost
        about a tenth of a message's time, and the session needs none of them.
    max_gap : float, optional
        Bridge steps up to this many nominal steps by resampling onto the nominal grid (as ``greybox predict
        --resample S --max-gap``); longer ones are gaps. Default: no resampling, ``tolerance`` applies.
    latency : {"exact", "low"}, default "exact"
        "exact": the derivatives of ``greybox predict`` (a look-ahead of 0.368 s at 2 ms); "low": causal
        derivatives, the estimates at once, their derived channels delayed (:mod:`greybox.live.causal`).

    Attributes
    ----------
    tally : ProcessTally or None
        Running figures of every sample estimated (with ``keep_tally``).
    runs : int
        Runs started (1 + gaps).
    output_columns : tuple of str or None
        The columns of the estimates, once :meth:`warm_up` ran.
    """

    def __init__(self, model, *, axis_config: AxisConfig | None = None, sample_time: float | None = None,
                 tolerance: float = 0.25, cutoff_hz: float | None = None, chunk_s: float = DEFAULT_CHUNK_S,
                 keep_tally: bool = False, max_gap: float | None = None, latency: str = "exact"):
        self.model = model
        self.axis_config = axis_config
        self.cutoff_hz = cutoff_hz
        self.chunk_s = float(chunk_s)
        self.latency = latency
        self.timeline = Timeline(sample_time=sample_time, tolerance=tolerance, max_gap=max_gap)
        self.tally = ProcessTally() if keep_tally else None
        self.runs = 0
        self.output_columns: tuple | None = None
        self._run: _Run | None = None

    @property
    def lookahead(self) -> int:
        """Samples of look-ahead of the current run (0 before the first run)."""
        return 0 if self._run is None else self._run.lookahead.margin

    @property
    def waiting(self) -> int:
        """Samples received and kept, not yet estimated."""
        return 0 if self._run is None else self._run.lookahead.waiting

    def warm_up(self) -> bool:
        """Run the model and the derivatives once over made-up samples, before the stream starts.

        The first estimate of a stream would otherwise wait while the compiled kernels (the derivative
        filter's, the model's) are loaded: tens of milliseconds, and on a busy machine more than a hundred,
        during which the messages behind it queue up. Nothing of the made-up stream is kept: it runs in an
        estimator of its own.

        Returns
        -------
        bool
            Whether the samples ran through (False when the model, the axis file or an option refuses made-up
            samples of the model's kind of axis; the stream's own messages then say why).
        """
        try:
            step = self.timeline.nominal or float(self.model.sample_time_)
            trial = LiveEstimator(self.model, axis_config=self.axis_config, sample_time=step,
                                  tolerance=self.timeline.tolerance, cutoff_hz=self.cutoff_hz, chunk_s=self.chunk_s,
                                  max_gap=self.timeline.max_gap, latency=self.latency)
            n = 2 * derivative_margin(step, cutoff_hz=self.cutoff_hz) + 32
            time = step * np.arange(n)
            log = AxisLog(time=time, position=np.sin(2.0 * np.pi * time), effort=np.zeros(n),
                          effort_unit=self.model.effort_unit_, motion=self.model.motion_, source="warm-up")
            ran = trial.step(log.select(slice(0, n // 2))).results + trial.step(log.select(slice(n // 2, n))).results \
                + trial.finish().results
        except (GreyboxError, AttributeError, ValueError):  # a model file without its fit's record, an option
            return False  # out of range: the stream's first message says what is wrong
        if ran:
            self.output_columns = tuple(ran[0].columns())
        return bool(ran)

    def step(self, log: AxisLog) -> StepOutput:
        """Take the samples of one message; return the estimates now complete and what happened.

        Parameters
        ----------
        log : AxisLog
            The samples of one message (:func:`greybox.live.messages.message_log`).

        Returns
        -------
        StepOutput
        """
        out = StepOutput()
        for event in self.timeline.push(log):
            self._event(event, out)
        return out

    def finish(self) -> StepOutput:
        """End the stream: the samples still held or waiting are estimated as the end of a log.

        Returns
        -------
        StepOutput
        """
        out = StepOutput()
        for event in self.timeline.flush():
            self._event(event, out)
        self._end_run(out)
        return out

    def _event(self, event, out: StepOutput) -> None:
        if isinstance(event, Dropped):
            out.events.append(event)
        elif isinstance(event, Gap):
            self._end_run(out)
            out.events.append(event)
        else:
            self._samples(event, out)

    def _samples(self, samples: AxisLog, out: StepOutput) -> None:
        if self._run is None:
            self._run = _Run(self.model, index=self.runs, sample_time=self.timeline.nominal,
                             axis_config=self.axis_config, cutoff_hz=self.cutoff_hz, chunk_s=self.chunk_s,
                             tally=self.tally, latency=self.latency)
            ready = self._run.lookahead.push(samples)
            out.events.append(RunStart(float(samples.time[0]), self.runs, self.timeline.nominal,
                                       self._run.lookahead.margin, self._run.lookahead.delay))
            self.runs += 1
        else:
            ready = self._run.lookahead.push(samples)
        if ready is not None:
            out.results.append(self._run.estimate(ready))
            out.runs.append(self._run.index)

    def _end_run(self, out: StepOutput) -> None:
        if self._run is None:
            return
        run, self._run = self._run, None
        waiting = run.lookahead.waiting
        try:
            ready = run.lookahead.finish()
        except LogError as exc:
            out.events.append(Lost(waiting, float("nan"), f"run too short to derive: {exc.problem}"))
            return
        if ready is None:
            return
        if len(ready) < 2:
            out.events.append(Lost(len(ready), float(ready.time[0]),
                                   "a run's last sample alone (a model needs two samples)"))
            return
        out.results.append(run.estimate(ready))
        out.runs.append(run.index)
