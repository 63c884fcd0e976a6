"""A stepping participant: joins the lockstep, waits for due inputs, steps, acks.

Services write only a `step(tick, inputs)` function; this class owns the protocol of DESIGN.md
§4: membership by a liveliness token, stepping every tick the conductor has granted as soon as
its inputs are complete (a fast participant runs ahead of a slow one, within the window),
Jacobi input release (a sample tagged k is handed over at tick k+1, never earlier), acks every
few ticks, a clean end (`clock/end`), its own faults told. Nothing from the bus is believed
blindly (identity.py, inbox.py): clock messages only from the conductor's session and only if
its clock could send them (`ClockLimits`), samples only from their producer's; refusals are
counted and logged without flooding (rejections.py)."""

from __future__ import annotations

import logging
import queue
import time
from collections.abc import Callable, Sequence

import zenoh

from catabot.bus import codec
from catabot.bus.clock import CONDUCTOR, ClockError, ClockLimits, EndRun, Stream, blames, end_reason
from catabot.bus.grants import Grants
from catabot.bus.identity import Roster, sender_of, shown
from catabot.bus.inbox import Conflict, Inbox, Inputs
from catabot.bus.keys import Keys
from catabot.bus.lanes import Event, Lanes
from catabot.bus.members import Members, claim
from catabot.bus.messages import Ack, End, Tick
from catabot.bus.outputs import Outputs
from catabot.bus.rejections import Rejected, Rejections
from catabot.bus.start_wait import StartWait

log = logging.getLogger("catabot.bus.participant")
WAITED = "waited at tick"  # the fault line `_waited` logs, which the launcher quotes
ORPHAN_GRACE_S = 0.5
LOST = "conductor lost"  # the reason of the End a participant makes when the clock vanished
DROPPED = "dropped"  # ... when a grant names it dropped
VANISHED = "the conductor vanished without an End reaching it: the conductor stopped, or \
this process lost its link or was frozen (the conductor's own error says which)"
MAX_HELD_CLOCK = 64  # clock messages held while the conductor's session is not known yet
StepFn = Callable[[Tick, Inputs], None]
EndFn = Callable[[End, Inputs], None]


class Stopped(ClockError):
    """`run()` was stopped from another thread before the run ended (a client leaving)."""


