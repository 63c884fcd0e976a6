"""The real Conductor and Participants over real Zenoh sessions on loopback (DESIGN.md §4).

Each test builds a small world: the conductor's session listens on a free port, every
participant's session connects to it, the conductor runs in one thread and each
participant's `run()` in its own. Deadlines are short so that faults show in well
under a second; every session is closed at the end (zenoh leaks threads otherwise).
"""

from __future__ import annotations

import contextlib
import logging
import threading
import time
import uuid
from collections.abc import Callable, Iterator, Sequence
from typing import Any

import pytest
import zenoh

from catabot import codec
from catabot.clock import Policy, Stream
from catabot.conductor import ClockSpec, Conductor, RunResult
from catabot.inbox import Inputs
from catabot.keys import Keys
from catabot.messages import End, GpsFix, Tick, VesselState
from catabot.participant import Participant
from catabot.session import Connection, free_port, open_session

DT_NS = 10_000_000
JOIN_S = 10.0  # generous bound on thread joins; a healthy test takes far less

Step = Callable[[Tick, Inputs], None]


def _state(tick: int) -> VesselState:
    zero = (0.0, 0.0, 0.0)
    return VesselState(
        tick, tick * DT_NS, (float(tick), 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), *[zero] * 4
    )


def _fix(tick: int) -> GpsFix:
    return GpsFix(tick, tick * DT_NS, 40.0 + tick * 1e-6, -74.0, 0.0, 0.0, 0.0)


class Member:
    """One participant with its own session, stepping in its own thread."""

    def __init__(
        self,
        world: World,
        name: str,
        step: Step | None,
        inputs: Sequence[Stream],
        peers: Sequence[str],
    ) -> None:
        self.world, self.name, self.user_step = world, name, step
        self.session = world.open()
        self.participant = Participant(
            self.session, world.keys, name, inputs=inputs, peers=peers, drain_s=1.0
        )
        self.ticks: list[int] = []
        self.released: dict[int, Inputs] = {}
        self.end: End | None = None
        self.end_inputs: Inputs | None = None
        self.error: BaseException | None = None
        self.thread = threading.Thread(target=self._run, name=f"member-{name}", daemon=True)

    def _step(self, tick: Tick, inputs: Inputs) -> None:
        self.world.log_event("start", self.name, tick.tick)
        self.ticks.append(tick.tick)
        self.released[tick.tick] = inputs
        if self.user_step is not None:
            self.user_step(tick, inputs)
        self.world.log_event("done", self.name, tick.tick)

    def _on_end(self, end: End, inputs: Inputs) -> None:
        self.end_inputs = inputs

    def _run(self) -> None:
        try:
            self.end = self.participant.run(self._step, self._on_end)
        except BaseException as exc:  # reported by the test, never lost in a thread
            self.error = exc

    def join(self, timeout: float = JOIN_S) -> None:
        self.thread.join(timeout)
        assert not self.thread.is_alive(), f"participant {self.name} did not finish"


class World:
    """A conductor session listening on loopback and participants connected to it."""

    def __init__(self) -> None:
        self.keys = Keys(f"test-{uuid.uuid4().hex[:8]}")
        self.endpoint = f"tcp/127.0.0.1:{free_port()}"
        self.sessions: list[zenoh.Session] = []
        self.members: dict[str, Member] = {}
        self.events: list[tuple[str, str, int]] = []
        self._lock = threading.Lock()
        self.conductor_session = self.open(Connection(listen=(self.endpoint,)))
        self.conductor: Conductor | None = None
        self.result: RunResult | None = None
        self.result_at = 0.0
        self._conductor_thread: threading.Thread | None = None

    def open(self, conn: Connection | None = None) -> zenoh.Session:
        session = open_session(conn or Connection(connect=(self.endpoint,)))
        self.sessions.append(session)
        return session

    def log_event(self, what: str, name: str, tick: int) -> None:
        with self._lock:
            self.events.append((what, name, tick))

    def member(
        self,
        name: str,
        step: Step | None = None,
        *,
        inputs: Sequence[Stream] = (),
        peers: Sequence[str] = (),
    ) -> Member:
        m = self.members[name] = Member(self, name, step, inputs, peers)
        return m

    def run(self, participants: Sequence[str], ticks: int, **spec: Any) -> RunResult:
        """Start every member and the conductor; wait for the conductor's result."""
        clock = ClockSpec(dt_ns=DT_NS, ticks=ticks, participants=tuple(participants), **spec)
        self.conductor = Conductor(self.conductor_session, self.keys, clock)
        for m in self.members.values():
            m.thread.start()

        def conduct() -> None:
            assert self.conductor is not None
            self.result = self.conductor.run()
            self.result_at = time.monotonic()

        self._conductor_thread = threading.Thread(target=conduct, name="conductor", daemon=True)
        self._conductor_thread.start()
        self._conductor_thread.join(JOIN_S + clock.start_timeout_s)
        assert not self._conductor_thread.is_alive(), "the conductor did not finish"
        assert self.result is not None
        return self.result

    def close(self) -> None:
        # Stop any participant still running (a failed test) with an End of its own run.
        for m in self.members.values():
            if m.thread.is_alive():
                end = End(m.participant.run_id, -1, "teardown")
                m.participant.events.put(("end", self.keys.end(), codec.encode(end)))
                m.thread.join(3.0)
        for m in self.members.values():
            _quietly(m.participant.close)
        if self.conductor is not None:
            _quietly(self.conductor.close)
        for session in self.sessions:
            _quietly(session.close)


