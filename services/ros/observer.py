"""The gateway outside the lockstep (the default): a plain subscriber of the world's streams
that never holds the clock.

The conductor does not wait for an observer, so the simulation runs at its own pace whatever
ROS does. It subscribes only to the streams someone on the ROS side wants (`wanted`, asked
again at every wake-up): with nobody listening it receives nothing and costs the run
nothing. Zenoh callbacks only append the sample to a bounded queue per key and wake the
gateway's thread; when the gateway falls behind, the oldest samples of a key are dropped
(counted, logged) instead of growing memory or pushing back on the publishers. The run ends
with `clock/end`; a conductor whose token vanishes without one ends it too (ClockError).

Like every process on the bus it believes nothing for its key alone (DESIGN.md §4a): a
sample must arrive on exactly one of its streams, from that stream's producer's session when
the roster names it, decode, and pass the stream's content check; an `End` must come from
the conductor's session. Refusals are counted (`rejections`), never raised into the gateway.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from typing import Any

import zenoh

from catabot.bus import codec
from catabot.bus.clock import CONDUCTOR, ClockError, Stream
from catabot.bus.identity import Roster, sender_of
from catabot.bus.inbox import checked
from catabot.bus.keys import Keys
from catabot.bus.messages import BodyStates, CameraFrame, End, LidarScan, Message, Tick
from catabot.bus.participant import VANISHED, EndFn, StepFn
from catabot.bus.rejections import Rejected, Rejections
from catabot.bus.vanished import ConductorWatch

log = logging.getLogger("ros.observer")
DEPTH = 100  # samples held per key: a simulated second of states at 10 ms ticks
BULKY_DEPTH = 4  # LiDAR scans and camera frames are hundreds of kB to megabytes each
BULKY = (CameraFrame, LidarScan)
ORPHAN_GRACE_S = 1.0
WARN_EVERY_S = 1.0


class Observer:
    def __init__(
        self,
        session: zenoh.Session,
        keys: Keys,
        streams: Sequence[Stream],
        wanted: Callable[[], frozenset[str]],
        wake: threading.Event,
        *,
        roster: Roster | None = None,
        rejections: Rejections | None = None,
    ) -> None:
        self.keys, self.wake, self.session = keys, wake, session
        self.roster = roster if roster is not None else Roster()
        self.rejections = rejections if rejections is not None else Rejections(log, "ros")
        self._wanted, self._pace = wanted, keys.world_states()
        self._data: dict[str, Any] = {}  # key -> subscriber, for the keys wanted now
        self._streams = {s.key: s for s in streams}
        self._held = {
            s.key: deque[bytes](maxlen=BULKY_DEPTH if s.message in BULKY else DEPTH)
            for s in streams
        }
        self._dropped = dict.fromkeys(self._held, 0)
        self._warned = dict.fromkeys(self._held, 0.0)
        self._end: bytes | None = None
        self._refused: list[tuple[str, Rejected]] = []  # from Zenoh's threads, counted here
        self._latest = Tick("", -1, 0, 0)
        self._conductor = ConductorWatch(session, keys, self.roster, on_left=wake.set)
        self._subs = [session.declare_subscriber(keys.end(), self._on_end),
                      self._conductor.subscriber]  # fmt: skip

    def _on_data(self, sample: zenoh.Sample) -> None:
        """Queue the sample; wake the gateway for the states (every tick: the pace), or for
        anything while the states are not wanted (one wake-up a tick, not one a sample)."""
        key = str(sample.key_expr)
        held = self._held.get(key)
        if held is None:
            self._refused.append((key, Rejected("not a stream key", repr(key))))
            return
        producer = self.roster.zid(self._streams[key].producer)
        if producer is not None and sender_of(sample) != producer:
            self._refused.append((key, Rejected("not from its producer", sender_of(sample))))
            return
        if len(held) == held.maxlen:
            self._dropped[key] += 1
        held.append(sample.payload.to_bytes())
        if key == self._pace or self._pace not in self._data:
            self.wake.set()

    def _on_end(self, sample: zenoh.Sample) -> None:
        conductor = self.roster.zid(CONDUCTOR)
        if conductor is not None and sender_of(sample) != conductor:
            self._refused.append((str(sample.key_expr), Rejected("end not from the conductor")))
            return
        self._end = sample.payload.to_bytes()
        self.wake.set()

    def run(self, step: StepFn, on_end: EndFn | None = None) -> End:
        """Hand `step` what arrived, as it arrives, until the run ends."""
        while True:
            self._subscribe(self._wanted())
            self.wake.wait(timeout=0.2)
            self.wake.clear()
            end = self._ended()
            if end is not None:
                if on_end is not None:
                    on_end(end, self._drain())
                return end
            step(self._latest, self._drain())

    def _subscribe(self, wanted: frozenset[str]) -> None:
        """Subscribe to the streams wanted now, and only to those."""
        for key in [k for k in self._data if k not in wanted]:
            self._data.pop(key).undeclare()
        for key in sorted(wanted - self._data.keys()):
            self._data[key] = self.session.declare_subscriber(key, self._on_data)

    def _ended(self) -> End | None:
        if self._end is not None:
            try:
                return codec.decode(self._end, End)
            except codec.CodecError as exc:
                log.warning("malformed end of run ignored: %s", exc)
                self._end = None
        if self._conductor.gone(ORPHAN_GRACE_S):
            raise ClockError(f"ros: {VANISHED}")
        return None

    def _drain(self) -> dict[str, list[Message]]:
        """Every held sample, decoded, per key in tick order; malformed ones logged."""
        out: dict[str, list[Message]] = {}
        while self._refused:
            self.rejections.add(*self._refused.pop(0))
        for key, held in self._held.items():
            msgs = []
            while held:
                try:
                    msgs.append(checked(held.popleft(), self._streams[key]))
                except Rejected as exc:
                    self.rejections.add(key, exc)
            if msgs:
                out[key] = msgs
                self._note(msgs[-1])
            now = time.monotonic()
            if self._dropped[key] and now - self._warned[key] > WARN_EVERY_S:
                log.warning("fell behind on %s: %d samples dropped", key, self._dropped[key])
                self._dropped[key], self._warned[key] = 0, now
        return out

    def _note(self, msg: Message) -> None:
        """The newest states give the gateway its tick (an observer gets no `Tick`)."""
        if isinstance(msg, BodyStates) and msg.tick >= self._latest.tick:
            self._latest = Tick("", msg.tick, msg.stamp_ns, 0)

    def close(self) -> None:
        for sub in [*self._subs, *self._data.values()]:
            sub.undeclare()
