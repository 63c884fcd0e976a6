"""A small lockstep world for the tests: a conductor and participant threads over real Zenoh.

The conductor's session listens on a free port, every participant's session connects to it,
the conductor runs in one thread and each participant's `run()` in its own; every session is
closed at the end (zenoh leaks threads otherwise).
"""

from __future__ import annotations

import contextlib
import threading
import time
import uuid
from collections.abc import Callable, Sequence
from typing import Any

import zenoh

from catabot.bus.clock import ClockLimits, Stream
from catabot.bus.conductor import ClockSpec, Conductor, RunResult
from catabot.bus.inbox import Inputs
from catabot.bus.keys import Keys
from catabot.bus.messages import End, GpsFix, Tick, VesselState
from catabot.bus.participant import Participant
from catabot.bus.session import Connection, free_port, open_session
from catabot.bus.settings import Schedule

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
        limits: ClockLimits | None = None,
    ) -> None:
        self.world, self.name, self.user_step = world, name, step
        self.session = world.open()
        self.participant = Participant(
            self.session, world.keys, name, inputs=inputs, peers=peers, drain_s=1.0, limits=limits
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
        limits: ClockLimits | None = None,
    ) -> Member:
        m = self.members[name] = Member(self, name, step, inputs, peers, limits)
        return m

    def run(
        self,
        participants: Sequence[str],
        ticks: int,
        *,
        settings: Schedule | None = None,
        **spec: Any,
    ) -> RunResult:
        """Start every member and the conductor; wait for the conductor's result."""
        clock = ClockSpec(dt_ns=DT_NS, ticks=ticks, participants=tuple(participants), **spec)
        self.conductor = Conductor(self.conductor_session, self.keys, clock, settings=settings)
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
        # Stop any participant still running (a failed test, one the test left waiting).
        for m in self.members.values():
            if m.thread.is_alive():
                m.participant.stop()
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
