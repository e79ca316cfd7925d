"""One live stream, message by message: read, estimate, publish, watch the limits, record, count.

:class:`LiveSession` takes the items of a source (:mod:`greybox.live.sources`) one at a time. A message
that cannot be used is counted and named in one line, and the stream goes on; the samples of a usable
one go to the :class:`~greybox.live.estimator.LiveEstimator`, and the estimates they complete go out as
one message to the sink, to the recorder and past the limits. Every event (samples dropped or lost, a
gap, the broker away and back, an alarm) is said in one line.
"""

from __future__ import annotations

from typing import Callable, Mapping

import numpy as np

from ..data.log import AxisLog
from .estimator import LiveEstimator, Lost, RunStart, StepOutput
from .limits import LimitWatch
from .messages import DEFAULT_BOUNDS, Decoder, MessageBounds, MessageError, MessageLogs, estimate_message, finite_rows
from .recording import Recorder
from .sources import ConnectionChange, Received
from .stats import LiveStats
from .timeline import Dropped, Gap

__all__ = ["LiveSession"]


def _signature(log: AxisLog) -> tuple:
    """What every message of a stream must agree on: the channels present, the units."""
    return (log.velocity is not None, log.acceleration is not None, log.effort_unit, log.motion)


def _describe(signature: tuple) -> str:
    velocity, acceleration, unit, motion = signature
    given = ["velocity"] * velocity + ["acceleration"] * acceleration
    return f"{motion} axis, effort in {unit}, {' and '.join(given) if given else 'no velocity or acceleration'}"


