"""``greybox live`` as one function: open the model, the source, the sink and the recording; run the stream.

:func:`run_live` runs until the source ends (the end of stdin), an alarm with ``exit_on_alarm``, or the
command is stopped: on SIGTERM or Ctrl-C (a :class:`KeyboardInterrupt` here) the recording's last file is
written and closed, the sink closed and the stats written before the interrupt goes on to the command
line, which exits with 143 (130 for Ctrl-C).
"""

from __future__ import annotations

import contextlib
import gc
import signal
import sys
import threading
import time
from dataclasses import dataclass
from typing import Callable, Mapping, TextIO

from ..errors import GreyboxError
from ..models.chunked import DEFAULT_CHUNK_S
from .broker import BrokerOptions
from .endpoints import open_endpoints
from .estimator import LiveEstimator
from .limits import Limit, LimitWatch
from .machine import MachineSession
from .messages import DEFAULT_BOUNDS, MessageBounds
from .opcua import OpcUaOptions
from .recording import DEFAULT_RECORD_S, Recorder
from .report import LINES_PER_INTERVAL, LineLimiter
from .session import LiveSession
from .sources import DEFAULT_IDLE_S, Idle
from .stats import LiveStats, StatsFile

__all__ = ["ALARM_STATUS", "SWITCH_INTERVAL_S", "LiveOutcome", "responsive_threads", "run_live", "settled_memory"]

#: Exit status of ``greybox live --exit-on-alarm`` after an alarm.
ALARM_STATUS = 3

#: Wall-clock seconds between writes of the stats file while the stream runs.
STATS_EVERY_S = 10.0


@dataclass(frozen=True)
class LiveOutcome:
    """How a live stream ended.

    Attributes
    ----------
    stats : LiveStats
        The counters (of a machine: its messages; each axis's are in its session).
    status : int
        Exit status: 0, or :data:`ALARM_STATUS` after an alarm with ``exit_on_alarm``.
    recorded : list of pathlib.Path
        Recording files written.
    """

    stats: LiveStats
    status: int
    recorded: list


class _Deferred:
    """SIGTERM and Ctrl-C held back while a message is handled, then passed on to the handlers before.

    A signal raises where the interpreter happens to be; in the middle of a message it would leave the
    estimates, the recording and the counters out of step. Between messages (waiting for the next one)
    it is passed on at once.
    """

    _SIGNALS = (signal.SIGTERM, signal.SIGINT)

    def __init__(self):
        self._busy = False
        self._pending = None
        self._previous: dict = {}

    def __enter__(self) -> "_Deferred":
        if threading.current_thread() is threading.main_thread():
            for number in self._SIGNALS:
                self._previous[number] = signal.signal(number, self._handler)
        return self

    def __exit__(self, *exc) -> None:
        for number, previous in self._previous.items():
            signal.signal(number, previous)

    def _handler(self, signum, frame) -> None:
        if self._busy:
            self._pending = (signum, frame)
        else:
            self._forward(signum, frame)

    def _forward(self, signum, frame) -> None:
        previous = self._previous.get(signum)
        if callable(previous):
            previous(signum, frame)
        raise KeyboardInterrupt()

    @contextlib.contextmanager
    def held(self):
        """Hold the signals back while the block runs; pass on one that came meanwhile."""
        self._busy = True
        try:
            yield
        finally:
            self._busy = False
        if self._pending is not None:
            pending, self._pending = self._pending, None
            self._forward(*pending)


@contextlib.contextmanager
def settled_memory():
    """Leave the objects of the start-up out of the garbage collector's passes while the stream runs.

    The modules, the model and the sessions are hundreds of thousands of objects that live as long as the
    command; a full pass of the collector over them takes half a second (more on a busy machine), and one
    falls due now and then as a long stream allocates. Frozen (:func:`gc.freeze`), they are not scanned
    while the block runs; the collector still runs over what the stream allocates. They are given back to
    the collector after the block.
    """
    gc.collect()
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


#: Python's GIL switch interval while a stream runs [s] (CPython's default is 5 ms).
SWITCH_INTERVAL_S = 0.0005


