"""The status messages: online/offline with the counters and the heartbeat, the will of a lost connection."""

from __future__ import annotations

import json
import time

from greybox.live.status import HEARTBEAT_S, StatusTopic, status_message, will_message


class Carrier:
    def __init__(self):
        self.sent = []

    def publish(self, topic, text, retain=False):
        self.sent.append((topic, json.loads(text), retain))
        return True


def test_status_messages_carry_the_state_the_time_and_the_counters():
    message = json.loads(status_message("online", client_id="greybox-line1", counters={"messages": 3},
                                        started=time.time() - 5.0))
    assert message["state"] == "online" and message["client_id"] == "greybox-line1"
    assert message["counters"] == {"messages": 3} and 4.9 <= message["uptime_s"] <= 60.0
    assert message["heartbeat_s"] == HEARTBEAT_S and message["time"].endswith("+00:00")
    assert json.loads(will_message("greybox-line1")) == {"state": "offline", "reason": "connection lost",
                                                         "client_id": "greybox-line1"}


def test_the_status_is_retained_and_due_again_after_the_heartbeat(monkeypatch):
    carrier, now = Carrier(), [100.0]
    monkeypatch.setattr(time, "monotonic", lambda: now[0])
    status = StatusTopic(carrier, "plant/status", "greybox-line1")
    assert status.due()
    status.publish("online", {"messages": 0})
    assert carrier.sent[0][0] == "plant/status" and carrier.sent[0][2] is True
    now[0] += HEARTBEAT_S - 0.1
    assert not status.due()
    now[0] += 0.1
    assert status.due()
