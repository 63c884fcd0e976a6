"""The conductor hears its own clock: a Tick or End on its keys that it did not send is forged.

A sample's sender is the source info it states, which any process on the mesh can copy from a
sample it received (identity.py). A trial posed as the conductor: a forged Tick carrying a
5 m/s current changed every recorded state and the run ended "completed" without a word; a
forged End stopped every participant, and the run's error blamed the network. The conductor
now subscribes to its own `clock/tick` and `clock/end` and compares each sample claiming its
session with what it sent: one it did not send ends the run as a fault that says so. This
detects, it does not prevent (a participant may have taken the forgery first): only the
secure profile's access control keeps others off the clock's keys."""

from __future__ import annotations

import queue
from collections import deque
from typing import Any

import zenoh

from catabot.bus.identity import sender_of
from catabot.bus.keys import Keys
from catabot.bus.outputs import Outputs

SENT = 1024  # the clock's last payloads, compared with what it hears (its own arrive at once)
FORGED = "{what} the conductor did not send reached {key}, in its session's name: a process \
on this mesh poses as the conductor, so the run's data cannot be trusted (on a network or \
with processes you do not trust, use the secure profile: README, Distributed runs)"


class ClockOutputs(Outputs):
    """The conductor's outputs; `forged` is the first forgery heard ("" while none)."""

    def __init__(self, session: zenoh.Session, keys: Keys, events: queue.SimpleQueue[Any]) -> None:
        """`events`: the conductor's queue, poked so that its loop wakes to a forgery."""
        super().__init__(session)
        self.keys, self.events, self.forged = keys, events, ""
        self._zid = str(session.zid())
        self._sent: deque[bytes] = deque(maxlen=SENT)
        self._subs = [session.declare_subscriber(k, self._heard) for k in (keys.tick(), keys.end())]

    def put(self, pub: zenoh.Publisher, payload: bytes) -> None:
        self._sent.append(payload)  # before the put: its own sample arrives within it
        super().put(pub, payload)

    def _heard(self, sample: zenoh.Sample) -> None:
        if self.forged or sender_of(sample) != self._zid:
            return  # a stranger's: refused by every participant, and counted there
        payload = sample.payload.to_bytes()
        if payload != self._sent[-1] and payload not in self._sent:  # the last, nearly always
            what = "a Tick" if str(sample.key_expr) == self.keys.tick() else "an End"
            self.forged = FORGED.format(what=what, key=self.keys.relative(str(sample.key_expr)))
            self.events.put(("forged", str(sample.key_expr), b""))

    def close(self) -> None:
        for sub in self._subs:
            sub.undeclare()
