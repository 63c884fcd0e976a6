"""The conductor: owns the clock, publishes ticks, collects acks, ends the run.

Zenoh callbacks only put events on a queue (they must never block); the conductor's own thread
takes them off with a timeout: how the deadline and liveliness faults are noticed unpolled."""

from __future__ import annotations

import logging
import queue
import threading
import time
import uuid
from collections.abc import Callable

import zenoh

from catabot.bus import clock
from catabot.bus.ack_check import checked_ack
from catabot.bus.clock import CONDUCTOR, ClockError, ClockSpec, Policy, Progress, RunResult
from catabot.bus.clock_watch import ClockOutputs
from catabot.bus.identity import Roster
from catabot.bus.keys import Keys
from catabot.bus.members import Members, claim
from catabot.bus.messages import Ack, End, Tick
from catabot.bus.rejections import Rejected, Rejections
from catabot.bus.session import LEASE_MS
from catabot.bus.settings import Schedule

log = logging.getLogger("catabot.bus.conductor")
WAITING_NOTE_S = 5.0  # how often the log names who has not joined yet
GONE_GRACE_S = 0.2  # after a participant's token goes, for others gone with it
WORDS_S = 0.6  # how long (from its token going) its fault may still come
LEFT = "left the run"  # a participant's token went without its words
BEFORE = " before it stepped one (its own log says why)"
SILENT = f" without a word: its process ended, or stopped answering for {LEASE_MS / 1000:g} s \
(killed, frozen, or its link lost)"


