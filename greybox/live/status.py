"""The status of a running ``greybox live`` on its broker: online or offline, with the counters, retained.

The status topic (``<sink topic>/status`` by default) holds one retained message: ``"online"`` with the
counters, rewritten every :data:`HEARTBEAT_S` seconds (a monitor takes a message older than that for a
service that hangs); ``"offline"`` when the command ends; and, published by the broker as the connection's
will, ``"offline"`` with the reason ``"connection lost"`` when the process dies or the network goes.
"""

from __future__ import annotations

import json
import time
from datetime import datetime, timezone

__all__ = ["HEARTBEAT_S", "status_message", "will_message", "StatusTopic"]

#: Seconds between two status messages while the command runs.
HEARTBEAT_S = 10.0


def _now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="milliseconds")


def status_message(state: str, *, client_id: str, counters: dict, started: float) -> str:
    """The JSON text of one status message.

    Parameters
    ----------
    state : {"online", "offline"}
        The service's state.
    client_id : str
        The client id of the command (without ``-in`` or ``-out``).
    counters : dict
        The counters (:meth:`greybox.live.stats.LiveStats.to_dict`).
    started : float
        When the command started, ``time.time()`` [s].
    """
    return json.dumps({"state": state, "time": _now(), "client_id": client_id,
                       "uptime_s": round(time.time() - started, 3), "heartbeat_s": HEARTBEAT_S, "counters": counters})


def will_message(client_id: str) -> str:
    """The JSON text the broker publishes when the connection is lost without a goodbye.

    Parameters
    ----------
    client_id : str
        The client id of the command.
    """
    return json.dumps({"state": "offline", "reason": "connection lost", "client_id": client_id})


class StatusTopic:
    """The retained status of the command on its broker, published through the sink's or the source's connection.

    Parameters
    ----------
    carrier : Connection
        The connection that publishes it (the sink's or the source's; its will is :func:`will_message` on
        ``topic``).
    topic : str
        The status topic.
    client_id : str
        The command's client id.

    Attributes
    ----------
    last_s : float
        When the last status went out, ``time.monotonic()`` [s].
    """

    def __init__(self, carrier, topic: str, client_id: str):
        self.carrier = carrier
        self.topic = topic
        self.client_id = client_id
        self.started = time.time()
        self.last_s = -float("inf")

    def publish(self, state: str, counters: dict) -> None:
        """Publish the state with the counters (retained).

        Parameters
        ----------
        state : {"online", "offline"}
            The state.
        counters : dict
            The counters.
        """
        self.carrier.publish(self.topic, status_message(state, client_id=self.client_id, counters=counters,
                                                        started=self.started), retain=True)
        self.last_s = time.monotonic()

    def due(self) -> bool:
        """Whether a heartbeat is due (:data:`HEARTBEAT_S` since the last status)."""
        return time.monotonic() - self.last_s >= HEARTBEAT_S
