"""What a client observes of a run without stepping: the newest sample of a stream, the run's
end, the conductor's presence.

Samples arrive on Zenoh's threads and are checked there, as a participant checks them
(catabot/bus/inbox.py): the exact key, the producer's session (the roster from `world/info`,
completed by liveliness tokens), the content; a refused one is counted and logged once a
second per key and reason, never handed to the stack. Waiting for a sample is bounded by a
timeout and ends early when the run ends, so no wait can hang.
"""

from __future__ import annotations

import contextlib
import logging
import threading
import time
from collections.abc import Callable
from typing import Any

import zenoh

from catabot.bus import codec
from catabot.bus.clock import CONDUCTOR, Stream
from catabot.bus.identity import Roster, sender_of, shown
from catabot.bus.inbox import checked
from catabot.bus.keys import Keys
from catabot.bus.members import Members
from catabot.bus.messages import End, Message
from catabot.bus.participant import ORPHAN_GRACE_S
from catabot.bus.rejections import Rejected, Rejections
from catabot.client.errors import NoData, RunEnded

log = logging.getLogger("catabot.client")
Callback = Callable[[Any], None]


class Watch:
    """The run's end and its members, for every wait of one client."""

    def __init__(self, session: zenoh.Session, keys: Keys, roster: Roster) -> None:
        self.session, self.keys = session, keys
        self.members = Members(keys, roster)
        self.rejections = Rejections(log, "client")
        self.changed = threading.Condition()  # notified on every sample, end and leave
        self.end: End | None = None
        self.gone_at = 0.0  # when the conductor's token vanished (0: it has not)
        self.ticking = False  # a stack of this client has stepped a tick: the run is going
        self._subs = [
            session.declare_subscriber(keys.end(), self._on_end),
            session.liveliness().declare_subscriber(keys.lives(), self._on_live, history=True),
        ]

    def _on_live(self, sample: zenoh.Sample) -> None:
        alive = sample.kind == zenoh.SampleKind.PUT
        with self.changed:
            name = self.members.token(str(sample.key_expr), alive=alive)
            if name == CONDUCTOR and not alive:
                self.gone_at = time.monotonic()
            self.changed.notify_all()

    def _on_end(self, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        try:
            if not self.members.sender_is(CONDUCTOR, sender_of(sample)):
                raise Rejected("clock message from a stranger", shown(sender_of(sample)))
            end = codec.decode(sample.payload.to_bytes(), End)
        except codec.CodecError as exc:
            self.rejections.add(key, Rejected("malformed", str(exc)))
            return
        except Rejected as exc:
            self.rejections.add(key, exc)
            return
        with self.changed:
            self.end = end
            self.changed.notify_all()

    def ended(self) -> RunEnded | None:
        """The error a waiting stack gets once the run is over (None while it runs). The
        End may trail the conductor's token on another route: a vanished conductor counts
        only after the participant's grace (ORPHAN_GRACE_S)."""
        if self.end is not None:
            e = self.end
            why = f": {e.error}" if e.error else ""
            return RunEnded(f"the run of world {self.keys.world!r} ended at tick {e.tick} "
                            f"({e.reason}{why})", e)  # fmt: skip
        if self.gone_at and time.monotonic() - self.gone_at > ORPHAN_GRACE_S:
            return RunEnded(f"the conductor of world {self.keys.world!r} vanished without "
                            "ending the run")  # fmt: skip
        return None

    def subscribe(self, stream: Stream, callback: Callback) -> zenoh.Subscriber:
        """`callback(message)` for every sample of `stream` from its producer that passes
        its checks (on a Zenoh thread: keep it short)."""

        def on_sample(sample: zenoh.Sample) -> None:
            key = str(sample.key_expr)
            try:
                if key != stream.key:
                    raise Rejected("not a stream key", key)
                sender = sender_of(sample)
                if stream.producer != "external" and not self.members.sender_is(
                    stream.producer, sender
                ):
                    raise Rejected("not from its producer", shown(sender))
                msg = checked(sample.payload.to_bytes(), stream)
            except Rejected as exc:
                self.rejections.add(key, exc)
                return
            callback(msg)

        sub = self.session.declare_subscriber(stream.key, on_sample)
        self._subs.append(sub)
        return sub

    def unsubscribe(self, sub: zenoh.Subscriber) -> None:
        if sub in self._subs:
            self._subs.remove(sub)
            with contextlib.suppress(zenoh.ZError):
                sub.undeclare()

    def close(self) -> None:
        for sub in self._subs:
            with contextlib.suppress(zenoh.ZError):  # the session is already closed
                sub.undeclare()
        self._subs = []


class Latest:
    """The newest message of one stream, and a wait for it bounded by a timeout and the run."""

    def __init__(self, watch: Watch, stream: Stream, what: str) -> None:
        self.watch, self.what = watch, what
        self.message: Message | None = None
        self.count = 0
        self._callbacks: list[Callback] = []
        self.sub = watch.subscribe(stream, self._on)

    def _on(self, msg: Message) -> None:
        with self.watch.changed:
            self.message = msg
            self.count += 1
            self.watch.changed.notify_all()
        for callback in list(self._callbacks):
            callback(msg)

    def add(self, callback: Callback) -> None:
        self._callbacks.append(callback)

    def wait(self, timeout_s: float) -> Message:
        """The newest message; waits up to `timeout_s` for the first one. RunEnded once the
        run is over (nothing newer will come); NoData on the timeout."""
        limit = time.monotonic() + timeout_s
        with self.watch.changed:
            while True:
                ended = self.watch.ended()
                if ended is not None:
                    raise ended  # what was newest is stale now: nothing more will come
                if self.message is not None:
                    return self.message
                left = limit - time.monotonic()
                if left <= 0:
                    raise NoData(
                        f"no {self.what} within {timeout_s:g} s (has the run started? a "
                        "lockstep run waits for its external participants before tick 0)"
                    )
                self.watch.changed.wait(min(left, 0.25))
