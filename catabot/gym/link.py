"""The env's seat in the lockstep: observe a control period, act, observe the next.

One seam between the environment and the bus, pull-style (the client API's
`join(...)`/`observe()`/`act()`): `observe()` blocks until the next control tick is granted
and every input due before it is in, and returns what the vessel's stack may see at that
tick; `act(command)` is the command for that tick, applied by physics from the next tick on
every run (DESIGN.md §4). Anything else the env knows it takes from its own resolved World.

`ParticipantLink` is built on `catabot.bus.participant.Participant`: its push loop runs on a
thread and hands each control tick over through two queues (measured: ≈40 µs a hand-over,
a small part of a 10-tick control period).
"""

from __future__ import annotations

import json
import queue
import threading
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol

import zenoh

from catabot.bus.clock import ClockError
from catabot.bus.inbox import Inputs
from catabot.bus.messages import BodyStates, End, Message, ThrustCmd, Tick, TwistCmd
from catabot.bus.participant import Participant
from catabot.bus.session import Connection
from catabot.errors import CataBotError
from catabot.world.world import World

Command = ThrustCmd | TwistCmd
POLL_S = 0.25  # how often a blocked wait looks whether the link was closed
RETRY = {"period_init_ms": 20, "period_max_ms": 100, "period_increase_factor": 1.5}


class LinkError(CataBotError, RuntimeError):
    """The run behind the env failed or ended while the env waited for it."""


class LinkTimeout(LinkError):
    """Nothing came from the run within the time allowed."""


@dataclass(frozen=True)
class Frame:
    """What the stack sees at a control tick: every body's state at the start of the tick
    (tagged tick - 1; the start states at tick 0) and the newest sample of each sensor."""

    tick: int
    stamp_ns: int
    bodies: BodyStates
    sensors: Mapping[str, Message] = field(default_factory=dict)


class Link(Protocol):
    def observe(self, timeout_s: float) -> Frame: ...
    def act(self, command: Command) -> None: ...
    def close(self) -> None: ...


class ParticipantLink:
    """The env as the participant that controls `vessel` at its controller's rate."""

    def __init__(self, world: World, vessel: str, sensors: Sequence[str], endpoint: str) -> None:
        me = world.body(vessel)
        if me.controller is None:
            raise LinkError(f"vessel {vessel!r} has no controller to take the seat of")
        self.name = me.controller.participant
        (self._control,) = [
            s for s in world.streams.controls if world.keys.vessel_of(s.key) == vessel
        ]
        self._sensor_keys = {world.keys.sensor(vessel, s): s for s in sensors}
        streams = [world.streams.states]
        streams += [s for s in world.streams.sensors if s.key in self._sensor_keys]
        self._latest = world.start_states()
        self._newest: dict[str, Message] = {}
        self._frames: queue.SimpleQueue[Frame | End | BaseException] = queue.SimpleQueue()
        self._commands: queue.SimpleQueue[Command | None] = queue.SimpleQueue()
        self._closed = threading.Event()
        self._pending = False  # a frame was handed out and waits for its command
        self._ended: End | None = None
        self._session = _session(endpoint)
        self._participant = Participant(
            self._session, world.keys, self.name, inputs=streams, peers=world.participants,
            limits=world.clock_limits, drain_s=0.5,
        )  # fmt: skip
        self._thread = threading.Thread(target=self._loop, name=f"link-{self.name}", daemon=True)
        self._thread.start()

    # -- the participant's side (its own thread) -------------------------------------------

    def _loop(self) -> None:
        try:
            self._frames.put(self._participant.run(self._step))
        except _Closed:
            pass
        except BaseException as exc:  # handed to the env's thread, raised there
            self._frames.put(exc)

    def _step(self, tick: Tick, inputs: Inputs) -> None:
        for key, samples in inputs.items():
            if key in self._sensor_keys:
                self._newest[self._sensor_keys[key]] = samples[-1]
            elif samples and isinstance(samples[-1], BodyStates):
                self._latest = samples[-1]  # the state at the start of this tick
        if tick.tick % (self._control.period or 1):
            return
        self._frames.put(Frame(tick.tick, tick.stamp_ns, self._latest, dict(self._newest)))
        command = self._wait_command()  # physics waits for one every control tick
        self._participant.publish(self._control.key, _tagged(command, tick))

    def _wait_command(self) -> Command:
        while True:
            try:
                command = self._commands.get(timeout=POLL_S)
            except queue.Empty:
                command = None
            if self._closed.is_set():
                raise _Closed
            if command is not None:
                return command

    # -- the env's side ---------------------------------------------------------------------

    def observe(self, timeout_s: float) -> Frame:
        """The next control tick's frame; LinkError when the run ends or fails first, or
        when nothing comes within `timeout_s`."""
        if self._pending:
            raise LinkError("observe() twice without act(): the run waits for a command")
        if self._ended is not None:
            raise LinkError(f"the run has ended ({self._ended.reason})")
        limit = time.monotonic() + timeout_s
        while True:
            try:
                item = self._frames.get(timeout=min(POLL_S, max(limit - time.monotonic(), 0)))
                break
            except queue.Empty:
                if time.monotonic() >= limit:
                    raise LinkTimeout(
                        f"no control tick from the run within {timeout_s:g} s (is it running?)"
                    ) from None
        if isinstance(item, End):
            self._ended = item
            why = f"{item.reason}: {item.error}" if item.error else item.reason
            raise LinkError(f"the run ended ({why})")
        if isinstance(item, ClockError | CataBotError):
            raise LinkError(str(item)) from item
        if isinstance(item, BaseException):
            raise LinkError(f"the env's participant failed: {item!r}") from item
        self._pending = True
        return item

    def act(self, command: Command) -> None:
        """The command of the tick last observed."""
        if not self._pending:
            raise LinkError("act() without a frame observed first")
        self._pending = False
        self._commands.put(command)

    def close(self) -> None:
        self._closed.set()
        self._commands.put(None)  # wakes a participant waiting for a command
        self._thread.join(timeout=2.0)
        self._participant.close()
        self._session.close()


def _session(endpoint: str) -> zenoh.Session:
    """A peer connecting to the run's conductor, which may not listen yet: Zenoh retries
    every 20 ms (its default waits 1 s, then 2 s, ...: a reset took a whole retry longer),
    and opens at once (a peer's default is to scout for 0.5 s first; the env knows its one
    endpoint and waits for the run's tokens anyway)."""
    config = Connection(connect=(endpoint,)).config()
    config.insert_json5("connect/retry", json.dumps(RETRY))
    config.insert_json5("scouting/delay", "0")
    try:
        return zenoh.open(config)
    except Exception as exc:
        raise LinkError(f"cannot open zenoh to the run at {endpoint}: {exc}") from None


class _Closed(Exception):
    """Unwinds the participant's loop when the env closes the link mid-wait."""


def _tagged(command: Command, tick: Tick) -> Command:
    if isinstance(command, ThrustCmd):
        return ThrustCmd(command.thrust, tick=tick.tick, stamp_ns=tick.stamp_ns)
    return TwistCmd(command.surge, command.yaw_rate, tick=tick.tick, stamp_ns=tick.stamp_ns)
