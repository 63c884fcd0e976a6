"""`Client`: one Zenoh session to one running world, for an autonomy stack.

    with Client.connect(connect=["tcp/127.0.0.1:7447"]) as sim:
        ego = sim.vessel("ego")
        ego.send(Thrust([0.5, 0.5]))

The world is discovered by a query (`world/info`, catabot/client/discover.py), never read
from a scenario file; everything after that is typed: `WorldInfo`, vessel handles with
their sensors, commands checked before they leave, and two ways to run a stack: joined to
the lockstep (`join`, `run_lockstep`: deterministic) or free-running (`run_free`).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable, Sequence
from types import TracebackType

import zenoh

from catabot.bus.clock import NS_PER_S, ClockError, EndRun, period_in_ticks
from catabot.bus.keys import Keys
from catabot.bus.messages import End
from catabot.bus.outputs import Outputs
from catabot.bus.session import (
    Connection,
    SessionError,
    add_connection_args,
    connection_from_args,
    open_session,
)
from catabot.client.commands import Command
from catabot.client.discover import find_world
from catabot.client.errors import (
    NotAParticipant,
    NotItsVessel,
    RunEnded,
    SeveralVessels,
    SimulatorNotFound,
    TooLate,
    UnknownVessel,
    WrongRate,
)
from catabot.client.free import run_free
from catabot.client.info import SensorInfo, VesselInfo, WorldInfo
from catabot.client.lockstep import Joined, Observation
from catabot.client.vessel import Vessel
from catabot.client.watch import Watch

Step = Callable[[Observation], Command | None]


class Client:
    def __init__(self, session: zenoh.Session, info: WorldInfo, where: str, timeout_s: float):
        self.session, self.info, self._where, self.timeout_s = session, info, where, timeout_s
        self.keys = Keys(info.name)
        self.watch = Watch(session, self.keys, info.new_roster())
        self._outputs = Outputs(session)
        self._vessels: dict[str, Vessel] = {}
        self._joined: list[Joined] = []

    @classmethod
    def connect(
        cls,
        connect: str | Sequence[str] = (),
        *,
        world: str | None = None,
        timeout_s: float = 5.0,
        listen: str | Sequence[str] = (),
        mode: str | None = None,
        zenoh_config: str | None = None,
    ) -> Client:
        """Open a session (an embedded peer on loopback by default; `connect` endpoints of
        `catabot run --listen` or a router) and find the world: `world`, or the only one
        running (a string is one endpoint). SimulatorNotFound after `timeout_s` if none
        answers."""
        conn = Connection(_endpoints(connect), _endpoints(listen), mode, None, zenoh_config)
        return cls.open(conn, world=world, timeout_s=timeout_s)

    @classmethod
    def from_args(cls, args: argparse.Namespace, *, timeout_s: float | None = None) -> Client:
        """After `add_stack_args(parser)` (or `catabot.bus.session.add_connection_args`);
        `--world` and `--timeout` are used when the parser has them."""
        world = getattr(args, "world", None)
        timeout = timeout_s if timeout_s is not None else getattr(args, "timeout", None)
        return cls.open(connection_from_args(args), world=world, timeout_s=timeout or 5.0)

    @classmethod
    def open(cls, conn: Connection, *, world: str | None, timeout_s: float) -> Client:
        try:
            where, session = conn.described(), open_session(conn)
        except SessionError as exc:  # one line under `except ClientError`, as the rest
            raise SimulatorNotFound(str(exc)) from None
        try:
            info = find_world(session, world, timeout_s, where)
        except BaseException:
            session.close()
            raise
        return cls(session, info, where, timeout_s)

    # -- observing and commanding ----------------------------------------------------------

    def vessel(self, vessel_id: str) -> Vessel:
        """A scenario vessel's or a traffic boat's handle (a boat: its state and commands,
        `Waypoints` included, no sensors); UnknownVessel (listing the ids) if there is none."""
        if vessel_id not in self._vessels:
            info, timeout = self._vessel(vessel_id), self.timeout_s
            self._vessels[vessel_id] = Vessel(
                self.watch, self._outputs, info, ready_timeout_s=timeout
            )
        return self._vessels[vessel_id]

    def _vessel(self, vessel_id: str) -> VesselInfo:
        info = self.info.vessels.get(vessel_id) or self.info.boats.get(vessel_id)
        if info is None:
            known = ", ".join(self.info.vessels) or "none"
            boats = list(self.info.boats)
            more = f"; traffic boats: {', '.join(boats[:3])}{'...' if len(boats) > 3 else ''}"
            raise UnknownVessel(f"world {self.info.name!r} has no vessel {vessel_id!r}; its "
                                f"vessels: {known}{more if boats else ''}")  # fmt: skip
        return info

    # -- the lockstep ----------------------------------------------------------------------

    def join(
        self,
        name: str | None,
        *,
        vessel: str | None = None,
        sensors: Sequence[str] = (),
        rate_hz: float | None = None,
    ) -> Joined:
        """Join the lockstep as participant `name` (the scenario must expect it: a vessel's
        `controller.participant` or `clock.external_participants`). `vessel`: the one to
        observe and, if `name` is its controller, to command (default: the vessel `name`
        controls); `sensors`: that vessel's sensors to wait for. The control period is the
        controller's rate, else `rate_hz` (default every tick); a `rate_hz` the clock cannot
        step, or that differs from the controller's, is WrongRate. `name` None: the controller
        participant of `vessel` (`--participant` left out, as add_stack_args says)."""
        info = find_world(self.session, self.info.name, self.timeout_s, self._where)  # fresh
        name = name if name is not None else _controller_of(info, vessel)
        self._expected(info, name)
        target = self._target(info, name, vessel)  # UnknownVessel
        _one_vessel(info, name, vessel)
        mounted = [target.sensor(s) for s in sensors] if target is not None else []
        if sensors and target is None:
            raise UnknownVessel(f"sensors {list(sensors)} asked for without a vessel")
        self._not_taken(info, name)
        period = self._period(info, name, target, rate_hz)
        joined = Joined(self.session, self.watch, info, name, target, mounted, period)
        self._joined.append(joined)
        return joined

    def _expected(self, info: WorldInfo, name: str) -> None:
        if name not in info.external:
            raise NotAParticipant(
                f"world {info.name!r} does not expect a participant {name!r}; it expects "
                f"{', '.join(info.external) or 'no external participant'} (name yours in the "
                "scenario's clock.external_participants or a vessel's controller.participant)"
            )

    def _target(self, info: WorldInfo, name: str, vessel: str | None) -> VesselInfo | None:
        if vessel is not None:
            return self._vessel(vessel)
        driven = [
            v for v in info.vessels.values() if v.controller and v.controller.participant == name
        ]
        return driven[0] if driven else None

    def _not_taken(self, info: WorldInfo, name: str) -> None:
        """TooLate while another session holds the name (first: a second copy of a stack
        was told it came too late), or once the clock has started (the run went on without
        `name`)."""
        holder = self.watch.members.present.get(name)
        if holder is not None:
            raise TooLate(f"participant {name!r} of world {info.name!r} is already joined by "
                          f"another session ({holder}): a second copy of the stack? stop it, "
                          "or join another run")  # fmt: skip
        if info.granted >= 0:
            raise TooLate(
                f"the run of world {info.name!r} has started (tick {info.granted} granted): "
                f"participant {name!r} joined too late, or left it; start the stack before "
                "the run's clock.start_timeout_s runs out"
            )

    def _period(self, info: WorldInfo, name: str, target: VesselInfo | None,
                rate_hz: float | None) -> int:  # fmt: skip
        c = target.controller if target is not None else None
        if rate_hz is None:
            return c.period_ticks if c is not None and c.participant == name else 1
        if not (math.isfinite(rate_hz) and rate_hz > 0):  # 0: ZeroDivisionError, traced
            raise WrongRate(f"rate_hz {rate_hz}: must be a finite number > 0")
        try:  # the rule every rate follows (DESIGN.md §4)
            period = period_in_ticks(
                round(NS_PER_S / rate_hz), info.dt_ns, what=f"rate_hz {rate_hz}"
            )
        except ClockError as exc:
            raise WrongRate(str(exc)) from None
        if c is not None and c.participant == name and period != c.period_ticks:
            assert target is not None
            raise WrongRate(f"rate_hz {rate_hz:g}: {name!r} steps as {target.id}'s "
                            f"controller, at its controller.rate_hz {c.rate_hz:g} Hz; leave "
                            "rate_hz out")  # fmt: skip
        return period

    def run_lockstep(
        self, name: str | None, step: Step, *, vessel: str | None = None,
        sensors: Sequence[str] = (), rate_hz: float | None = None,
    ) -> End:  # fmt: skip
        """Join as `name` and call `step(observation) -> command | None` every control
        period until the run ends; returns its End. A step that raises `EndRun(reason)`
        ends the run there for everyone (`Joined.end_run`); one that raises anything else
        leaves with that exception as the run's cause (the conductor's error names it)."""
        joined = self.join(name, vessel=vessel, sensors=sensors, rate_hz=rate_hz)
        try:
            while True:
                try:
                    obs = joined.observe()
                except RunEnded as ended:
                    if ended.end is None:
                        raise
                    return ended.end
                try:
                    joined.act(step(obs))  # a command act() refuses (NaN) is the stack's bug too
                except EndRun as request:
                    return joined.end_run(str(request))
                except Exception as exc:  # the stack's bug: the run's cause, in its words
                    joined.close(fault=_told(exc))
                    raise
        finally:
            joined.close()

    def run_free(
        self, step: Step, *, rate_hz: float, vessel: str, sensors: Sequence[str] = (),
        max_steps: int | None = None,
    ) -> End | None:  # fmt: skip
        """Call `step(observation)` `rate_hz` times a wall-clock second with the newest
        state and samples, and send what it returns (never blocks the clock). Returns the
        End when the run ends, None after `max_steps`."""
        target = self._vessel(vessel)
        mounted: list[SensorInfo] = [target.sensor(s) for s in sensors]
        return run_free(self.watch, self.info, self.vessel(vessel), mounted, step,
                        rate_hz=rate_hz, max_steps=max_steps)  # fmt: skip

    # -- the session -----------------------------------------------------------------------

    def close(self, *, fault: str = "") -> None:
        """Leave the run; `fault` (a stack that failed) is told for every seat it held."""
        try:
            for joined in self._joined:
                joined.close(fault=fault)
            self.watch.close()
        finally:
            self.session.close()

    def __enter__(self) -> Client:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        """An exception of the stack's own (not the run's end) is the run's cause in its
        words, as `run_lockstep` tells it; Ctrl-C is told as the interruption it is (it read
        "left the run without a word", as a crash or a lost link does)."""
        if isinstance(exc, KeyboardInterrupt | SystemExit):  # its own words, not a crash's
            self.close(fault=f"interrupted ({type(exc).__name__} in the stack)")
        else:
            told = exc is not None and not isinstance(exc, RunEnded)
            self.close(fault=_told(exc) if told and exc is not None else "")


def _one_vessel(info: WorldInfo, name: str, vessel: str | None) -> None:
    """A `Joined` commands one vessel, its own: a participant the scenario gives two would
    leave the second without commands, one joined to another vessel its own, and physics
    waiting for them until the deadline (which then blamed physics)."""
    driven = [vid for vid, v in info.vessels.items()
              if v.controller and v.controller.participant == name]  # fmt: skip
    if len(driven) > 1:
        raise SeveralVessels(
            f"participant {name!r} controls vessels {', '.join(driven)} in world {info.name!r}, "
            "and a joined client commands one: give each vessel its own controller.participant"
        )
    if driven and vessel is not None and vessel != driven[0]:
        other = info.vessels.get(vessel)
        theirs = other.controller.participant if other and other.controller else None
        hint = f"; {theirs!r} controls {vessel!r}" if theirs else ""
        raise NotItsVessel(f"participant {name!r} controls vessel {driven[0]!r}, not "
                           f"{vessel!r}: join with vessel={driven[0]!r} (--vessel "
                           f"{driven[0]}){hint}")  # fmt: skip


def add_stack_args(parser: argparse.ArgumentParser) -> None:
    """The flags of a stack: the connection's, and `--world`, `--vessel`, `--participant`,
    `--timeout`, which `catabot run` passes a controller's `program` (README), so one script
    runs beside a run by hand and as the run's own program alike."""
    add_connection_args(parser)
    parser.add_argument("--world", help="scenario name (default: the one running)")
    parser.add_argument("--vessel", default="ego", help="vessel id (default: ego)")
    parser.add_argument(
        "--participant", help="lockstep name (default: the vessel's controller.participant)"
    )
    parser.add_argument(
        "--timeout", type=float, default=30.0, help="seconds to wait for the run (default: 30)"
    )


