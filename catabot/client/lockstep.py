"""Joining the lockstep as a named participant, pull style: `observe()`, then `act(command)`.

The protocol is the bus's own `Participant` (catabot/bus/participant.py: Jacobi inputs,
acks, End, sender checks), run on a thread of its own; its step hands each control
period's observation to the stack through a queue and waits for the stack's command on
another. So the stack's loop is plain code (what a Gymnasium env needs), and the
determinism is the participant's: at control tick k the observation holds the state at
t_k (the `BodyStates` tagged k-1; the start poses at k = 0) and the newest sample of each
sensor tagged before k, and the command goes out tagged k on the vessel's clocked command
stream, applied by physics from tick k+1 on every run.
"""

from __future__ import annotations

import contextlib
import math
import queue
import threading
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import zenoh

from catabot.bus.clock import EndRun, end_reason_problem, ender_of
from catabot.bus.inbox import Inputs
from catabot.bus.keys import Keys
from catabot.bus.messages import BodyStates, End, Message, ThrustCmd, Tick, TwistCmd, VesselState
from catabot.bus.participant import Participant, Stopped
from catabot.bus.settings import changes_of, sensor_switch
from catabot.client.commands import Command, Thrust, Twist, kind_of, message
from catabot.client.errors import ClientError, CommandError, NoData, RunEnded
from catabot.client.info import SensorInfo, VesselInfo, WorldInfo
from catabot.client.watch import Watch
from catabot.world.rotations import yaw_of_quaternions

END_GRACE_S = 7.0  # longer than a participant's drain after an End (5 s)
_LEAVE = object()  # put on the command queue by close(): the step gives up its wait


@dataclass(frozen=True)
class Observation:
    """What a stack sees at the start of control period `tick` (time `time_s`): its vessel's
    `state` (None when joined without a vessel), every body's state in `bodies` (rows in
    `WorldInfo.body_ids` order), the newest sample of each sensor asked for (None before the
    first) and every sample since the previous observation in `samples`."""

    tick: int
    stamp_ns: int
    state: VesselState | None
    bodies: BodyStates
    sensors: dict[str, Any]
    samples: dict[str, list[Any]] = field(default_factory=dict, repr=False)

    @property
    def time_s(self) -> float:
        return self.stamp_ns / 1e9

    @property
    def yaw_rad(self) -> float:
        """The vessel's heading (ENU: 0 east, counter-clockwise) from its quaternion, the
        one rule (catabot/world/rotations.py) every stack had written itself; NaN without
        a vessel."""
        if self.state is None:
            return math.nan
        return float(yaw_of_quaternions(np.array([self.state.orientation]))[0])


CLOSED = "closed by its stack before the run's end"