class Conductor:
    def __init__(
        self,
        session: zenoh.Session,
        keys: Keys,
        spec: ClockSpec,
        *,
        roster: Roster | None = None,
        settings: Schedule | None = None,
    ) -> None:
        self.session, self.keys, self.spec = session, keys, spec
        self.settings = settings if settings is not None else Schedule(ticks=spec.ticks)
        self.run_id, self._created = uuid.uuid4().hex[:12], time.monotonic()
        self.events: queue.SimpleQueue[tuple[str, str, bytes]] = queue.SimpleQueue()
        roster = roster if roster is not None else Roster()
        claim(session, keys, CONDUCTOR, roster)  # NameTaken: a second conductor stops
        self._members = Members(keys, roster, expected={*spec.participants, CONDUCTOR})
        self.rejections = Rejections(log, CONDUCTOR)
        self.dropped: dict[str, str] = {}  # name: why (policy drop)
        self._left: set[str] = set()  # dropped for a token gone without words
        self._stop_reason = ""
        self._end_at: int | None = None  # the last tick, when a participant ended the run
        self._told = ""  # the fault a participant told (Ack.fault): the run's error
        self._done, self._granted = 0, -1  # ticks every active one acked; the last granted
        self._acked = {name: -1 for name in spec.participants}
        self._t0, self._out = self._created, ClockOutputs(session, keys, self.events)  # forged?
        self._token = session.liveliness().declare_token(keys.live(CONDUCTOR, str(session.zid())))
        # Acks on a FIFO channel (no Python callback per ack); rare events (one leaving, a stop)
        # to `events`: the watchdog wakes the loop with a poke on the conductor's own ack key.
        self._acks = session.declare_subscriber(keys.acks(), zenoh.handlers.FifoChannel(4096))
        self._poke_key = keys.ack(CONDUCTOR)
        self._poke_pub = session.declare_publisher(self._poke_key)
        self._live = session.liveliness().declare_subscriber(
            keys.lives(), self._on_live, history=True
        )
        self._deadline: float | None = None
        self._closed = threading.Event()  # the watchdog's end
        self._watchdog = threading.Thread(target=self._watch, name="watchdog", daemon=True)
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
        error = self._told or error or (clock.FAULT_STOP if self._stop_reason == "fault" else "")
        done = self._done  # complete ticks, also when a fault or a stop cut the run short
        reason = "fault" if error else (self._stop_reason or "completed")
        self._out.publish(self.keys.end(), End(self.run_id, done - 1, reason, error))
        wall, dropped = time.monotonic() - start, self.dropped
        return RunResult(done, wall, error, [*dropped], reason, joined - self._created, dropped)

    def _await_members(self) -> None:
        """Every token; who is missing every WAITING_NOTE_S (by hand, it said nothing), and
        who came and went (a stack that crashed after its join was "never joined")."""
        expected, limit_s, came = set(self.spec.participants), self.spec.start_timeout_s, set[str]()
        limit, note = time.monotonic() + limit_s, time.monotonic() + WAITING_NOTE_S
        while not expected <= self.members and not self._stop_reason:
            late, came = self._next_event(min(limit, note))[0] == "late", came | self.members
            if late:
                now, missing = time.monotonic(), sorted(expected - self.members)
                if now >= limit:
                    raise ClockError(clock.never_joined(missing, limit_s, came=came))
                note = now + WAITING_NOTE_S
                log.info("waiting for %s to join (%.0f s left)%s", ", ".join(missing),
                         limit - now, clock.came_and_went(missing, came))  # fmt: skip

    def _tick_loop(self, on_progress: Callable[[Progress], None] | None, start: float) -> None:
        """Grant ticks while the window and the pace allow, take acks, report progress.

        After a stop no more ticks are granted, but every granted tick completes, so every
        participant ends on the same last tick.
        """
        last_report, self._t0 = start - 1.0, start  # the first at once: the clock started
        self._deadline = None
        while self._done < self.spec.ticks and not self._stop_reason:
            self._grant(self._horizon())
            self._await_progress()
            now = time.monotonic()
            if on_progress and self._done and now - last_report >= 0.25:
                on_progress(self._progress(self._done - 1, now - start))
                last_report = now
        while self._done <= (self._granted if self._end_at is None else self._end_at):
            self._await_progress()
        if on_progress:
            on_progress(self._progress(self._done - 1, time.monotonic() - start))

    def _progress(self, k: int, wall: float) -> Progress:
        sim_s = (k + 1) * self.spec.dt_ns / 1e9
        return Progress(k, (k + 1) * self.spec.dt_ns, (k + 1) / max(wall, 1e-9), sim_s / wall)

    def _horizon(self) -> int:
        """The last tick that may be stepped now: the window past the slowest participant,
        the run's end, and (paced runs) the ticks whose wall-clock time has come."""
        last = self._window_end()
        factor = self.spec.realtime_factor
        if factor:
            due = (time.monotonic() - self._t0) * factor * 1e9 / self.spec.dt_ns
            last = min(last, int(due))
        return last

    def _window_end(self) -> int:
        """The last tick the window and the run's length allow, whatever the pace."""
        return min(self._done - 1 + self.spec.window_ticks, self.spec.ticks - 1)

    def _pace_wait(self) -> float | None:
        """Seconds until the next tick is due when only the pace holds it back, else None."""
        factor = self.spec.realtime_factor
        nxt = self._granted + 1
        if not factor or nxt > self._window_end():
            return None
        return max(self._t0 + nxt * self.spec.dt_ns / 1e9 / factor - time.monotonic(), 0.0)

    def _grant(self, last: int, *, again: bool = False) -> None:
        """Publish a Tick granting every tick up to `last` (again: repeat it with a new
        dropped list), with the setting changes of the ticks it adds."""
        if last <= self._granted and not again:
            return
        was_idle = self._done > self._granted
        self._granted = max(last, self._granted)
        if was_idle:  # work is outstanding from now on
            self._restart_deadline()
        k, dt = self._granted, self.spec.dt_ns
        changes = self.settings.grant(k)
        tick = Tick(self.run_id, k, k * dt, dt, tuple(self.dropped), self.spec.ack_every, changes,
                    self.spec.digest)  # fmt: skip
        self._out.publish(self.keys.tick(), tick)

    def _await_progress(self) -> None:
        """Wait for an ack or an event, or (paced runs) until the next tick is due, then take
        every ack queued; apply membership and the deadline."""
        wait = self._pace_wait()
        if wait is None:
            self._take(self._acks.recv())  # some tick is outstanding: an ack or a poke comes
        elif wait > 0:
            time.sleep(wait)
        self._take_queued()
        self._check_events()

    def _take_queued(self) -> None:
        while (sample := self._acks.try_recv()) is not None:
            self._take(sample)

    def _take(self, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        if key == self._poke_key:
            return
        try:
            name, ack = checked_ack(key, sample, keys=self.keys, members=self._members,
                                    expected=self._acked, run_id=self.run_id)  # fmt: skip
        except Rejected as exc:
            self.rejections.add(key, exc)
            return
        self._acked[name] = max(self._acked[name], min(ack.tick, self._granted))
        told = f"stopped at tick {ack.tick + 1}: {ack.fault}" if ack.fault else ""
        if told and self.spec.policy is not Policy.ABORT:  # its words, also once it left
            self._told_drop(name, told)
        elif told or ack.end:
            self._end_request(name, ack, fault=clock.blame(name, told) if told else "")
        self._advance()

    def _end_request(self, name: str, ack: Ack, *, fault: str = "") -> None:
        """A participant ends the run after `ack.tick` (first wins; a told `fault` fails it)."""
        if self._stop_reason:
            return
        self._end_at = max(min(ack.tick, self._granted), self._done - 1)
        self._stop_reason = "fault" if fault else clock.ended_by(name, self._end_at, ack.end)
        self._told = fault
        log.info("run %s", fault or self._stop_reason)
        self._grant(self._granted, again=True)

    def _advance(self) -> None:
        """Every active participant has acked up to `_done - 1`: restart the deadline."""
        done = min((self._acked[n] for n in self._active()), default=self._granted) + 1
        if done > self._done:
            self._done = done
            self._restart_deadline()

    def _restart_deadline(self) -> None:
        """`deadline_s` (+ a slow setting's grace) from now while a granted tick is out."""
        wait = self.spec.deadline_s + self.settings.grace(self._done, self._granted)
        self._deadline = time.monotonic() + wait if self._done <= self._granted else None

    def _active(self) -> list[str]:  # the participants not dropped
        return [n for n in sorted(self._acked) if n not in self.dropped]

    def _check_events(self) -> None:
        """Apply pending membership events (a stop is noted in `_stop_reason`) and the deadline."""
        if self._out.forged:  # before who left: a forged End makes them leave
            raise ClockError(self._out.forged)
        gone = self._now_gone()
        if gone:  # a lost link takes every token behind it: name them together
            gone = self._settled_gone()
        active = self._active()  # less any dropped for a fault it told (policy drop)
        if len(gone) > 1 and self.spec.policy is Policy.ABORT:  # one link: every token at once
            raise ClockError(
                f"participants {', '.join(map(repr, gone))} left the run at once at tick "
                f"{self._done}: the conductor lost its link to them (a router, or the network "
                "between them, gone?)"
            )
        for name in gone:
            why = BEFORE if self._acked[name] < 0 else SILENT
            self._left.add(name)  # until words of its own come (_told_drop)
            self._fault(name, f"{LEFT} at tick {self._acked[name] + 1}{why}")
        k = self._done
        if self._deadline is not None and time.monotonic() > self._deadline:
            for name in [n for n in active if self._acked[n] < k <= self._granted]:
                self._fault(name, f"missed the {self.spec.deadline_s:g} s deadline of tick {k}")

    def _settled_gone(self) -> list[str]:
        """Who is gone once their words had time to come (a fault told before leaving may land
        after the token went): WORDS_S under drop too (a loaded machine lost a crash's cause)."""
        limit = time.monotonic() + WORDS_S
        time.sleep(GONE_GRACE_S)
        while True:
            self._take_queued()
            gone = self._now_gone()
            if not gone or self._told or time.monotonic() >= limit:
                return gone
            time.sleep(GONE_GRACE_S / 4)

    def _now_gone(self) -> list[str]:
        """Events applied: the active ones whose token went (unless through the run's end)."""
        while not self.events.empty():
            self._next_event(0.0)
        return [n for n in self._active() if n not in self.members and not self._through(n)]

    def _through(self, name: str) -> bool:
        """`name` has stepped the run's last tick (ended by a participant): it may leave."""
        return self._end_at is not None and self._acked[name] >= self._end_at

    def _told_drop(self, name: str, told: str) -> None:
        """Dropped for its words; they replace "left the run" that came first (a loaded VM)."""
        if name not in self.dropped:
            self._fault(name, told)
        elif name in self._left:
            self._left.discard(name)
            self.dropped[name] = clock.blame(name, told)

    def _fault(self, name: str, what: str) -> None:
        message = clock.blame(name, what)
        if self.spec.policy is Policy.ABORT:
            raise ClockError(message)
        log.error("%s; dropping it and going on (policy drop)", message)
        self.dropped[name] = message
        self._advance()
        self._grant(self._horizon(), again=True)  # tell the others to stop waiting for it

    def _next_event(self, deadline: float) -> tuple[str, str, bytes]:
        """Wait for one event ("late" when the deadline passes); membership is tracked here."""
        try:
            event = self.events.get(timeout=max(deadline - time.monotonic(), 0.0))
        except queue.Empty:
            return ("late", "", b"")
        kind, key, _ = event
        if kind in ("join", "leave") and self._members.token(key, alive=kind == "join") is None:
            self.rejections.add(key, Rejected(self._members.refusal(key), key))
        return event

    @property
    def members(self) -> set[str]:  # the participants whose token is alive (and bound)
        return set(self._members.present)

    def close(self) -> None:
        self._closed.set()
        self._watchdog.join()
        self._acks.undeclare()
        self._out.close()
        self._live.undeclare()
        self._token.undeclare()
