"""The conductor: owns the clock, publishes ticks, collects acks, ends the run.

Zenoh callbacks only put events on a queue (they must never block); the conductor's
own thread takes them off with a timeout, which is how the per-tick deadline and
liveliness faults are noticed without polling.
"""

from __future__ import annotations

import logging
import queue
import threading
import time
import uuid
from collections.abc import Callable
from dataclasses import dataclass, field

import zenoh

from catabot import codec
from catabot.clock import ClockError, Policy
from catabot.keys import Keys
from catabot.messages import Ack, End, Tick

log = logging.getLogger("catabot.conductor")
CONDUCTOR = "conductor"
BLOCK = zenoh.CongestionControl.BLOCK


@dataclass(frozen=True)
class ClockSpec:
    dt_ns: int
    ticks: int
    participants: tuple[str, ...]
    deadline_s: float = 10.0
    start_timeout_s: float = 60.0
    policy: Policy = Policy.ABORT
    realtime_factor: float | None = None


@dataclass
class Progress:
    tick: int
    stamp_ns: int
    ticks_per_s: float
    realtime_factor: float


@dataclass
class RunResult:
    ticks_done: int
    wall_s: float
    error: str = ""
    dropped: list[str] = field(default_factory=list)
    reason: str = "completed"
    join_s: float = 0.0


