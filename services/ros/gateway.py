"""The gateway's work at each step: the world out as ROS 2 topics, ROS commands in.

Out (catabot/ros2: the recorder's conversion): every vessel's `odom`, `/tf` a tick, sensor
topics, `/clock`, and once, latched, `/tf_static` and `/buoys`. Nothing is converted for a
topic nobody subscribes to. `/clock` is the newest state's stamp (observer) or the tick's
(lockstep), every tick or at `ros.clock_hz`.

In: a command for a vessel whose controller is this gateway (`controller.participant:
"ros"`, `ros.lockstep: true`) is held and published on its clocked stream at the next
controller tick, tagged with it, so physics applies it at the same tick on every run (the
`vessels[].controller` mechanism, DESIGN.md §8). Any other command is published at once,
free-running (tick -1): physics applies it at its next tick boundary.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import zenoh

from catabot.bus import codec
from catabot.bus.clock import Stream
from catabot.bus.inbox import Inputs
from catabot.bus.messages import BodyStates, Message, ThrustCmd, Tick, TwistCmd, check_ids
from catabot.bus.rejections import Rejections
from catabot.bus.session import BLOCK
from catabot.config.rates import rate_in_ticks
from catabot.config.ros import GATEWAY, RosConfig
from catabot.ros2 import types
from catabot.ros2.convert import Converter
from catabot.ros2.convert_sensors import Out
from catabot.ros2.names import CLOCK, TF
from catabot.ros2.wire import topic_qos
from catabot.run.advice import advise
from catabot.world.world import World
from services.ros.inbound import Command, Inbound
from services.ros.wire import Outlet, Wire

log = logging.getLogger("ros.gateway")
KINDS = {"twist": "cmd_vel", "thrust": "thrust"}  # controller.command -> ROS command


@dataclass
class Control:
    """A vessel this gateway drives in the lockstep: its clocked stream and last command."""

    stream: Stream
    command: str  # the ROS command that feeds it: cmd_vel or thrust
    last: Message
    fresh: Message | None = None  # the reply to this tick's /clock; None if refused
    replied: bool = False  # a reply came (refused or not): the wait for it is over


class Gateway:
    """Converts and publishes what the world produces; routes what ROS commands.
    `publish`: how a clocked command goes out (the lockstep participant's publish)."""

    def __init__(
        self,
        world: World,
        ros: RosConfig,
        session: zenoh.Session,
        publish: Callable[[str, Message], None] | None = None,
        on_command: Callable[[], None] = lambda: None,
        *,
        rejections: Rejections,
    ) -> None:
        self.world, self.ros, self.keys = world, ros, world.keys
        self.convert = convert = Converter(world, ros, boats=ros.traffic)
        self.wire = wire = Wire(session, ros)
        self.odom = [Outlet(wire, topic, types.ODOMETRY) for topic in convert.odom_topics]
        self.tf = Outlet(wire, TF, types.TF)
        self.clock = Outlet(wire, CLOCK, types.CLOCK)
        self.clock_every = _period(world, ros)
        self.sensors = {
            world.keys.relative(s.key): [
                Outlet(wire, topic, kind) for topic, kind in convert.names.sensor_topics(s)
            ]
            for s in world.sensors
        }
        self.outlets = {o.topic: o for outlets in self.sensors.values() for o in outlets}
        self.latched = [self._latch(out) for out in (convert.static_tf(), convert.buoys()) if out]
        vessels = [v for v in world.vessels if ros.traffic or v.kind == "vessel"]
        self.inbound = Inbound(wire, convert.names, vessels, ros, on_command, rejections=rejections)
        self._session, self._publish = session, publish
        self._free: dict[str, zenoh.Publisher] = {}
        streams = world.streams
        self._checks = {s.key: s.check for s in (*streams.commands, *streams.waypoints)}
        self.controls = _controls(world)
        self._silent_ticks = 0  # controller ticks the stack did not answer in time
        self._odom_version = self._wanted_version = -1
        self._odom_watched: list[int] = []
        self._wanted_keys: frozenset[str] = frozenset()
        log.info(
            "publishing %d topics (%s, domain %d), %d vessels take commands, %s",
            len(self.odom) + len(self.outlets) + len(self.latched) + 2,
            " and ".join(wire.conventions), ros.domain_id, len(vessels),
            "in the lockstep" if ros.lockstep else "observing",
        )  # fmt: skip

    def _latch(self, out: Out) -> Outlet:
        """A topic sent once and kept for late subscribers (/tf_static, /buoys)."""
        outlet = Outlet(self.wire, out.topic, out.type, topic_qos(out.topic))
        outlet.put(out.data)
        return outlet

    # -- out -----------------------------------------------------------------------------

    def publish(self, inputs: Inputs, *, clock_from_states: bool) -> None:
        """Everything in `inputs` that someone subscribes to; `clock_from_states`: /clock
        follows each state's stamp (the observer, which sees no ticks)."""
        states = self.keys.world_states()
        for batch in inputs.get(states, []):
            if isinstance(batch, BodyStates):
                self._states(batch)
                if clock_from_states:
                    self.tick_clock(batch.tick + 1, batch.stamp_ns)  # stamped t_(k+1)
        for key, msgs in inputs.items():
            if key != states:
                self._sensor(self.keys.relative(key), msgs)

    def wanted(self) -> frozenset[str]:
        """The stream keys some subscribed topic is built from (the observer subscribes to
        these only): states for odom, /tf and /clock, each sensor for its topics."""
        if self._wanted_version != self.wire.version:
            self._wanted_version = self.wire.version
            odom = any(o.sends for o in (*self.odom, self.tf, self.clock))
            keys = {self.keys.world_states()} if odom else set()
            for stream, outlets in self.sensors.items():
                if any(o.sends for o in outlets):
                    keys.add(f"{self.keys.prefix}/{stream}")
            self._wanted_keys = frozenset(keys)
        return self._wanted_keys

    def _watched_odom(self) -> list[int]:
        """Indices of the odom outlets someone subscribes to, found again only when a
        subscription came or went."""
        if self._odom_version != self.wire.version:
            self._odom_version = self.wire.version
            self._odom_watched = [i for i, outlet in enumerate(self.odom) if outlet.sends]
        return self._odom_watched

    def _states(self, batch: BodyStates) -> None:
        watched = self._watched_odom()
        try:
            check_ids("world/states", batch.tick, batch.ids, self.world.body_ids)
            if watched:
                payloads, odom = self.convert.odometry(batch), self.odom
                for i in watched:
                    for send in odom[i].sends:
                        send(payloads[i])
            if self.tf.watched:
                self.tf.put(self.convert.tf(batch))
        except ValueError as exc:
            log.error("not published: %s", exc)

    def _sensor(self, stream: str, msgs: list[Message]) -> None:
        """Only the topics someone subscribes to are built (a radar's PPI is painted by
        every sweep all the same, so it is whole when someone looks)."""
        wanted = {outlet.topic for outlet in self.sensors.get(stream, []) if outlet.watched}
        for msg in msgs:
            try:
                outs = self.convert.sensor(stream, msg, wanted.__contains__)
            except ValueError as exc:
                log.error("not published: %s", exc)
                continue
            for out in outs:
                self.outlets[out.topic].put(out.data)

    def tick_clock(self, tick: int, stamp_ns: int, *, force: bool = False) -> None:
        if (force or tick % self.clock_every == 0) and self.clock.watched:
            self.clock.put(self.convert.clock(stamp_ns).data)

    # -- in ------------------------------------------------------------------------------

    def takes_commands(self, tick: Tick) -> bool:
        """Whether a vessel this gateway controls takes a command at `tick` (then /clock
        goes out whatever `ros.clock_hz`: the stack replies to it)."""
        return any(tick.tick % (c.stream.period or 1) == 0 for c in self.controls.values())

    def clocked(self, tick: Tick) -> None:
        """A lockstep tick: this tick's /clock, then the controlled vessels' commands, each
        the stack's reply to that /clock. A reply that came before it was sent answers an
        earlier one: dropped. (Taken at the next controller tick, a late reply to /clock 0
        raced the reply to /clock 10, and two runs of one stack differed.)"""
        takes = self.takes_commands(tick)
        until = time.monotonic() + self.ros.reply_timeout_s  # the whole wait of this tick
        if takes and tick.tick == 0:
            self._await_stack(until)  # before the first /clock: a stack to answer it
        for cmd in self.inbound.take():
            self._route(cmd)
        for control in self.controls.values():
            if takes and tick.tick % (control.stream.period or 1) == 0:
                control.fresh, control.replied = None, False
        self.tick_clock(tick.tick, tick.stamp_ns, force=takes)
        self.commands(tick, until=until)

    def commands(self, tick: Tick | None = None, *, until: float | None = None) -> None:
        """Route the commands received so far. At a tick where a vessel this gateway
        controls takes a command, publish it clocked, waiting for the ROS stack's reply to
        this tick's /clock until `until` (`ros.reply_timeout_s` after the tick began, the
        wait for a first subscriber included: the two had outlasted the clock's deadline);
        with nobody subscribed to /clock, nobody can reply: the last command holds at once."""
        for cmd in self.inbound.take():
            self._route(cmd)
        if tick is None:
            return
        until = time.monotonic() + self.ros.reply_timeout_s if until is None else until
        for vessel, control in self.controls.items():
            if tick.tick % (control.stream.period or 1):
                continue
            if not control.replied and self.clock.watched:
                self._await(vessel, control, tick, until)
            msg = control.fresh or control.last
            control.last, control.fresh, control.replied = msg, None, False
            assert self._publish is not None, "a lockstep gateway publishes its controls"
            clocked = replace(msg, tick=tick.tick, stamp_ns=tick.stamp_ns)  # type: ignore[call-arg]
            self._publish(control.stream.key, clocked)

    def _route(self, cmd: Command) -> None:
        control = self.controls.get(cmd.vessel)
        if control is not None and cmd.name == control.command:
            if not control.replied:  # the first reply to this /clock: a second one won
                control.fresh, control.replied = cmd.message, True  # as it happened to arrive
            else:
                why = ValueError("a second reply to one /clock: the first is taken (a "
                                 "lockstep stack replies once per /clock)")  # fmt: skip
                self.inbound.refuse(self.convert.names.topic(cmd.vessel, cmd.name), why)
            return
        if cmd.message is None:  # refused, and counted, where it arrived
            return
        key = {
            "cmd_vel": self.keys.cmd_twist,
            "thrust": self.keys.cmd_thrust,
            "waypoints": self.keys.cmd_waypoints,
        }[cmd.name](cmd.vessel)
        if not self._allowed(key, cmd):
            return
        publisher = self._free.get(key)
        if publisher is None:
            publisher = self._free[key] = self._session.declare_publisher(
                key, congestion_control=BLOCK
            )
        publisher.put(codec.encode(cmd.message))

    def _allowed(self, key: str, cmd: Command) -> bool:
        """The bus's own check of a free command, here: a path for the ego or a twist for a
        vessel a controller drives would be refused in physics' log, unseen by ROS users."""
        check = self._checks.get(key)
        try:
            if check is not None:
                check(cmd.message)
        except ValueError as exc:
            self.inbound.refuse(self.convert.names.topic(cmd.vessel, cmd.name), exc)
            return False
        return True

    def _await_stack(self, until: float) -> None:
        """Before the first command: wait for a /clock subscriber, the stack that answers
        (a clock sent before its subscription is known would reach nobody)."""
        while not self.clock.watched and time.monotonic() < until:
            time.sleep(0.01)
        if not self.clock.watched:
            advise(log, "nobody subscribes to /clock: the controlled vessels hold their last "
                        "command (at first: rest) until a stack does")  # fmt: skip

    def _await(self, vessel: str, control: Control, tick: Tick, until: float) -> None:
        while not control.replied:
            left = until - time.monotonic()
            if left <= 0:
                said = (f"no {control.command} for {vessel} at tick {tick.tick} within "
                        f"{self.ros.reply_timeout_s:g} s: the last one holds (this run is no "
                        "longer reproducible)")  # fmt: skip
                if self._silent_ticks == 0:  # on the console once; each one in the log
                    advise(log, f"{said}; every tick without a reply waits as long again")
                else:
                    log.warning("%s", said)
                self._silent_ticks += 1
                return
            for cmd in self.inbound.wait(left):
                self._route(cmd)

    def close(self) -> None:
        self.inbound.close()
        self.wire.close()


def _period(world: World, ros: RosConfig) -> int:
    """/clock every this many ticks."""
    if ros.clock_hz is None:
        return 1
    return rate_in_ticks(ros.clock_hz, world.scenario.dt_ns, where="ros.clock_hz")


def _controls(world: World) -> dict[str, Control]:
    """The vessels whose controller is this gateway, with a neutral first command."""
    out = {}
    for stream in world.streams.controls:
        if stream.producer != GATEWAY:
            continue
        vessel = world.body(world.keys.vessel_of(stream.key))
        assert vessel.controller is not None
        kind = vessel.controller.command
        neutral: Message = (
            TwistCmd(0.0, 0.0) if kind == "twist"
            else ThrustCmd(tuple(0.0 for _ in vessel.model.thrusters))
        )  # fmt: skip
        out[vessel.id] = Control(stream, KINDS[kind], neutral)
    return out
