"""A stepping participant: joins the lockstep, waits for due inputs, steps, acks.

Services write only a `step(tick, inputs)` function; this class owns the protocol of
DESIGN.md §4: membership by a liveliness token, stepping every tick the conductor has
granted as soon as its inputs are complete (so a fast participant runs ahead of a slow
one, within the window), Jacobi input release (a sample tagged k is handed over at tick
k+1, never earlier), acks every few ticks, malformed payloads logged with their key and
dropped, and a clean end on `clock/end`.
"""

from __future__ import annotations

import logging
import queue
import time
from collections.abc import Callable, Sequence
from typing import Any

import zenoh

from catabot.bus import codec
from catabot.bus.clock import CONDUCTOR, ClockError, Stream
from catabot.bus.inbox import Inbox, Inputs
from catabot.bus.keys import Keys
from catabot.bus.messages import Ack, End, Message, Tick
from catabot.bus.session import BLOCK

log = logging.getLogger("catabot.bus.participant")
ORPHAN_GRACE_S = 0.5
StepFn = Callable[[Tick, Inputs], None]
EndFn = Callable[[End, Inputs], None]


class Participant:
    def __init__(
        self,
        session: zenoh.Session,
        keys: Keys,
        name: str,
        *,
        inputs: Sequence[Stream] = (),
        peers: Sequence[str] = (),
        drain_s: float = 5.0,
    ) -> None:
        self.session, self.keys, self.name = session, keys, name
        self.inbox = Inbox(inputs)
        self.peers = set(peers) - {name}
        self.drain_s = drain_s
        self.next_tick = 0
        self._grant: Tick | None = None
        self._waiting_since = time.monotonic()  # for the warning about a long wait
        self.events: queue.SimpleQueue[tuple[str, str, bytes]] = queue.SimpleQueue()
        self.present: set[str] = set()
        self.run_id = ""
        self._orphaned_at = 0.0
        self._warned_tick = -1
        self._pubs: dict[str, zenoh.Publisher] = {}
        self._listeners: dict[str, Any] = {}
        self._watched: set[str] = set()
        self._subs = [
            session.declare_subscriber(keys.tick(), self._push("tick")),
            session.declare_subscriber(keys.end(), self._push("end")),
            session.liveliness().declare_subscriber(keys.lives(), self._on_live, history=True),
        ]
        self._subs += [
            session.declare_subscriber(key, self._push("data")) for key in self.inbox.keys
        ]
        self._ack = session.declare_publisher(keys.ack(name), congestion_control=BLOCK)
        self._token = session.liveliness().declare_token(keys.live(name))

    def _push(self, kind: str) -> Callable[[zenoh.Sample], None]:
        def on_sample(sample: zenoh.Sample) -> None:
            self.events.put((kind, str(sample.key_expr), sample.payload.to_bytes()))

        return on_sample

    def _on_live(self, sample: zenoh.Sample) -> None:
        kind = "join" if sample.kind == zenoh.SampleKind.PUT else "leave"
        self.events.put((kind, self.keys.participant_of(str(sample.key_expr)), b""))

    def publish(self, key: str, msg: Message) -> None:
        """Publish an output; lockstep data is never dropped under congestion."""
        self._publisher(key).put(codec.encode(msg))

    def watched(self, key: str) -> bool:
        """Whether any subscriber matches `key` now: outputs only observers read can skip
        their encoding while nobody looks. Kept current by a Zenoh matching listener per
        key (asking Zenoh each tick cost ~25 us a key under load)."""
        return bool(self.watched_among([key]))

    def watched_among(self, keys: Sequence[str]) -> list[int]:
        """Indices of the `keys` someone subscribes to now; one set test a tick while nobody
        watches (asking key by key cost physics 0.17 ms a tick with 100 boats)."""
        for key in keys:
            if key not in self._listeners:
                self._listen(key)
        if not self._watched:
            return []
        return [i for i, key in enumerate(keys) if key in self._watched]

    def _listen(self, key: str) -> None:
        pub = self._publisher(key)

        def on_change(status: Any) -> None:
            (self._watched.add if status.matching else self._watched.discard)(key)

        self._listeners[key] = pub.declare_matching_listener(on_change)
        on_change(pub.matching_status)  # the listener reports changes only

    def _publisher(self, key: str) -> zenoh.Publisher:
        pub = self._pubs.get(key)
        if pub is None:
            pub = self._pubs[key] = self.session.declare_publisher(key, congestion_control=BLOCK)
        return pub

    # -- the loop ------------------------------------------------------------------------

    def run(self, step: StepFn, on_end: EndFn | None = None) -> End:
        """Step every granted tick until the conductor ends the run; returns the end message."""
        while True:
            kind, key, payload = self._next()
            if kind == "data":
                self._take_data(key, payload)
            elif kind == "tick":
                self._take_tick(payload)
            elif kind == "end":
                end = self._take_end(payload)
                if end is not None:
                    return self._finish(end, on_end)
            self._step_ready(step)

    def _step_ready(self, step: StepFn) -> None:
        """Step every granted tick whose inputs are complete, in order, acking every
        `ack_every` ticks and at the grant's end."""
        grant = self._grant
        while grant is not None and self.next_tick <= grant.tick:
            k = self.next_tick
            if not self._ready(k):
                break
            step(self._tick_of(grant, k), self.inbox.release(k))
            self.next_tick = k + 1
            if (k + 1) % grant.ack_every == 0 or k == grant.tick:
                self._ack.put(codec.encode(Ack(grant.run, k)))
            self._waiting_since = time.monotonic()

    @staticmethod
    def _tick_of(grant: Tick, k: int) -> Tick:
        stamp = grant.stamp_ns - (grant.tick - k) * grant.dt_ns
        return Tick(grant.run, k, stamp, grant.dt_ns, grant.dropped, grant.ack_every)

    def _next(self) -> tuple[str, str, bytes]:
        """The next event; an End may trail the conductor's token, so allow it a grace."""
        if self._orphaned_at and time.monotonic() - self._orphaned_at > ORPHAN_GRACE_S:
            raise ClockError(f"{self.name}: the conductor disappeared without ending the run")
        try:
            event = self.events.get(timeout=0.1 if self._orphaned_at else 1.0)
        except queue.Empty:
            return ("idle", "", b"")
        kind, who, _ = event
        if kind == "join":
            self.present.add(who)
        elif kind == "leave":
            self.present.discard(who)
            if who == CONDUCTOR:
                self._orphaned_at = time.monotonic()
        return event

    def _take_data(self, key: str, payload: bytes) -> None:
        try:
            self.inbox.add(key, payload)
        except codec.CodecError as exc:
            log.warning("%s: dropped malformed payload on %s: %s", self.name, key, exc)

    def _take_tick(self, payload: bytes) -> None:
        try:
            tick = codec.decode(payload, Tick)
        except codec.CodecError as exc:
            log.warning("%s: malformed tick: %s", self.name, exc)
            return
        if not self.run_id:
            self.run_id = tick.run
        if tick.run != self.run_id:
            return
        self.inbox.drop_producers(tick.dropped)
        self.peers -= set(tick.dropped)  # a dropped peer that crashed will never be present
        if self._grant is None or tick.tick >= self._grant.tick:
            if self._grant is None or self.next_tick > self._grant.tick:
                self._waiting_since = time.monotonic()  # it had run dry: a wait begins
            self._grant = tick  # grants only grow; a repeat carries a new dropped list

    def _take_end(self, payload: bytes) -> End | None:
        try:
            end = codec.decode(payload, End)
        except codec.CodecError as exc:
            log.warning("%s: malformed end: %s", self.name, exc)
            return None
        return end if not self.run_id or end.run == self.run_id else None

    def _ready(self, tick: int) -> bool:
        """Peers seen (so they know our subscriptions) and every due input arrived."""
        missing = self.inbox.missing(tick)
        if not missing and self.peers <= self.present:
            return True
        if time.monotonic() - self._waiting_since > 5.0 and self._warned_tick != tick:
            self._warned_tick = tick
            log.warning(
                "%s: tick %d still waits for %s (peers absent: %s)",
                self.name,
                tick,
                missing,
                sorted(self.peers - self.present),
            )
        return False

    def _finish(self, end: End, on_end: EndFn | None) -> End:
        """Collect samples due up to the last complete tick, bounded in time."""
        limit = time.monotonic() + (self.drain_s if not end.error else 1.0)
        while self.inbox.missing(end.tick + 1) and time.monotonic() < limit:
            try:
                kind, key, payload = self.events.get(timeout=max(limit - time.monotonic(), 0))
            except queue.Empty:
                break
            if kind == "data":
                self._take_data(key, payload)
        if self.inbox.missing(end.tick + 1):
            log.warning(
                "%s: run ended without samples from %s", self.name, self.inbox.missing(end.tick + 1)
            )
        if on_end is not None:
            on_end(end, self.inbox.release(end.tick + 1))
        return end

    def close(self) -> None:
        self._token.undeclare()
        for sub in self._subs:
            sub.undeclare()
