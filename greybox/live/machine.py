"""A machine's stream: one live session per axis, fed from one topic per axis or from messages of every axis.

A message whose MQTT topic ends in an axis name (``axis/X``, ``machine1/Y``) holds that axis's columns with
their plain names (``position_mm``, ...) and goes to that axis's session. Any other message holds the
columns of several axes, named ``<axis>_<quantity>_<unit>`` (``X_position_mm``, ``Y_current_A``, ...; the
machine file's channel names map others) and feeds every axis it names. Each axis's estimates carry
``"axis"`` and go to ``<TOPIC>/<axis>`` on an MQTT sink.
"""

from __future__ import annotations

from typing import Callable, Mapping

from .messages import DEFAULT_BOUNDS, Decoder, MessageBounds, MessageError
from .session import LiveSession
from .sources import ConnectionChange, Received
from .stats import LiveStats

__all__ = ["MachineSession"]


class MachineSession:
    """The sessions of a machine's axes, fed from one source.

    Parameters
    ----------
    sessions : mapping of str to LiveSession
        One session per axis (each with ``subtopic`` its axis name).
    say : callable
        ``say(line)`` for the lines of the machine (messages no axis takes, the broker connection).
    bounds : MessageBounds, optional
        The largest message taken.

    Attributes
    ----------
    stats : LiveStats
        The counters of the messages (received, rejected) and of the broker connection.
    """

    def __init__(self, sessions: Mapping[str, LiveSession], *, say: Callable[[str], None],
                 bounds: MessageBounds = DEFAULT_BOUNDS):
        self.sessions = dict(sessions)
        self.say = say
        self.stats = LiveStats()
        self._decoder = Decoder(bounds)

    @property
    def alarmed(self) -> bool:
        """Whether any axis raised an alarm."""
        return any(session.alarmed for session in self.sessions.values())

    def handle(self, item: Received | ConnectionChange) -> None:
        """Take one item of the source.

        Parameters
        ----------
        item : Received or ConnectionChange
            A message, or a change of the broker connection.
        """
        if isinstance(item, ConnectionChange):
            self.stats.disconnections += 0 if item.connected else 1
            for index, session in enumerate(self.sessions.values()):
                session.connection(item, quiet=index > 0)
            return
        self.stats.messages += 1
        try:
            decoded = self._decoder.decode(item.payload)
        except MessageError as exc:
            self.stats.rejected += 1
            self.say(f"{item.name}: skipped: {exc}")
            return
        if decoded is None:
            return
        columns, seq = decoded
        own = item.topic.rsplit("/", 1)[-1] if item.topic else ""
        if own in self.sessions:
            self.sessions[own].take(columns, seq, name=item.name, select=False)
            return
        prefixes = {str(name).split("_", 1)[0] for name in columns}
        axes = [axis for axis, session in self.sessions.items() if axis in prefixes or session.mapping]
        if not axes:
            self.stats.rejected += 1
            self.say(f"{item.name}: skipped: no column of the axes {', '.join(self.sessions)} "
                     "(name them <axis>_<quantity>_<unit>, or publish each axis on a topic ending in its name)")
            return
        for axis in axes:
            self.sessions[axis].take(columns, seq, name=item.name)

    def warm_up(self) -> None:
        """Load every axis's compiled kernels before the stream starts (:meth:`LiveSession.warm_up`)."""
        for session in self.sessions.values():
            session.warm_up()

    def finish(self) -> None:
        """The end of the stream, for every axis."""
        for session in self.sessions.values():
            session.finish()

    def idle(self, idle_s: float) -> None:
        """The stream went quiet, for every axis (:meth:`LiveSession.idle`).

        Parameters
        ----------
        idle_s : float
            Seconds since the last message.
        """
        for session in self.sessions.values():
            session.idle(idle_s)

    def close(self, *, stopped: bool = False) -> None:
        """Close every axis's recording and the sink.

        Parameters
        ----------
        stopped : bool, default False
            The command was stopped (see :meth:`LiveSession.close`).
        """
        for session in self.sessions.values():
            session.close(stopped=stopped)

    def stats_line(self) -> str:
        """The counters: one line for the machine's messages, then one per axis."""
        lines = [f"stats: {self.stats.messages} messages ({self.stats.rejected} rejected by every axis)"]
        lines += [f"{axis} {session.stats_line()}" for axis, session in self.sessions.items()]
        return "\n".join(lines)

    def counters(self) -> dict:
        """The counters of the machine and of each axis as they are now, JSON-able."""
        return {**self.stats.to_dict(),
                "axes": {axis: session.current_stats().to_dict() for axis, session in self.sessions.items()}}