def _quietly(fn: Callable[[], object]) -> None:
    with contextlib.suppress(Exception):  # the crash test's session refuses a second close
        fn()


@pytest.fixture
def world() -> Iterator[World]:
    w = World()
    try:
        yield w
    finally:
        w.close()


# -- (a) the happy path -------------------------------------------------------------------


def test_three_participants_step_every_tick_in_lockstep(world: World) -> None:
    names = ["physics", "sensors", "recorder"]
    for name in names:
        world.member(name, peers=names)
    result = world.run(names, 50, deadline_s=2.0, start_timeout_s=5.0)

    assert result.error == ""
    assert result.ticks_done == 50
    assert result.dropped == []
    assert result.reason == "completed"
    assert world.conductor is not None
    for name in names:
        m = world.members[name]
        m.join()
        assert m.error is None
        assert m.ticks == list(range(50))  # each tick once, in order
        assert m.end is not None
        assert (m.end.run, m.end.tick, m.end.reason, m.end.error) == (
            world.conductor.run_id,
            49,
            "completed",
            "",
        )
    # lockstep: nobody starts tick k before everybody has finished tick k - 1
    finished: dict[int, int] = {}
    for what, _name, tick in world.events:
        if what == "start" and tick > 0:
            assert finished.get(tick - 1, 0) == len(names), f"tick {tick} started early"
        elif what == "done":
            finished[tick] = finished.get(tick, 0) + 1


def test_ticks_carry_time(world: World) -> None:
    stamps: list[tuple[int, int, int]] = []
    world.member("solo", lambda t, _i: stamps.append((t.tick, t.stamp_ns, t.dt_ns)))
    result = world.run(["solo"], 5, deadline_s=2.0, start_timeout_s=5.0)
    world.members["solo"].join()
    assert result.error == ""
    assert stamps == [(k, k * DT_NS, DT_NS) for k in range(5)]


# -- (b) Jacobi inputs --------------------------------------------------------------------


def _producer_consumer(world: World, produce: Step) -> tuple[str, Member]:
    key = world.keys.sensor("ego", "gps")
    names = ["prod", "cons"]
    world.member("prod", produce, peers=names)
    cons = world.member("cons", inputs=[Stream(key, GpsFix, "prod", 2)], peers=names)
    return key, cons


def _check_jacobi(cons: Member, key: str, ticks: int) -> None:
    assert cons.ticks == list(range(ticks))
    for k in range(ticks):
        got = [m.tick for m in cons.released[k].get(key, [])]
        # the sample of tick j (j even) is handed over at tick j + 1: never earlier, never later
        expected = [k - 1] if k >= 1 and (k - 1) % 2 == 0 else []
        assert got == expected, f"tick {k}: released {got}, expected {expected}"
    assert cons.end_inputs == {}  # nothing left over for the end