@contextlib.contextmanager
def responsive_threads(interval_s: float = SWITCH_INTERVAL_S):
    """Let paho's network threads in within ``interval_s`` while the main thread estimates.

    A message arrives in the source's network thread and its estimate leaves through the sink's; both need
    the GIL, which the main thread holds while it handles a message. A thread waiting for the GIL asks for
    it after the switch interval (CPython's default 5 ms): on a busy machine, where the main thread's
    handling of a message is stretched by other processes, the next message's arrival or the last
    estimate's sending waited up to that long. The interval is set back after the block.

    Parameters
    ----------
    interval_s : float, default SWITCH_INTERVAL_S
        The switch interval [s] while the block runs.
    """
    previous = sys.getswitchinterval()
    sys.setswitchinterval(interval_s)
    try:
        yield
    finally:
        sys.setswitchinterval(previous)


def _axis_session(model_path, axis_config_path, options: dict, *, record_dir, record_s, limits, hold_s, columns,
                  axis, source, say, bounds, envelope_path=None):
    """A function of the sink that builds the session of one axis's model: (session, kind, recorders)."""
    from ..data.axis_config import read_axis_config
    from ..models.files import load_model
    from ..models.registry import model_kind

    model = load_model(model_path)
    config = read_axis_config(axis_config_path) if axis_config_path else None
    mapping = {**(config.channels if config else {}), **(columns or {})}
    envelope, combined = None, None
    if envelope_path is not None:
        from .envelope import Watches, read_envelope

        envelope, combined = read_envelope(envelope_path, model_path=model_path, axis_config=config), Watches

    def build(out):
        recorder = None if record_dir is None else Recorder(
            record_dir, model=model, axis_config=config, chunk_s=options["chunk_s"], every_s=record_s,
            attrs={"model_file": str(model_path), "source": str(source)})
        watches = [LimitWatch(list(limits), hold_s=hold_s)] if limits else []
        watches += [envelope] if envelope is not None else []
        watch = watches[0] if len(watches) == 1 else combined(watches) if watches else None
        session = LiveSession(LiveEstimator(model, axis_config=config, **options), out, say=say, limits=watch,
                              recorder=recorder, mapping=mapping, axis=axis, bounds=bounds)
        return session, model_kind(model), [recorder] if recorder is not None else []

    return build


def _machine_session(model_path, machine_path, options: dict, *, record_dir, record_s, limits, hold_s, columns,
                     source, say, bounds):
    """A function of the sink that builds the sessions of a machine model's axes: (session, kind, recorders)."""
    from pathlib import Path

    from ..data.machine_config import read_machine_config
    from ..models.machine import load_machine
    from ..models.registry import model_kind

    if columns:
        raise GreyboxError("--columns applies to one axis; give a machine's channel names in --machine TOML")
    machine = load_machine(model_path)
    described = read_machine_config(machine_path) if machine_path else None

    def build(out):
        sessions, recorders = {}, []
        for axis, model in machine.models.items():
            entry = described.axis(axis) if described is not None else None
            config = entry.config if entry is not None else None
            recorder = None if record_dir is None else Recorder(
                Path(record_dir) / axis, model=model, axis_config=config, chunk_s=options["chunk_s"],
                every_s=record_s, attrs={"model_file": str(Path(model_path) / f"{axis}.gbm"), "source": str(source)})
            recorders += [recorder] if recorder is not None else []
            sessions[axis] = LiveSession(
                LiveEstimator(model, axis_config=config, **options), out,
                say=lambda line, axis=axis: say(f"{axis}: {line}"),
                limits=LimitWatch(list(limits), hold_s=hold_s) if limits else None, recorder=recorder,
                mapping=dict(entry.channels) if entry is not None and entry.channels else None, axis=axis,
                subtopic=axis, bounds=bounds)
        kinds = sorted({model_kind(model) for model in machine.models.values()})
        described_kind = f"machine ({', '.join(machine.axes)}: {', '.join(kinds)})"
        return MachineSession(sessions, say=say, bounds=bounds), described_kind, recorders

    return build, list(machine.axes)


def _sink_changes(out, session, say) -> None:
    """Say and count the losses and returns of the sink's broker connection."""
    for change in out.changes():
        if change.connected:
            say(f"sink's broker connection back; {out.queued} output message(s) queued go out now")
        else:
            session.stats.output_disconnections += 1
            say(f"sink's broker connection lost ({change.reason}); output messages are queued "
                f"(at most {out.connection.options.queue_size}) until it is back")