class Joined:
    """A stack in the lockstep: `observe()` blocks until the next control period's inputs
    are in, `act(command)` sends its command; RunEnded when the run is over."""

    def __init__(
        self,
        session: zenoh.Session,
        watch: Watch,
        info: WorldInfo,
        name: str,
        vessel: VesselInfo | None,
        sensors: list[SensorInfo],
        period: int,
    ) -> None:
        self.name, self.info, self.vessel, self.period = name, info, vessel, period
        self._watch = watch
        self._sensors = {s.key: s.name for s in sensors}
        owner = vessel.id if vessel is not None else ""
        self._switchable = {(owner, s.name): s.key for s in sensors}  # catabot set ... enabled
        self._control = vessel.control_stream() if vessel is not None else None
        if self._control is not None and self._control.producer != name:
            self._control = None  # another participant drives this vessel: observe only
        states = info.states_stream()
        self.participant = Participant(
            session, Keys(info.name), name, inputs=[states, *(s.stream() for s in sensors)],
            peers=info.participants, roster=info.new_roster(), limits=info.limits,
        )  # fmt: skip
        self._bodies = info.start
        self._newest: dict[str, Any] = {s.name: None for s in sensors}
        self._since: dict[str, list[Any]] = {s.name: [] for s in sensors}
        self._last: Message | None = None
        self._observations: queue.SimpleQueue[tuple[str, Any]] = queue.SimpleQueue()
        self._commands: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._pending: Observation | None = None  # observed, not yet acted on
        self._acted = -1  # the tick of the observation last acted on
        self.end: End | None = None
        self._closed = False
        self._thread = threading.Thread(target=self._run, name=f"lockstep-{name}", daemon=True)
        self._thread.start()

    # -- the participant's thread -------------------------------------------------------

    def _run(self) -> None:
        try:
            end = self.participant.run(self._step)
            self._observations.put(("end", end))
        except Stopped:
            self._observations.put(("left", None))
        except Exception as exc:  # a ClockError (conductor gone) or a bug: the stack hears it
            self._observations.put(("error", exc))

    def _step(self, tick: Tick, inputs: Inputs) -> None:
        self._watch.ticking = True  # Vessel.send need not wait for a state (vessel.py)
        self._switch(tick)
        for msg in inputs.get(self.info.states_key, ()):
            assert isinstance(msg, BodyStates)
            self._bodies = msg  # the state at the start of this tick (tagged tick - 1)
        for key, name in self._sensors.items():
            samples = inputs.get(key)
            if samples:
                self._since[name].extend(samples)
                self._newest[name] = samples[-1]
        if tick.tick % self.period:
            return
        self._observations.put(("obs", self._observation(tick)))
        command = self._commands.get()  # the stack's act(); the conductor's deadline runs
        if command is _LEAVE:
            raise Stopped(f"{self.name} left the run at tick {tick.tick}")
        if isinstance(command, EndRun):
            raise command
        if self._control is not None:
            self.participant.publish(self._control.key, command)

    def _switch(self, tick: Tick) -> None:
        """Sensors switched off or on at this tick (`catabot set sensor.<vessel>.<sensor>.
        enabled`): one that is off is not waited for (a stack reading it held the run to
        its deadline, as the services, told of switches, did not)."""
        for change in changes_of(tick.settings):
            named = sensor_switch(change.key)
            key = self._switchable.get(named) if named is not None else None
            if key is not None:
                self.participant.inbox.switch(key, tick.tick, on=bool(change.decoded))

    def _observation(self, tick: Tick) -> Observation:
        since, self._since = self._since, {name: [] for name in self._since}
        state = self._bodies.row(self.vessel.row) if self.vessel is not None else None
        return Observation(tick.tick, tick.stamp_ns, state, self._bodies, dict(self._newest),
                           since)  # fmt: skip

    # -- the stack's thread --------------------------------------------------------------

    def observe(self, timeout_s: float | None = None) -> Observation:
        """The next control period's observation; blocks until it is granted and its inputs
        are in. RunEnded when the run ends first (the End's reason), NoData after
        `timeout_s` (None: wait as long as the run goes on). Without an act() since the
        previous observation, act(None) is implied."""
        self._check_running()
        if self._pending is not None:
            self.act(None)
        kind, value = self._wait(timeout_s)
        if kind == "obs":
            self._pending = value
            return value
        if kind == "end":
            self.end = value
            raise RunEnded(
                f"the run of world {self.info.name!r} ended at tick {value.tick} "
                f"({value.reason}{': ' + value.error if value.error else ''})", value
            )  # fmt: skip
        if kind == "left":
            raise ClientError(f"participant {self.name!r} has left the run (close())")
        raise RunEnded(f"{self.name}: {value}") from value

    def _wait(self, timeout_s: float | None) -> tuple[str, Any]:
        """The participant's next word; if the client saw the run end (or the conductor
        vanish) and the participant says nothing within its drain time, it is stopped and
        the stack hears why: a participant that never saw the conductor cannot end alone."""
        waited, ended_at = 0.0, None
        while True:
            try:
                return self._observations.get(timeout=0.25)
            except queue.Empty:
                waited += 0.25
            ended = self._watch.ended()
            if ended is not None:
                ended_at = waited if ended_at is None else ended_at
                if waited - ended_at > END_GRACE_S:
                    self.participant.stop()
                    raise ended
            if timeout_s is not None and waited >= timeout_s:
                raise NoData(f"{self.name}: no control period granted within {timeout_s:g} s")

    def act(self, command: Command | None) -> None:
        """The command for the period last observed, tagged with its tick: applied from the
        next tick on every run. None keeps the last command (zero thrust, or a zero twist,
        before the first)."""
        self._check_running()
        obs = self._pending
        if obs is None:
            again = f"act() again for tick {self._acted}" if self._acted >= 0 else "act() first"
            raise ClientError(f"{self.name}: {again}: one act() answers each observe()")
        msg = self._message(command, obs) if self._control is not None else None
        if command is not None and self._control is None:
            raise CommandError(
                f"participant {self.name!r} drives no vessel's commands in this world "
                "(a vessel's controller.participant names the one that does); send free "
                "commands with Client.vessel(id).send()"
            )
        self._pending, self._acted = None, obs.tick
        self._last = msg if msg is not None else self._last
        self._commands.put(msg)

    def end_run(self, reason: str, *, timeout_s: float = 10.0) -> End:
        """End the run instead of acting on the period last observed (an episode is over):
        the run ends cleanly after the tick before it, for everyone, and its recording holds
        every tick up to that one. Returns the End; NoData if it does not come in time."""
        self._check_running()
        if self._pending is None:
            raise ClientError(f"{self.name}: end_run() takes the place of act() for the period "
                              "observe() returned, and none is waiting (before the first "
                              "observe(), or it was acted on): call observe() first")  # fmt: skip
        problem = end_reason_problem(reason)
        if problem:
            raise ClientError(f"{self.name}: end_run() takes {problem}")
        self._pending = None
        self._commands.put(EndRun(reason))
        kind, value = self._wait(timeout_s)
        if kind != "end":
            raise RunEnded(f"{self.name}: the run did not end as asked ({kind}: {value})")
        self.end = value
        if ender_of(value.reason) != self.name:  # another ended it first, or a fault
            raise RunEnded(f"{self.name}: the run had ended before this request ({value.reason})",
                           value)  # fmt: skip
        return value

    def _check_running(self) -> None:
        """RunEnded, as `observe` says it, once the run is over."""
        if self.end is not None:
            raise RunEnded(f"the run of world {self.info.name!r} has ended ({self.end.reason})",
                           self.end)  # fmt: skip

    def _message(self, command: Command | None, obs: Observation) -> Message:
        vessel, control = self.vessel, self._control
        assert vessel is not None and control is not None and vessel.controller is not None
        kind = vessel.controller.command
        if command is None:
            command = self._neutral(kind) if self._last is None else self._restate(kind)
        elif kind_of(command) != kind:
            raise CommandError(
                f"vessel {vessel.id!r} takes {kind} commands in lockstep (its controller's "
                f"`command`), not {kind_of(command)}"
            )
        return message(command, vessel, tick=obs.tick, stamp_ns=obs.stamp_ns)

    def _neutral(self, kind: str) -> Command:
        assert self.vessel is not None
        if kind == "thrust":
            return Thrust([0.0] * self.vessel.thrusters)
        return Twist(0.0, 0.0)

    def _restate(self, kind: str) -> Command:
        last = self._last
        if isinstance(last, ThrustCmd):
            return Thrust(last.thrust)
        assert isinstance(last, TwistCmd), kind
        return Twist(last.surge, last.yaw_rate)

    def close(self, *, fault: str = "") -> None:
        """Leave the run (mid-run the conductor names this participant gone and, by the
        scenario's policy, ends the run or drops it). `fault`: why, when the stack failed
        (at most 200 characters kept): the conductor's error, the run's cause, quotes it."""
        if self._closed:
            return
        self._closed = True
        if self._thread.is_alive():  # mid-run: said, or the run's error read "without a word"
            self.participant.report_fault(fault or CLOSED)
        if self._thread.is_alive():
            self._commands.put(_LEAVE)
            self.participant.stop()
            self._thread.join(timeout=5.0)
        with contextlib.suppress(zenoh.ZError):  # the session closed first
            self.participant.close()