class Conductor:
    def __init__(self, session: zenoh.Session, keys: Keys, spec: ClockSpec) -> None:
        self.session, self.keys, self.spec = session, keys, spec
        self.run_id = uuid.uuid4().hex[:12]
        self._created = time.monotonic()
        self.events: queue.SimpleQueue[tuple[str, str, bytes]] = queue.SimpleQueue()
        self.members: set[str] = set()
        self.dropped: list[str] = []
        self._stop_reason = ""
        self._done = 0
        self._tick_pub = session.declare_publisher(keys.tick(), congestion_control=BLOCK)
        self._end_pub = session.declare_publisher(keys.end(), congestion_control=BLOCK)
        self._token = session.liveliness().declare_token(keys.live(CONDUCTOR))
        # Acks arrive on a FIFO channel (no Python callback per ack: the hot path); rare
        # events (a participant leaving, a deadline passing, a stop) go to `events`, and the
        # watchdog thread wakes the tick loop by publishing a poke on the conductor's own ack key.
        self._acks = session.declare_subscriber(keys.acks(), zenoh.handlers.FifoChannel(4096))
        self._poke_key = keys.ack(CONDUCTOR)
        self._poke_pub = session.declare_publisher(self._poke_key)
        self._live = session.liveliness().declare_subscriber(
            keys.lives(), self._on_live, history=True
        )
        self._deadline: float | None = None
        self._closed = threading.Event()
        self._watchdog = threading.Thread(
            target=self._watch, name="conductor-watchdog", daemon=True
        )
        self._watchdog.start()

    def _on_live(self, sample: zenoh.Sample) -> None:
        kind = "join" if sample.kind == zenoh.SampleKind.PUT else "leave"
        self.events.put((kind, str(sample.key_expr), b""))

    def stop(self, reason: str) -> None:
        """Ask the run to end at the next tick boundary (Ctrl-C, a signal)."""
        self._stop_reason = reason
        self.events.put(("stop", "", b""))

    def _watch(self) -> None:
        """Poke the tick loop when an event is pending or the tick's deadline has passed."""
        poked_for: float | None = None
        while not self._closed.wait(0.02):
            deadline = self._deadline
            late = deadline is not None and time.monotonic() > deadline and poked_for != deadline
            if late or (deadline is not None and not self.events.empty()):
                poked_for = deadline if late else poked_for
                self._poke_pub.put(b"")

    # -- run ---------------------------------------------------------------------------

    def run(self, on_progress: Callable[[Progress], None] | None = None) -> RunResult:
        """Wait for every participant, tick to the end; wall time counts from tick 0."""
        joined = start = time.monotonic()
        try:
            self._await_members()
            joined = start = time.monotonic()
            self._tick_loop(on_progress, start)
            error = ""
        except ClockError as exc:
            error = str(exc)
        done = self._done  # complete ticks, also when a fault or a stop cut the run short
        reason = self._stop_reason or ("completed" if not error else "fault")
        self._end_pub.put(codec.encode(End(self.run_id, done - 1, reason, error)))
        wall = time.monotonic() - start
        return RunResult(done, wall, error, list(self.dropped), reason, joined - self._created)

    def _await_members(self) -> None:
        expected = set(self.spec.participants)
        limit = time.monotonic() + self.spec.start_timeout_s
        while not expected <= self.members:
            if self._stop_reason:
                return
            if self._next_event(limit)[0] == "late":
                raise ClockError(self._start_timeout(expected))

    def _start_timeout(self, expected: set[str]) -> str:
        missing = ", ".join(sorted(expected - self.members))
        return f"participant(s) never joined within {self.spec.start_timeout_s:g} s: {missing}"

    def _tick_loop(self, on_progress: Callable[[Progress], None] | None, start: float) -> int:
        last_report, k = start, 0
        for k in range(self.spec.ticks):
            if self._stop_reason:
                return k
            self._pace(k)
            self._publish_tick(k)
            self._await_acks(k)
            self._done = k + 1
            now = time.monotonic()
            if on_progress and now - last_report >= 0.25:
                on_progress(self._progress(k, now - start))
                last_report = now
        if on_progress:
            on_progress(self._progress(self.spec.ticks - 1, time.monotonic() - start))
        return self.spec.ticks

    def _progress(self, k: int, wall: float) -> Progress:
        sim_s = (k + 1) * self.spec.dt_ns / 1e9
        return Progress(k, (k + 1) * self.spec.dt_ns, (k + 1) / max(wall, 1e-9), sim_s / wall)

    def _pace(self, k: int) -> None:
        factor = self.spec.realtime_factor
        if factor:
            if not hasattr(self, "_t0"):
                self._t0 = time.monotonic()
            delay = self._t0 + k * self.spec.dt_ns / 1e9 / factor - time.monotonic()
            if delay > 0:
                time.sleep(delay)

    def _publish_tick(self, k: int) -> None:
        tick = Tick(self.run_id, k, k * self.spec.dt_ns, self.spec.dt_ns, tuple(self.dropped))
        self._tick_pub.put(codec.encode(tick))

    def _await_acks(self, k: int) -> None:
        """Wait until every participant acked tick `k` or was dropped.

        A stop asked meanwhile does not cut the tick short: the tick completes (so every
        participant has the same last tick) and the loop stops at the next boundary.
        """
        waiting = set(self.spec.participants) - set(self.dropped)
        self._check_events(k, waiting)
        self._deadline = time.monotonic() + self.spec.deadline_s
        try:
            while waiting:
                sample = self._acks.recv()
                key = str(sample.key_expr)
                if key != self._poke_key:
                    self._take_ack(k, key, sample.payload.to_bytes(), waiting)
                else:
                    self._check_events(k, waiting)
        finally:
            self._deadline = None

    def _check_events(self, k: int, waiting: set[str]) -> None:
        """Apply pending membership events (a stop is noted in `_stop_reason`) and the deadline."""
        while not self.events.empty():
            self._next_event(0.0)
        for name in sorted(waiting - self.members):
            self._fault(name, f"left the run at tick {k}", waiting)
        if self._deadline is not None and time.monotonic() > self._deadline:
            for name in sorted(waiting):
                self._fault(
                    name, f"missed the {self.spec.deadline_s:g} s deadline of tick {k}", waiting
                )

    def _take_ack(self, k: int, key: str, payload: bytes, waiting: set[str]) -> None:
        try:
            ack = codec.decode(payload, Ack)
        except codec.CodecError as exc:
            log.warning("malformed ack on %s: %s", key, exc)
            return
        if ack.run == self.run_id and ack.tick == k:
            waiting.discard(self.keys.participant_of(key))

    def _fault(self, name: str, what: str, waiting: set[str]) -> None:
        message = f"participant {name!r} {what}"
        if self.spec.policy is Policy.ABORT:
            raise ClockError(message)
        log.error("%s; dropping it and going on (policy drop)", message)
        self.dropped.append(name)
        waiting.discard(name)

    def _next_event(self, deadline: float) -> tuple[str, str, bytes]:
        """Wait for one event ("late" when the deadline passes); membership is tracked here."""
        try:
            event = self.events.get(timeout=max(deadline - time.monotonic(), 0.0))
        except queue.Empty:
            return ("late", "", b"")
        kind, key, _ = event
        if kind == "join":
            self.members.add(self.keys.participant_of(key))
        elif kind == "leave":
            self.members.discard(self.keys.participant_of(key))
        return event

    def close(self) -> None:
        self._closed.set()
        self._watchdog.join()
        self._acks.undeclare()
        self._live.undeclare()
        self._token.undeclare()