def run_live(model_path, *, source: str, sink: str = "-", axis_config_path=None, machine_path=None,
             record_dir=None, envelope_path=None,
             record_s: float = DEFAULT_RECORD_S, limits: list[Limit] = (), hold_s: float = 0.0,
             exit_on_alarm: bool = False, stats_path=None, sample_time: float | None = None,
             tolerance: float = 0.25, cutoff_hz: float | None = None, chunk_s: float = DEFAULT_CHUNK_S,
             max_gap: float | None = None, latency: str = "exact", columns: Mapping[str, str] | None = None,
             axis: str | None = None, broker: BrokerOptions | None = None,
             status_topic: str | None = None, opcua: OpcUaOptions | None = None,
             bounds: MessageBounds = DEFAULT_BOUNDS,
             lines_per_interval: int = LINES_PER_INTERVAL, idle_s: float | None = DEFAULT_IDLE_S,
             say: Callable[[str], None] = print, stdin: TextIO | None = None,
             stdout: TextIO | None = None) -> LiveOutcome:
    """Estimate the process current (and force) of a live stream with a model trained on air cuts.

    Parameters
    ----------
    model_path : path-like
        Model file written by ``greybox train``, or a machine model (a directory written by ``greybox train
        --axes``): then one session per axis (:mod:`greybox.live.machine`).
    source : str
        ``-`` (JSON or CSV lines on ``stdin``), ``mqtt[s]://[USER@]HOST[:PORT]/TOPIC`` (wildcards allowed) or
        ``opc.tcp://[USER@]HOST[:PORT]`` (the variables in ``opcua``).
    sink : str, default "-"
        ``-`` (JSON lines on ``stdout``) or ``mqtt[s]://[USER@]HOST[:PORT]/TOPIC``.
    axis_config_path : path-like, optional
        Axis file (TOML): the process force (torque) and the channel names.
    machine_path : path-like, optional
        With a machine model: the machine file (TOML) with each axis's channels and mechanics.
    record_dir : path-like, optional
        Folder of the rolling Parquet recording (a sub-folder per axis of a machine).
    envelope_path : path-like, optional
        Envelope file (``greybox process teach``) of one axis's model: each part of the stream is checked against
        it while it is cut (:mod:`greybox.live.envelope`), its alarms on ``<sink topic>/alarm/envelope``.
    record_s : float, default 60.0
        Log seconds per recording file.
    limits : list of Limit
        Limits on output columns.
    hold_s : float, default 0.0
        Hold time [s] of the limits.
    exit_on_alarm : bool, default False
        End the stream at the first alarm (status :data:`ALARM_STATUS`).
    stats_path : path-like, optional
        JSON file of the counters, rewritten every 10 s and at the end.
    sample_time : float, optional
        Nominal step [s]; default the median step of the first samples.
    tolerance : float, default 0.25
        Time-step tolerance, a fraction of the nominal step.
    cutoff_hz : float, optional
        Derivative-filter cut-off [Hz].
    chunk_s : float, default 60.0
        Chunk length [s] of the model.
    max_gap : float, optional
        Bridge steps up to this many nominal steps by resampling onto the nominal grid, and leave out samples
        holding NaN (as ``greybox predict --resample S --max-gap`` treats a log); default: no resampling.
    latency : {"exact", "low"}, default "exact"
        The derivatives of ``greybox predict`` after their look-ahead, or causal ones at once
        (:mod:`greybox.live.causal`).
    columns : mapping of str to str, optional
        ``{canonical_name: column}`` for message columns not named by the convention (over the axis
        file's channels).
    axis : str, optional
        Axis to take from messages holding several.
    broker : BrokerOptions, optional
        Log-in, TLS, client id, QoS, session and queue of the broker connections.
    status_topic : str, optional
        Topic of the retained status (online/offline, the counters every 10 s); default
        ``<sink topic>/status`` with an MQTT sink.
    opcua : OpcUaOptions, optional
        With an ``opc.tcp://`` source: the variables (``{column: node id}``), the log-in, the security and the
        subscription's intervals.
    bounds : MessageBounds, optional
        The largest message taken (bytes, JSON nesting, samples); a larger one is refused in one line.
    lines_per_interval : int, default 20
        Lines of the stream (messages skipped, samples dropped, gaps, alarms) said per 10 s; those beyond
        are counted and summed up in one line per 10 s. Every line is cut to 300 characters.
    idle_s : float or None, default 0.5
        After this many seconds without a message (on a broker) the samples waiting for their look-ahead are
        estimated as the end of a run, so that the tail of a stream comes out; None: never.
    say : callable, default print
        ``say(line)`` for each line of text.
    stdin, stdout : text file, optional
        The streams of ``-`` (default ``sys.stdin``, ``sys.stdout``).

    Returns
    -------
    LiveOutcome

    Raises
    ------
    GreyboxError
        For a model, axis or envelope file that cannot be read, a source or sink that cannot be opened, a limit on a
        column the output lacks, or messages that do not fit the model (units, kind of axis).
    KeyboardInterrupt
        On SIGTERM or Ctrl-C, after the recording, the sink and the stats are closed.
    """
    from ..models.machine import is_machine_model

    options = dict(sample_time=sample_time, tolerance=tolerance, cutoff_hz=cutoff_hz, chunk_s=chunk_s,
                   max_gap=max_gap, latency=latency)
    watched = [limit.column for limit in limits]
    if envelope_path is not None:
        from .envelope import ENVELOPE_COLUMN

        watched.append(ENVELOPE_COLUMN)
    lines = LineLimiter(say, burst=lines_per_interval)
    if is_machine_model(model_path):
        if envelope_path is not None:
            raise GreyboxError("--envelope applies to one axis's model; a machine model's axes have none")
        build, axes = _machine_session(model_path, machine_path, options, record_dir=record_dir, record_s=record_s,
                                 limits=limits, hold_s=hold_s, columns=columns, source=source, say=lines,
                                 bounds=bounds)
    else:
        if machine_path:
            raise GreyboxError("--machine applies to a machine model (a directory written by 'greybox train "
                               "--axes'); give one axis's mechanics with --axis-config")
        build, axes = _axis_session(model_path, axis_config_path, options, record_dir=record_dir, record_s=record_s,
                              limits=limits, hold_s=hold_s, columns=columns, axis=axis, source=source, say=lines,
                              bounds=bounds, envelope_path=envelope_path), [None]
    ends = open_endpoints(source, sink, options=broker or BrokerOptions(), status_topic=status_topic, axes=axes,
                          limit_columns=watched, opcua=opcua, stdin=stdin or sys.stdin,
                          stdout=stdout or sys.stdout)
    stream, out = ends.stream, ends.out
    try:
        session, kind, recorders = build(out)
        session.warm_up()
    except BaseException:
        ends.close()
        raise
    status, stopped = 0, True
    stats_file = StatsFile(stats_path) if stats_path is not None else None
    deferred = _Deferred()
    try:
        with deferred, settled_memory(), responsive_threads():
            say(f"greybox live: {kind} model {model_path}, reading {'stdin' if source == '-' else stream.address}, "
                f"writing {'stdout' if sink == '-' else out.address}"
                + (f", status on {ends.status.topic}" if ends.status is not None else ""))
            last_stats = last_message = time.monotonic()
            for item in stream:
                lines.tick()
                _sink_changes(out, session, lines)
                if ends.status is not None and ends.status.due():
                    ends.status.publish("online", session.counters())
                if isinstance(item, Idle):
                    quiet = time.monotonic() - last_message
                    if idle_s is not None and quiet >= idle_s:
                        with deferred.held():
                            session.idle(quiet)
                else:
                    last_message = time.monotonic()
                    with deferred.held():
                        session.handle(item)
                    if session.alarmed and exit_on_alarm:
                        status = ALARM_STATUS
                        break
                if stats_file is not None and time.monotonic() - last_stats > STATS_EVERY_S:
                    stats_file.write(session.counters())  # the file written by a thread of its own
                    last_stats = time.monotonic()
            else:
                with deferred.held():
                    session.finish()
            stopped = status != 0
    finally:
        lines.flush()
        try:
            if ends.status is not None:
                ends.status.publish("offline", session.counters())
            session.close(stopped=stopped)
            stream.close()
        finally:
            if stats_file is not None:
                stats_file.close(session.counters())
            for line in session.stats_line().splitlines():
                say(line)
    return LiveOutcome(session.stats, status, [path for recorder in recorders for path in recorder.written])