class LiveSession:
    """The handling of one stream's messages.

    Parameters
    ----------
    estimator : LiveEstimator
        Carries the model's state.
    sink : LineSink or MqttSink
        Where the estimates and alarms go.
    say : callable
        ``say(line)`` for each line of text (notes, alarms, the stats).
    limits : LimitWatch, optional
        Limits on the estimates.
    recorder : Recorder, optional
        Rolling Parquet files of the estimates.
    mapping : mapping of str to str, optional
        ``{canonical_name: column}`` for message columns not named by the convention.
    axis : str, optional
        Axis to take from messages holding several.
    subtopic : str, optional
        The axis of a machine's session: its output messages carry ``"axis"`` and go to ``<TOPIC>/<axis>``.
    bounds : MessageBounds, optional
        The largest message taken.

    Attributes
    ----------
    stats : LiveStats
        The counters.
    alarmed : bool
        Whether an alarm was raised.
    """

    def __init__(self, estimator: LiveEstimator, sink, *, say: Callable[[str], None],
                 limits: LimitWatch | None = None, recorder: Recorder | None = None,
                 mapping: Mapping[str, str] | None = None, axis: str | None = None, subtopic: str | None = None,
                 bounds: MessageBounds = DEFAULT_BOUNDS):
        self.estimator = estimator
        self.sink = sink
        self.say = say
        self.limits = limits
        self.recorder = recorder
        self.mapping = dict(mapping) if mapping else None
        self.axis = axis
        self.subtopic = subtopic
        self.stats = LiveStats()
        self.alarmed = False
        self._decoder = Decoder(bounds)
        self._logs = MessageLogs(mapping=self.mapping)
        self._signature: tuple | None = None
        self._offline_since: float | None = None
        self._run = 0  # run of the last estimates
        self._last_s = float("nan")  # time of the last sample estimated
        self._open = True

    def handle(self, item: Received | ConnectionChange) -> None:
        """Take one item of the source.

        Parameters
        ----------
        item : Received or ConnectionChange
            A message, or a change of the broker connection.
        """
        if isinstance(item, ConnectionChange):
            self.connection(item)
            return
        self.stats.messages += 1
        try:
            decoded = self._decoder.decode(item.payload)
        except MessageError as exc:
            self.stats.rejected += 1
            self.say(f"{item.name}: skipped: {exc}")
            return
        if decoded is not None:
            self.take(*decoded, name=item.name)

    def take(self, columns: Mapping[str, np.ndarray], seq=None, *, name: str, select: bool = True) -> None:
        """Take the columns of one decoded message.

        Parameters
        ----------
        columns : mapping of str to ndarray
            The message's columns (:meth:`greybox.live.messages.Decoder.decode`).
        seq : object, optional
            The message's sequence tag.
        name : str
            How the message is named in lines.
        select : bool, default True
            Take the session's ``axis`` from columns named ``<axis>_<quantity>_<unit>``; False for a
            message of this axis alone (its own topic).
        """
        if self.estimator.timeline.max_gap is not None:
            columns, bad = finite_rows(columns)
            if bad:
                self.stats.samples_received += bad
                self.stats.drop("not finite", bad)
                self.say(f"{name}: {bad} sample(s) holding NaN or infinity dropped; the gap is bridged (--max-gap)")
                if not len(next(iter(columns.values()))):
                    return
        try:
            log = self._logs.log(columns, name=name, axis=self.axis if select else None)
            signature = _signature(log)
            if self._signature is None:
                self._signature = signature
            elif signature != self._signature:
                raise MessageError(f"the message carries {_describe(signature)}; the stream started with "
                                   f"{_describe(self._signature)}")
        except MessageError as exc:
            self.stats.rejected += 1
            self.say(f"{name}: skipped: {exc}")
            return
        self.stats.samples_received += len(log)
        self._publish(self.estimator.step(log), seq)

    def stats_line(self) -> str:
        """The counters in one line."""
        return self.stats.line()

    def current_stats(self) -> LiveStats:
        """The counters, with the samples waiting now."""
        if self._open:
            self.stats.waiting = self.estimator.waiting
            self.stats.outputs_lost, self.stats.outputs_queued = self.sink.lost, self.sink.queued
        return self.stats

    def counters(self) -> dict:
        """The counters as they are now, JSON-able."""
        return self.current_stats().to_dict()

    def warm_up(self) -> None:
        """Load the compiled kernels before the stream starts, so that the first message is not kept waiting
        (:meth:`LiveEstimator.warm_up`); check the limits against the columns of the output then.

        Raises
        ------
        GreyboxError
            When a limit names a column the output lacks (e.g. the force without an axis file).
        """
        if self.estimator.warm_up() and self.limits is not None:
            self.limits.check_columns(self.estimator.output_columns)

    def finish(self) -> None:
        """The end of the stream (or of a run, :meth:`idle`): the samples still waiting are estimated as the end
        of a log, and the limits see the run end (an envelope checks the part being cut whole, as at a gap; the
        alarms raised stay raised until the next run)."""
        self._publish(self.estimator.finish(), None)
        if self.limits is not None:
            self._alarms(self.limits.end_run(self._last_s), None)

    def idle(self, idle_s: float) -> None:
        """The stream went quiet: the samples waiting are estimated as the end of a run (the next sample
        starts a new one, from the model's initial state).

        Parameters
        ----------
        idle_s : float
            Seconds since the last message, said in the line.
        """
        pending = self.estimator.waiting + self.estimator.timeline.held
        if pending:
            self.say(f"no message for {idle_s:.2g} s: the {pending} sample(s) waiting are estimated as the end of "
                     "a run; the next sample starts a new one")
            self.finish()
        if self.recorder is not None:
            self.recorder.flush()  # the recording on disk too, while the stream is quiet

    def close(self, *, stopped: bool = False) -> None:
        """Write the recording's last file and close the sink.

        Parameters
        ----------
        stopped : bool, default False
            The command was stopped (SIGTERM, Ctrl-C): the samples waiting for their look-ahead are
            counted as lost.
        """
        self._open = False
        stats = self.stats
        if stopped:
            unaccounted = stats.samples_received - stats.samples_estimated - stats.skipped
            if unaccounted > 0:  # with --max-gap the estimates are the grid's points, not the samples received
                stats.lose("stopped before their look-ahead arrived", unaccounted)
        stats.waiting = 0 if stopped else self.estimator.waiting
        try:
            if self.recorder is not None:
                self.recorder.close()
        finally:
            self.sink.close()
            self.stats.outputs_lost, self.stats.outputs_queued = self.sink.lost, self.sink.queued

    def connection(self, change: ConnectionChange, *, quiet: bool = False) -> None:
        """Count a loss or return of the source's connection (broker or server), and say it.

        Parameters
        ----------
        change : ConnectionChange
            The change.
        quiet : bool, default False
            Count without saying (another session says it).
        """
        say = (lambda line: None) if quiet else self.say
        if not change.connected:
            self.stats.disconnections += 1
            self._offline_since = change.time_s
            say(f"{change.peer} connection lost; reconnecting")
        else:
            away = change.time_s - self._offline_since if self._offline_since is not None else 0.0
            self.stats.offline_s += away
            self._offline_since = None
            say(f"{change.peer} connection back after {away:.1f} s" + (f"; {change.after}" if change.after else ""))

    def _publish(self, out: StepOutput, seq) -> None:
        for event in out.events:
            self._event(event)
        if not out.results:
            return
        parts = [result.columns() for result in out.results]
        columns = parts[0] if len(parts) == 1 else {name: np.concatenate([part[name] for part in parts])
                                                    for name in parts[0]}
        self.stats.samples_estimated += out.n_samples
        starts = []  # whether each result starts a new run after the first: a new file
        for run, part in zip(out.runs, parts):  # the alarms first: they are what a shop floor waits for
            starts.append(run != self._run and run != 0)
            if run != self._run:  # the estimates of a new run: the limits re-armed
                self._run = run
                if self.limits is not None:
                    self._alarms(self.limits.rearm(self._last_s), seq)
            if self.limits is not None:
                self._alarms(self.limits.check(part), seq)
            self._last_s = float(part["time_s"][-1]) if len(part["time_s"]) else self._last_s
        self.sink.estimate(estimate_message(columns, seq, axis=self.subtopic), subtopic=self.subtopic)
        if self.recorder is not None:
            for start, result in zip(starts, out.results):
                if start:
                    self.recorder.new_run()
                self.recorder.add(result)

    def _alarms(self, alarms, seq) -> None:
        for alarm in alarms:
            if alarm.state == "raised":
                self.alarmed = True
                self.stats.alarms += 1
            else:
                self.stats.alarms_cleared += 1
            self.sink.alarm(alarm.message(seq), subtopic=self.subtopic, column=alarm.column)
            self.say(alarm.line())

    def _event(self, event) -> None:
        if isinstance(event, Dropped):
            self.stats.drop(event.reason, event.count)
            what = "not after" if event.reason == "backwards" else "too soon after"
            self.say(f"{event.count} sample(s) dropped: t = {event.time_s:.9g} s {what} t = {event.after_s:.9g} s")
        elif isinstance(event, Gap):
            self.stats.gaps += 1
            self.say(f"gap of {1e3 * event.step_s:.6g} ms before t = {event.time_s:.9g} s (about {event.missing} "
                     "samples missing): a new run starts, the model's state re-initialised")
        elif isinstance(event, Lost):
            self.stats.lose(event.reason, event.count)
            self.say(f"{event.count} sample(s) lost: {event.reason}")
        elif isinstance(event, RunStart):
            if event.index == 0:
                delay = (f"; each estimate follows its sample by {event.lookahead} samples "
                         f"({event.lookahead * event.sample_time:.3g} s), the look-ahead of the derivatives"
                         if event.lookahead else "")
                if event.delay:
                    delay += ("; causal derivatives (--latency low): the derived acceleration lags by "
                              f"{event.delay:.3g} samples ({1e3 * event.delay * event.sample_time:.3g} ms)")
                self.say(f"stream starts at t = {event.time_s:.9g} s, step {1e3 * event.sample_time:.6g} ms{delay}")