class Participant(Outputs):
    def __init__(
        self,
        session: zenoh.Session,
        keys: Keys,
        name: str,
        *,
        inputs: Sequence[Stream] = (),
        peers: Sequence[str] = (),
        drain_s: float = 5.0,
        roster: Roster | None = None,
        limits: ClockLimits | None = None,
    ) -> None:
        super().__init__(session)
        self.keys, self.name = keys, name
        self.roster = roster if roster is not None else Roster()
        self.limits = limits
        self.inbox = Inbox(inputs, roster=self.roster, dt_ns=limits.dt_ns if limits else 0)
        claim(session, keys, name, self.roster)  # NameTaken: a second physics stops
        self.peers, self.drain_s = set(peers) - {name}, drain_s
        producers = {stream.producer for stream in self.inbox.streams.values()}
        self.members = Members(keys, self.roster, expected={*peers, *producers, name, CONDUCTOR})
        self.rejections = Rejections(log, name)
        self._grants = Grants(limits=limits, everyone=self.peers | {name})
        self.next_tick, self._acked = 0, -1  # the next tick to step, the last acked
        self._ended = False  # asked the conductor to end the run: no more steps
        self._held_clock: list[Event] = []  # until the conductor's session is known
        self.events = Lanes(trusted=self.roster.knows)  # a stranger's flood: lanes.py
        self._orphaned_at = 0.0
        self._warned_tick, self._met = -1, False  # _met: every peer seen present once
        self._idle_s = limits.idle_s if limits else 1.0
        self._waiting_since = self._check_at = time.monotonic()  # _check_at: next _ack_waiting
        self._start = StartWait(session, keys, name, roster=self.roster, events=self.events,
                                digest=limits.digest if limits else "")  # fmt: skip
        self._subs = [
            session.declare_subscriber(keys.tick(), self._push("tick")),
            session.declare_subscriber(keys.end(), self._push("end")),
            session.liveliness().declare_subscriber(keys.lives(), self._on_live, history=True),
            *(session.declare_subscriber(key, self._push("data")) for key in self.inbox.keys),
        ]
        self._ack = self._publisher(keys.ack(name))
        self._token = session.liveliness().declare_token(keys.live(name, str(session.zid())))

    def _push(self, kind: str) -> Callable[[zenoh.Sample], None]:
        def on_sample(sample: zenoh.Sample) -> None:
            payload = sample.payload  # copied only if its sender's lane has room (lanes.py)
            self.events.offer(kind, str(sample.key_expr), sender_of(sample), len(payload),
                              payload.to_bytes)  # fmt: skip

        return on_sample

    def keep(self, subscriber: zenoh.Subscriber[None]) -> None:
        self._subs.append(subscriber)  # it feeds `events`: undeclared with this participant

    @property
    def granted(self) -> int:  # the last tick granted so far (-1 before the first grant)
        return self._grants.tick

    @property
    def run_id(self) -> str:  # the conductor's run, once a tick of it was believed
        return self._grants.run_id

    def _on_live(self, sample: zenoh.Sample) -> None:
        kind = "join" if sample.kind == zenoh.SampleKind.PUT else "leave"
        self.events.put((kind, str(sample.key_expr), b"", ""))

    @property
    def present(self) -> set[str]:
        return set(self.members.present)

    def run(self, step: StepFn, on_end: EndFn | None = None) -> End:
        """Step every granted tick until the run ends; its End (`LOST`: the conductor vanished)."""
        while True:
            if self._orphaned_at and time.monotonic() - self._orphaned_at > ORPHAN_GRACE_S:
                why = f"{self.name}: {VANISHED}"
                return self._finish(End(self.run_id, self.next_tick - 1, LOST, why), on_end)
            event = self._next()
            if event[0] == "stop":
                raise Stopped(f"{self.name} left the run at tick {self.next_tick}")
            started = time.perf_counter()
            end = self._take(event)
            self.events.spent(event, time.perf_counter() - started)  # a stranger's: budgeted
            if end is not None:
                return self._finish(end, on_end)
            if self.events.dropped:
                self._report_floods()
            self._step_ready(step)
            if event[0] == "idle" or self._grants.repeated or time.monotonic() >= self._check_at:
                self._ack_waiting()  # by the clock too: events without end (junk) held it

    def _take(self, event: Event) -> End | None:
        kind, key, payload, sender = event
        if kind == "data":
            self._take_data(key, payload, sender)
        elif kind == "stray":
            self.rejections.add(key, Rejected("no such stream", payload.decode()))
        elif kind in ("tick", "end"):
            return self._take_clock(event)
        elif kind == "digest" and self.limits is not None:
            self.limits.check_digest(payload.decode(), waiting=True)
        return None

    def _step_ready(self, step: StepFn) -> None:
        """Step every granted tick whose inputs are complete, in order, acking every
        `ack_every` ticks and at the grant's end."""
        grant = self._grants.last
        while grant is not None and self.next_tick <= grant.tick and not self._ended:
            k = self.next_tick
            if not self._ready(k):
                break
            try:
                step(self._grants.tick_of(k), self.inbox.release(k))
            except EndRun as request:
                self._end_before(grant, k, str(request))
                return
            self.next_tick = k + 1
            if (k + 1) % grant.ack_every == 0 or k == grant.tick:
                self._ack_through(grant, k)
            self._waiting_since = time.monotonic()

    def _ack_through(self, grant: Tick, k: int, *, end: str = "") -> None:
        """Ack tick k; `end`: and ask the conductor to end the run after it."""
        self.put(self._ack, codec.encode(Ack(grant.run, k, end=end)))
        self._acked = k

    def _end_before(self, grant: Tick, k: int, reason: str) -> None:
        self._ended = True
        self._ack_through(grant, k - 1, end=end_reason(reason))

    def report_fault(self, why: str) -> None:
        """Tell the conductor why this participant stops (its own fault): every host's cause."""
        if self.run_id and not self._ended:
            self._ended = True
            ack = Ack(self.run_id, self.next_tick - 1, fault=end_reason(why))
            self.put(self._ack, codec.encode(ack))

    def _ack_waiting(self) -> None:
        """Ticks stepped since the last ack wait for inputs (no events for `idle_s`, or the
        run is ending): ack them now, or a missed deadline names whoever waits for data."""
        self._check_at = time.monotonic() + self._idle_s
        grant = self._grants.last
        if grant is None:
            self._start.idle(self.present)
        elif self.next_tick - 1 > self._acked:
            self._ack_through(grant, self.next_tick - 1)

    def _next(self) -> Event:
        """The next event; an End may trail the conductor's token, so allow it a grace."""
        try:
            event = self.events.get(timeout=0.1 if self._orphaned_at else self._idle_s)
        except queue.Empty:
            return ("idle", "", b"", "")
        if event[0] in ("join", "leave"):
            self._membership(event[0], event[1])
        return event

    def _membership(self, kind: str, key: str) -> None:
        name = self.members.token(key, alive=kind == "join")
        if name is None:
            self.rejections.add(key, Rejected(self.members.refusal(key), key))
        elif kind == "leave" and name == CONDUCTOR:
            self._orphaned_at = time.monotonic()
        elif kind == "join":
            self.events.joined(self.roster.zid(name) or "")  # its laned samples first
            self._retry_held(name)

    def _report_floods(self) -> None:
        """Samples a stranger's lane could not hold (lanes.py), counted like any refusal."""
        for sender, (count, key) in self.events.take_dropped().items():
            why = f"from {shown(sender)}, dropped unread: sent faster than they are taken"
            self.rejections.add(key, Rejected("flood", why), count=count)

    def _retry_held(self, name: str) -> None:
        """Samples and clock messages held until `name`'s session was known."""
        for key, rejected in self.inbox.retry_pending(self._horizon()):
            self.rejections.add(key, rejected)
        if name == CONDUCTOR:
            held, self._held_clock = self._held_clock, []
            for event in held:
                self.events.put(event)  # taken again, in order, now that the sender is known

    def _horizon(self) -> int:
        """No sample may be tagged at or past this: the clock cannot have granted it."""
        if self.limits is None:
            return 2**62
        return min(self.next_tick + self.limits.window, self.limits.ticks)

    def _take_data(self, key: str, payload: bytes, sender: str) -> None:
        try:
            self.inbox.add(key, payload, sender=sender, horizon=self._horizon())
        except Conflict as exc:  # the run would depend on which came first: it ends here
            self.rejections.add(key, exc)
            self.report_fault(str(exc))
        except Rejected as exc:
            self.rejections.add(key, exc)

    def _take_clock(self, event: Event) -> End | None:
        """A Tick or End, believed only from the conductor's session (held until that is
        known: before tick 0 nothing from an unknown sender is adopted)."""
        kind, key, payload, sender = event
        if self.roster.zid(CONDUCTOR) is None:
            if len(self._held_clock) < MAX_HELD_CLOCK:
                self._held_clock.append(event)
            return None
        try:
            if not self.members.sender_is(CONDUCTOR, sender):
                raise Rejected("clock message from a stranger", shown(sender))
            if kind == "tick":
                self._take_tick(codec.decode(payload, Tick))
                return self._dropped()
            return self._grants.end(codec.decode(payload, End))
        except codec.CodecError as exc:
            self.rejections.add(key, Rejected("malformed", str(exc)))
        except Rejected as exc:
            self.rejections.add(key, exc)
        return None

    def _take_tick(self, tick: Tick) -> None:
        dry = self.next_tick > self._grants.tick  # it had run dry: a wait begins
        self._grants.take(tick, next_tick=self.next_tick)  # Rejected: the clock cannot send it
        self.inbox.drop_producers(tick.dropped)
        self.peers -= set(tick.dropped)  # a dropped peer that crashed will never be present
        if dry:
            self._waiting_since = time.monotonic()

    def _dropped(self) -> End | None:
        """Its own End once a grant names it dropped (policy drop): a slow stack had stepped
        45 s of queued ticks whose commands nobody took, then heard "completed"."""
        if self._grants.drops(self.name):
            why = f"{self.name} was dropped (clock.policy drop): the run goes on without it"
            return End(self.run_id, self.next_tick - 1, DROPPED, why)
        return None

    def _ready(self, tick: int) -> bool:
        """Every due input in, and each peer seen once (it knows our subscriptions); one gone
        later is the conductor's to judge (a told fault: the others still step its ticks)."""
        missing = self.inbox.missing(tick)
        self._met = self._met or self.peers <= self.present
        if not missing and self._met:
            return True
        if time.monotonic() - self._waiting_since > 5.0 and self._warned_tick != tick:
            self._warned_tick = tick
            log.warning("%s: tick %d still waits for %s (peers absent: %s)", self.name, tick,
                        missing, sorted(self.peers - self.present))  # fmt: skip
        return False

    def _finish(self, end: End, on_end: EndFn | None) -> End:
        """Collect samples due up to the last complete tick, bounded in time."""
        own = blames(end.error, self.name) or end.reason == DROPPED  # its lateness held others
        if end.error and not own:
            self._waited(self.next_tick)
        limit = time.monotonic() + (self.drain_s if not end.error else 1.0)
        while self.inbox.missing(end.tick + 1) and time.monotonic() < limit:
            try:
                event = self.events.get(timeout=max(limit - time.monotonic(), 0))
            except queue.Empty:
                break
            if event[0] == "data":
                self._take_data(event[1], event[2], event[3])
        if not own and (missing := self.inbox.unarrived(end.tick + 1)):  # a link went
            log.warning("%s: the run ended at tick %d without %s", self.name, end.tick, missing)
        if on_end is not None:
            on_end(end, self.inbox.release(end.tick + 1))
        return end

    def _waited(self, tick: int) -> None:
        """Whose data held this participant at a fault (the launcher quotes it in the cause):
        one waiting for a stack that acked a tick without its command looked hung."""
        if missing := self.inbox.missing(tick):
            whose = ", ".join(f"{key} from {self.inbox.streams[key].producer!r}" for key in missing)
            log.error("%s %s %d for %s", self.name, WAITED, tick, whose)

    def stop(self) -> None:
        """`run()` raises `Stopped` at its next event (another thread's: a client leaving)."""
        self.events.put(("stop", "", b"", ""))

    def close(self) -> None:
        self._token.undeclare()
        for sub in self._subs:
            sub.undeclare()
