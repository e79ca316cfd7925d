"""A teach-in envelope watched on a live stream: the parts found in the stream, each checked while it is cut.

``greybox live --envelope ENVELOPE`` (an envelope of ``greybox process teach``) watches the estimates with an
:class:`EnvelopeWatch`, beside (or instead of) the ``--limit`` watch, through the same three calls
(:meth:`~EnvelopeWatch.check_columns`, :meth:`~EnvelopeWatch.check`, :meth:`~EnvelopeWatch.rearm`).

**Parts.** The stream carries no part counter through the model, so a part starts at the first motion after a
rest of at least the envelope's ``min_rest_s`` seen in the stream, with as much rest before it as the reference
part has before its first motion (the rest seen, lengthened by repeating its first sample where it was shorter:
the reference may have been cut from a log by its part counter, at its loading time); a stream that starts in
motion waits for the next rest. A part ends where the next one starts, or at a gap in the time stamps (a new run).

**While the part is cut.** Each part's samples go to a :class:`~greybox.process.watch.PartWatch` as they are
estimated; a stretch that leaves the band raises an alarm at once (half a smoothing window after it began plus
the estimate's look-ahead and the message's length). A re-levelling envelope is applied with the corrections of
the previous part of the stream (the friction changes little from one part to the next): they are found when
that part ends, by checking it whole (:func:`~greybox.process.check.check_part`) on its own air moves. The first
part of a stream has no part before it: it is checked whole when it ends, not while it is cut.

**When the part ends.** The whole part is checked: its mean load deviation over the cut leaving its limit (a
worn tool, an oversized blank) raises an alarm then. An alarm stays raised until the next part starts (or the
run ends), which clears it.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path
from typing import Callable, Iterable, Mapping

import numpy as np

from ..errors import GreyboxError
from ..process.alignment import STANDSTILL_MM_S
from ..process.check import check_part
from ..process.envelope import Envelope
from ..process.parts import Part
from ..process.watch import PartWatch

__all__ = ["ENVELOPE_COLUMN", "EnvelopeAlarm", "EnvelopeWatch", "Watches", "read_envelope"]

#: The "column" of the envelope's alarms: they go to ``<sink topic>/alarm/envelope``.
ENVELOPE_COLUMN = "envelope"
#: Time [s] a model's estimate takes after a part's first motion to forget the state it started from (the twin's
#: GMS: 0.02 s): a stream's model carries the previous part's state, the envelope's parts started from the
#: model's initial state, so the two read otherwise until then.
MODEL_SETTLE_S = 0.05


@dataclass(frozen=True)
class EnvelopeAlarm:
    """A part leaving its envelope (raised), or the alarm cleared as the next part starts.

    Attributes
    ----------
    part : int
        The part's number in the stream (from 1).
    kind : str
        ``rise``, ``drop``, ``missing cut`` or ``extra cut`` (:data:`~greybox.process.check.KINDS`); empty
        when cleared.
    since_s : float
        Log time [s] where the stretch began (the part's start for the whole part's mean deviation).
    time_s : float
        Log time [s] of the last sample estimated when it was seen.
    whole_part : bool
        Raised by the whole part's mean load deviation at its end, not by a stretch.
    state : {"raised", "cleared"}
        Whether the alarm is raised or cleared.
    column : str
        :data:`ENVELOPE_COLUMN`.
    """

    part: int
    kind: str
    since_s: float
    time_s: float
    whole_part: bool = False
    state: str = "raised"
    column: str = ENVELOPE_COLUMN

    def message(self, seq=None) -> str:
        """The alarm as JSON text, with the wall-clock time it is sent.

        Parameters
        ----------
        seq : object, optional
            The ``"seq"`` of the input message whose samples raised or cleared it.
        """
        wall = datetime.now(timezone.utc).isoformat(timespec="milliseconds")
        return json.dumps({"alarm": ENVELOPE_COLUMN, "state": self.state, "part": self.part, "kind": self.kind,
                           "whole_part": self.whole_part, "since_s": self.since_s, "time_s": self.time_s,
                           "wall_time": wall, "seq": seq})

    def line(self) -> str:
        """The alarm in one line of text."""
        if self.state == "cleared":
            return f"ENVELOPE ALARM CLEARED: part {self.part} ended at t = {self.time_s:.4f} s"
        if self.whole_part:
            return (f"ENVELOPE ALARM: part {self.part} (from t = {self.since_s:.4f} s): its mean load over the cut "
                    f"left the envelope ({self.kind}), seen at its end, t = {self.time_s:.4f} s")
        return (f"ENVELOPE ALARM: part {self.part}: {self.kind} from t = {self.since_s:.4f} s, seen at "
                f"t = {self.time_s:.4f} s")


def read_envelope(path, *, model_path=None, axis_config=None) -> "EnvelopeWatch":
    """The watch of an envelope file for a stream estimated by the model file ``model_path``.

    Parameters
    ----------
    path : path-like
        Envelope file (``greybox process teach``).
    model_path : path-like, optional
        The live model file; an envelope of a model's signal must have been taught with this file (by its
        SHA-256).
    axis_config : AxisConfig, optional
        The live axis file: converts a re-levelled process current to the force.

    Raises
    ------
    GreyboxError
        For an envelope file that cannot be read or is invalid, or taught with another model.
    """
    from ..process.parts import PartSignal

    envelope = Envelope.load(path)
    described = envelope.signal_
    kind = described.get("kind")
    if kind not in ("raw", "current", "force"):
        raise GreyboxError(f"--envelope {Path(path).name}: taught on an unknown signal {kind!r}")
    if kind != "raw":
        if model_path is None or PartSignal(model=str(model_path)).describe()["model_sha256"] \
                != described.get("model_sha256"):
            raise GreyboxError(f"--envelope {Path(path).name}: taught with another model file than "
                               f"{Path(str(model_path)).name} (SHA-256 differs)")
    convert = axis_config.process_load if axis_config is not None else None
    return EnvelopeWatch(envelope, kind=kind, convert=convert, min_rest_s=float(described.get("min_rest_s", 2.0)),
                         name=Path(path).name)


class EnvelopeWatch:
    """The parts of a stream checked against an envelope while they are cut (module docstring).

    Parameters
    ----------
    envelope : Envelope
        A fitted or loaded envelope.
    kind : {"force", "current", "raw"}, default "force"
        The signal it was taught on: the process force (torque), the process current, or the measured current.
    convert : callable, optional
        ``convert(current_A, velocity)``: the force of a process current (a re-levelled force envelope).
    min_rest_s : float, default 2.0
        Shortest rest [s] before a part's first motion.
    name : str, default "envelope"
        The envelope's name in messages.
    """

    def __init__(self, envelope: Envelope, *, kind: str = "force", convert: Callable | None = None,
                 min_rest_s: float = 2.0, name: str = "envelope"):
        self.envelope = envelope
        self.kind = kind
        self.convert = convert
        self.min_rest_s = min_rest_s
        self.name = name
        self._names: dict | None = None
        self._rest = max(1, int(round(min_rest_s / envelope.sample_time_)))
        self._resting = 0  # standstill samples just before the next one (0: in motion, or none seen yet)
        self._recent: dict | None = None  # the last samples, for the rest before a part's first motion
        self._lead = int(np.argmax(np.abs(envelope.reference_velocity_) > STANDSTILL_MM_S))  # the reference's rest
        self._part: dict | None = None  # the part being cut: its number, start, samples, watch
        self._ended: dict | None = None  # a part checked whole at the end of a run, its alarms still raised
        self._parts = 0
        self._corrections: dict | None = None
        self._raised = False
        self._skip_s = envelope.width_ // 2 * envelope.sample_time_ + MODEL_SETTLE_S

    # --------------------------------------------------------------------------------------- columns
    def check_columns(self, columns: Iterable[str]) -> None:
        """Find the columns the envelope watches among the output's (at the start).

        Parameters
        ----------
        columns : iterable of str
            The output columns.

        Raises
        ------
        GreyboxError
            When the output lacks the envelope's signal (e.g. the force without ``--axis-config``).
        """
        columns = list(columns)
        unit = self.envelope.unit_
        role = "_measured_" if self.kind == "raw" else "_process_"
        signal = [name for name in columns if name.endswith(role + unit) and not name.startswith("motor_")]
        velocity = [name for name in columns if name.startswith("velocity_")]
        measured = [name for name in columns if "_measured_" in name]
        if not signal or not velocity or not measured:
            raise GreyboxError(f"--envelope {self.name}: taught on the {self.kind} signal [{unit}], which the "
                               "output lacks" + (" (the force needs --axis-config)" if self.kind == "force" else ""))
        stem, _, effort_unit = measured[0].partition("_measured_")
        names = {"time": "time_s", "velocity": velocity[0], "signal": signal[0]}
        if self.envelope.relevel and self.envelope.scaled_:
            names["level"] = f"{stem}_model_{effort_unit}"
            if self.kind == "force":
                names["current"] = f"{stem}_process_{effort_unit}"
                if self.convert is None:
                    raise GreyboxError(f"--envelope {self.name}: a re-levelled force needs the axis file")
        missing = [name for name in names.values() if name not in columns]
        if missing:
            raise GreyboxError(f"--envelope {self.name}: the output lacks {missing[0]}")
        self._names = names

    # --------------------------------------------------------------------------------------- samples
    def check(self, columns: Mapping[str, np.ndarray]) -> list[EnvelopeAlarm]:
        """The alarms raised and cleared by the next estimates, in time order.

        Parameters
        ----------
        columns : mapping of str to ndarray
            Output columns of consecutive samples of one run.

        Raises
        ------
        GreyboxError
            When the output lacks the envelope's signal (checked on the first call).
        """
        if self._names is None:
            self.check_columns(columns)
        block = {key: np.asarray(columns[name], dtype=float) for key, name in self._names.items()}
        n = block["time"].size
        if n == 0:
            return []
        moving = np.abs(block["velocity"]) > STANDSTILL_MM_S
        index = np.arange(n)
        last_moving = np.maximum.accumulate(np.where(moving, index, -1))
        before = np.concatenate(([-1], last_moving[:-1]))  # the last motion before each sample
        resting = np.where(before >= 0, index - before - 1, self._resting + index)  # standstill samples before it
        starts = np.flatnonzero(moving & (resting >= self._rest)).tolist()
        self._resting = int(n - 1 - last_moving[-1]) if last_moving[-1] >= 0 else self._resting + n
        alarms: list[EnvelopeAlarm] = []
        bounds = sorted({0, *starts, n})
        for a, b in zip(bounds[:-1], bounds[1:]):
            piece = {key: values[a:b] for key, values in block.items()}
            if a in starts:
                alarms += self._end_part(float(piece["time"][0]))
                alarms += self._start_part()
            if self._part is not None:
                alarms += self._feed(piece)
            self._recent = _tail(self._recent, piece, self._lead)
        return alarms

    def rearm(self, time_s: float = math.nan) -> list[EnvelopeAlarm]:
        """A run ended at a gap: the part being cut is checked whole; the next part starts after a rest.

        Parameters
        ----------
        time_s : float, optional
            Time of the last sample of the run that ended [s].

        Returns
        -------
        list of EnvelopeAlarm
            The whole part's alarm, and the alarm cleared.
        """
        alarms = self._end_part(time_s)
        self._resting, self._recent = 0, None
        return alarms

    def end_run(self, time_s: float = math.nan) -> list[EnvelopeAlarm]:
        """The stream ended or went quiet: the part being cut is checked whole; its alarms stay raised until the
        next part starts or the next run re-arms the watch.

        Parameters
        ----------
        time_s : float, optional
            Time of the last sample of the run [s].

        Returns
        -------
        list of EnvelopeAlarm
            The whole part's alarms.
        """
        alarms = self._end_part(time_s, clear=False)
        self._resting, self._recent = 0, None
        return alarms

    def _start_part(self) -> list[EnvelopeAlarm]:
        """Start the next part with the rest before its first motion; the alarms of that rest (none expected)."""
        self._parts += 1
        live = not (self.envelope.relevel and self._corrections is None)
        watch = PartWatch(self.envelope, corrections=self._corrections, skip_s=self._skip_s) if live else None
        lead, self._recent = _padded(self._recent, self._lead, self.envelope.sample_time_), None
        self._part = {"number": self._parts, "samples": [], "watch": watch, "start": math.nan}
        return self._feed(lead) if lead is not None and lead["time"].size else []

    def _watched(self, piece: dict) -> list:
        watch, extra = self._part["watch"], {}
        if "level" in piece:
            extra["level"] = piece["level"]
        if "current" in piece:
            extra.update(current=piece["current"], convert=self.convert)
        return watch.update(piece["velocity"], piece["signal"], **extra)

    def _feed(self, piece: dict) -> list[EnvelopeAlarm]:
        part = self._part
        if not part["samples"]:
            part["start"] = float(piece["time"][0])
        part["samples"].append(piece)
        if part["watch"] is None:
            return []
        breaches = self._watched(piece)
        seen = float(piece["time"][-1])
        out = [EnvelopeAlarm(part["number"], breach.kind, part["start"] + breach.start_s, seen)
               for breach in breaches]
        self._raised |= bool(out)
        return out

    def _end_part(self, time_s: float, clear: bool = True) -> list[EnvelopeAlarm]:
        part, self._part = self._part, None
        if part is None:
            ended, self._ended = self._ended, None
            if ended is None or not clear:
                self._ended = ended
                return []
            self._raised = False
            return [EnvelopeAlarm(ended["number"], "", ended["start"], time_s, state="cleared")]
        alarms = []
        samples = {key: np.concatenate([piece[key] for piece in part["samples"]]) for key in part["samples"][0]}
        if samples["time"].size > 1:
            whole = check_part(self.envelope, Part(
                "stream", part["number"], part["start"], samples["time"] - part["start"], samples["velocity"],
                samples["signal"], level=samples.get("level"), current=samples.get("current"),
                convert=self.convert if "current" in samples else None))
            end = float(samples["time"][-1])
            if part["watch"] is None:  # the stream's first part of a re-levelling envelope: checked now, whole
                moving = np.flatnonzero(np.abs(samples["velocity"]) > STANDSTILL_MM_S)
                settled = samples["time"][moving[0]] - part["start"] + self._skip_s if moving.size else 0.0
                alarms += [EnvelopeAlarm(part["number"], stretch.kind, part["start"] + stretch.start_s, end)
                           for stretch in whole.stretches if stretch.end_s >= settled]
            if whole.mean_kind:
                alarms.append(EnvelopeAlarm(part["number"], whole.mean_kind, part["start"], end, whole_part=True))
            self._corrections = whole.offsets or None
        if not clear:
            if self._raised or alarms:
                self._raised, self._ended = True, part
            return alarms
        if self._raised or alarms:
            alarms.append(EnvelopeAlarm(part["number"], "", part["start"], time_s, state="cleared"))
        self._raised = False
        return alarms


def _padded(lead: dict | None, count: int, step: float) -> dict | None:
    """The rest at the end of ``lead`` (the samples before a part's first motion), lengthened to ``count`` samples by
    repeating its first one (at standstill: not compared, and the whole part's alignment sees no motion there)."""
    if lead is None:
        return lead
    moving = np.flatnonzero(np.abs(lead["velocity"]) > STANDSTILL_MM_S)
    if moving.size:  # the rest only, not the end of the motion before it
        lead = {key: values[moving[-1] + 1:] for key, values in lead.items()}
    if lead["time"].size >= count or lead["time"].size == 0:
        return lead
    missing = count - lead["time"].size
    out = {key: np.concatenate([np.full(missing, values[0]), values]) for key, values in lead.items()}
    out["time"][:missing] = lead["time"][0] - step * np.arange(missing, 0, -1)
    return out


def _tail(recent: dict | None, piece: dict, count: int) -> dict:
    """The last ``count`` samples of ``recent`` followed by ``piece``."""
    joined = piece if recent is None else {key: np.concatenate([recent[key], piece[key]]) for key in piece}
    return {key: values[max(0, values.size - count):] for key, values in joined.items()}


class Watches:
    """Several watches of a session's estimates (``--limit`` and ``--envelope``) as one.

    Parameters
    ----------
    watches : list
        Each with ``check_columns``, ``check`` and ``rearm`` (:class:`~greybox.live.limits.LimitWatch`,
        :class:`EnvelopeWatch`).
    """

    def __init__(self, watches: list):
        self.watches = list(watches)

    def check_columns(self, columns: Iterable[str]) -> None:
        """Each watch's :meth:`check_columns`.

        Parameters
        ----------
        columns : iterable of str
            The output columns.
        """
        columns = list(columns)
        for watch in self.watches:
            watch.check_columns(columns)

    def check(self, columns: Mapping[str, np.ndarray]) -> list:
        """Each watch's alarms, one watch after the other.

        Parameters
        ----------
        columns : mapping of str to ndarray
            Output columns of consecutive samples.
        """
        return [alarm for watch in self.watches for alarm in watch.check(columns)]

    def rearm(self, time_s: float = math.nan) -> list:
        """Each watch's :meth:`rearm`.

        Parameters
        ----------
        time_s : float, optional
            Time of the last sample of the run that ended [s].
        """
        return [alarm for watch in self.watches for alarm in watch.rearm(time_s)]

    def end_run(self, time_s: float = math.nan) -> list:
        """Each watch's ``end_run``.

        Parameters
        ----------
        time_s : float, optional
            Time of the last sample of the run [s].
        """
        return [alarm for watch in self.watches for alarm in watch.end_run(time_s)]