def test_consumer_gets_exactly_the_samples_of_earlier_ticks(world: World) -> None:
    key = world.keys.sensor("ego", "gps")
    participant: dict[str, Participant] = {}

    def produce(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick % 2 == 0:
            time.sleep(0.004)  # a slow producer
            participant["p"].publish(key, _fix(tick.tick))

    key, cons = _producer_consumer(world, produce)
    participant["p"] = world.members["prod"].participant
    result = world.run(["prod", "cons"], 30, deadline_s=2.0, start_timeout_s=5.0)
    for m in world.members.values():
        m.join()
        assert m.error is None
    assert result.error == "" and result.ticks_done == 30
    _check_jacobi(cons, key, 30)


def test_consumer_waits_for_a_late_sample(world: World) -> None:
    """A producer whose sample trails its ack: the consumer must wait, not step without it."""
    key = world.keys.sensor("ego", "gps")
    sent: dict[int, float] = {}
    timers: list[threading.Timer] = []

    def send_late(tick: int) -> None:
        sent[tick] = time.monotonic()
        publisher.put(codec.encode(_fix(tick)))

    def produce(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick % 2 == 0:
            timer = threading.Timer(0.03, send_late, args=(tick.tick,))
            timers.append(timer)
            timer.start()

    key, cons = _producer_consumer(world, produce)
    publisher = world.members["prod"].session.declare_publisher(key)
    step_at: dict[int, float] = {}
    cons.user_step = lambda tick, _inputs: step_at.__setitem__(tick.tick, time.monotonic())
    result = world.run(["prod", "cons"], 12, deadline_s=2.0, start_timeout_s=5.0)
    for timer in timers:
        timer.join()
    for m in world.members.values():
        m.join()
        assert m.error is None
    publisher.undeclare()
    assert result.error == "" and result.ticks_done == 12
    _check_jacobi(cons, key, 12)
    for j, t in sent.items():
        if j + 1 < 12:
            assert step_at[j + 1] >= t, f"tick {j + 1} stepped before the sample of tick {j}"


# -- (c) deadline -------------------------------------------------------------------------


def test_a_step_past_the_deadline_ends_the_run_naming_it(world: World) -> None:
    release = threading.Event()

    def hang(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick == 3:
            release.wait(5.0)

    world.member("fast")
    world.member("stuck", hang)
    try:
        result = world.run(["fast", "stuck"], 20, deadline_s=0.5, start_timeout_s=5.0)
    finally:
        release.set()
    assert "'stuck'" in result.error
    assert "deadline" in result.error and "tick 3" in result.error
    assert "'fast'" not in result.error
    assert result.reason == "fault"
    assert result.ticks_done == 3  # ticks 0, 1 and 2 completed
    fast = world.members["fast"]
    fast.join()
    assert fast.ticks == [0, 1, 2, 3]
    assert fast.end is not None and fast.end.error == result.error
    assert fast.end.tick == 2  # the last complete tick
    world.members["stuck"].join()


# -- (d) policy drop ----------------------------------------------------------------------


def test_policy_drop_goes_on_without_the_hanging_participant(world: World) -> None:
    release = threading.Event()
    key = world.keys.vessel_state("ego")
    names = ["hang", "cons", "other"]
    holder: dict[str, Participant] = {}

    def hang(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick == 5:
            release.wait(5.0)
        holder["p"].publish(key, _state(tick.tick))

    holder["p"] = world.member("hang", hang, peers=names).participant
    cons = world.member("cons", inputs=[Stream(key, VesselState, "hang", 1)], peers=names)
    world.member("other", peers=names)
    try:
        result = world.run(names, 20, deadline_s=0.3, start_timeout_s=5.0, policy=Policy.DROP)
    finally:
        release.set()
    assert result.error == ""
    assert result.dropped == ["hang"]
    assert result.ticks_done == 20
    assert result.reason == "completed"
    for m in world.members.values():
        m.join()
        assert m.error is None
    assert cons.ticks == list(range(20))
    assert world.members["other"].ticks == list(range(20))
    for k in range(1, 6):  # before the drop, the consumer had every state
        assert [m.tick for m in cons.released[k][key]] == [k - 1]


# -- (e) start timeout --------------------------------------------------------------------


def test_a_participant_that_never_joins_is_named(world: World) -> None:
    world.member("here")
    t0 = time.monotonic()
    result = world.run(["here", "ghost"], 10, deadline_s=1.0, start_timeout_s=0.5)
    assert time.monotonic() - t0 < 3.0
    assert "never joined" in result.error
    assert "ghost" in result.error and "here" not in result.error
    assert "0.5 s" in result.error
    assert result.ticks_done == 0
    here = world.members["here"]
    here.join()
    assert here.ticks == []
    assert here.end is not None and here.end.error == result.error


# -- (f) a crash mid-run ------------------------------------------------------------------


def _crash_at(world: World, tick: int, crashed_at: list[float]) -> Step:
    def step(t: Tick, _inputs: Inputs) -> None:
        if t.tick == tick:
            crashed_at.append(time.monotonic())
            world.members["crash"].session.close()

    return step


def test_a_participant_that_crashes_is_named_within_a_second(world: World) -> None:
    crashed_at: list[float] = []
    names = ["a", "b", "crash"]
    world.member("a", peers=names)
    world.member("b", peers=names)
    world.member("crash", _crash_at(world, 10, crashed_at), peers=names)
    result = world.run(names, 50, deadline_s=5.0, start_timeout_s=5.0)
    assert crashed_at, "the crash never happened"
    assert result.error == "participant 'crash' left the run at tick 10"
    assert world.result_at - crashed_at[0] < 1.0
    assert result.ticks_done == 10
    for name in ("a", "b"):
        m = world.members[name]
        m.join()
        assert m.error is None
        assert m.end is not None and "crash" in m.end.error
    world.members["crash"].join()


def test_policy_drop_goes_on_without_a_crashed_participant(world: World) -> None:
    crashed_at: list[float] = []
    names = ["a", "b", "crash"]
    world.member("a", peers=names)
    world.member("b", peers=names)
    world.member("crash", _crash_at(world, 10, crashed_at), peers=names)
    result = world.run(names, 30, deadline_s=1.0, start_timeout_s=5.0, policy=Policy.DROP)
    assert crashed_at
    assert result.error == ""
    assert result.dropped == ["crash"]
    assert result.ticks_done == 30
    for name in ("a", "b"):
        m = world.members[name]
        m.join()
        assert m.error is None
        assert m.ticks == list(range(30))
    world.members["crash"].join()


# -- (g) malformed input ------------------------------------------------------------------


def test_malformed_input_is_logged_and_the_participant_goes_on(
    world: World, caplog: pytest.LogCaptureFixture
) -> None:
    key = world.keys.vessel_state("ego")
    names = ["inj", "cons"]
    holder: dict[str, Participant] = {}

    def inject(tick: Tick, _inputs: Inputs) -> None:
        p = holder["p"]
        if tick.tick == 3:
            p.session.put(key, b"\xc1 not msgpack")
            p.session.put(key, codec.encode(_fix(3)))  # a valid message of the wrong type
        p.publish(key, _state(tick.tick))

    holder["p"] = world.member("inj", inject, peers=names).participant
    cons = world.member("cons", inputs=[Stream(key, VesselState, "inj", 1)], peers=names)
    with caplog.at_level(logging.WARNING, logger="catabot.participant"):
        result = world.run(names, 20, deadline_s=2.0, start_timeout_s=5.0)
        for m in world.members.values():
            m.join()
            assert m.error is None
    assert result.error == "" and result.ticks_done == 20
    assert cons.ticks == list(range(20))
    for k in range(1, 20):
        assert [m.tick for m in cons.released[k][key]] == [k - 1]
    warnings = [r.getMessage() for r in caplog.records if r.name == "catabot.participant"]
    malformed = [w for w in warnings if "malformed" in w]
    assert len(malformed) == 2, warnings
    assert all(key in w and w.startswith("cons:") for w in malformed)
    assert any("not a msgpack payload" in w for w in malformed)
    assert any("'gps' where 'vessel_state' was expected" in w for w in malformed)


# -- stop and pacing ----------------------------------------------------------------------


def test_stop_ends_the_run_at_the_tick_boundary(world: World) -> None:
    def step(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick == 5:
            assert world.conductor is not None
            world.conductor.stop("interrupted")  # before this tick's ack goes out

    solo = world.member("solo", step)
    result = world.run(["solo"], 50, deadline_s=2.0, start_timeout_s=5.0)
    solo.join()
    # the tick in progress is completed (everyone acked it), then the run stops
    assert (result.error, result.reason, result.ticks_done) == ("", "interrupted", 6)
    assert solo.ticks == list(range(6))
    assert solo.end is not None and (solo.end.reason, solo.end.tick) == ("interrupted", 5)


def test_realtime_factor_paces_the_clock(world: World) -> None:
    solo = world.member("solo")
    result = world.run(["solo"], 20, deadline_s=2.0, start_timeout_s=5.0, realtime_factor=2.0)
    solo.join()
    assert result.error == "" and result.ticks_done == 20
    assert result.wall_s >= 19 * DT_NS / 1e9 / 2.0  # tick 19 starts 95 ms after tick 0