def _controller_of(info: WorldInfo, vessel: str | None) -> str:
    """The participant named by the vessel's `controller.participant` (no vessel named: the
    world's only such seat), the default of a stack's `--participant`; NotAParticipant
    names what to give when there is none."""
    seats = {v.id: v.controller.participant for v in info.vessels.values()
             if v.controller is not None and v.controller.participant}  # fmt: skip
    if vessel is None and len(seats) == 1:
        vessel = next(iter(seats))
    if vessel in seats:
        return seats[vessel]
    why = (f"vessel {vessel!r} of world {info.name!r} has no controller participant"
           if vessel is not None else
           f"no vessel named, and world {info.name!r} has {len(seats)} controller participants, "
           "not one")  # fmt: skip
    raise NotAParticipant(f"no participant named and {why}: give one (--participant NAME; it "
                          f"expects {', '.join(info.external) or 'none'})")  # fmt: skip


def _told(exc: BaseException) -> str:
    """A stack's exception as the fault the run's error quotes."""
    return f"{type(exc).__name__}: {exc}"


def _endpoints(given: str | Sequence[str]) -> tuple[str, ...]:
    """A string is one endpoint, not a sequence of one-letter ones ('t', 'c', 'p', ...)."""
    return (given,) if isinstance(given, str) else tuple(given)
