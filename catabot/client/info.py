"""The world a stack joins, as typed objects: the conductor's `world/info` answer, parsed.

The answer (catabot/run/world_info.py) is all a stack needs instead of the scenario file:
vessels, sensors, streams with their producers and periods, the clock's limits and the
roster. It comes over Zenoh, so it is parsed as untrusted input: a malformed answer is a
`ClientError` naming the field, never a KeyError deep inside a step.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from catabot.bus import checks
from catabot.bus.clock import ClockLimits, Stream
from catabot.bus.identity import Roster
from catabot.bus.messages import MESSAGE_TYPES, BodyStates, Message, ThrustCmd, TwistCmd
from catabot.client.errors import ClientError, UnknownSensor
from catabot.errors import CataBotError

VERSION = 1
MessageType = type[Message]  # a field named `type` shadows the builtin inside the class
COMMANDS: dict[str, type[Message]] = {"thrust": ThrustCmd, "twist": TwistCmd}


@dataclass(frozen=True)
class SensorInfo:
    """One sensor: `period_ticks` ticks between samples, produced by `producer` on `key`;
    `frame` is its ROS frame id, `mount` its pose in the body frame (FLU): xyz in m, rpy
    (roll, pitch, yaw) in rad; `params` the type's parameters with every default."""

    name: str
    type: str
    rate_hz: float
    period_ticks: int
    key: str
    frame: str
    mount_xyz: tuple[float, float, float]
    mount_rpy: tuple[float, float, float]
    params: dict[str, Any]
    message: MessageType
    producer: str = "sensors"

    @property
    def mount(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        return self.mount_xyz, self.mount_rpy

    def stream(self) -> Stream:
        return Stream(self.key, self.message, self.producer, self.period_ticks)


@dataclass(frozen=True)
class ControllerInfo:
    """The lockstep participant that drives a vessel: its command is a clocked stream."""

    participant: str
    rate_hz: float
    command: str  # thrust | twist
    key: str
    period_ticks: int


@dataclass(frozen=True)
class VesselInfo:
    id: str
    model: str
    row: int  # its row in every `BodyStates`
    thrusters: int
    state_key: str
    command_keys: dict[str, str]  # thrust, twist, waypoints -> key
    controller: ControllerInfo | None
    sensors: dict[str, SensorInfo]
    kind: str = "vessel"  # or "boat": a traffic boat (it follows paths; no sensors)

    @property
    def command(self) -> str | None:
        """The command kind its controller sends in lockstep (None: no controller)."""
        return self.controller.command if self.controller is not None else None

    def sensor(self, name: str) -> SensorInfo:
        if name not in self.sensors:
            known = ", ".join(self.sensors) or "none"
            raise UnknownSensor(f"vessel {self.id!r} has no sensor {name!r}; its sensors: {known}")
        return self.sensors[name]

    def control_stream(self) -> Stream | None:
        """The clocked command stream its controller produces (with the content check)."""
        c = self.controller
        if c is None:
            return None
        check = checks.thrust(self.thrusters) if c.command == "thrust" else checks.twist
        return Stream(c.key, COMMANDS[c.command], c.participant, c.period_ticks, check=check)


@dataclass(frozen=True)
class Buoy:
    id: str
    row: int
    x_m: float
    y_m: float


@dataclass(frozen=True)
class WorldInfo:
    name: str
    seed: int
    dt_ns: int
    duration_s: float
    limits: ClockLimits
    participants: tuple[str, ...]  # every stepping participant (services, then external)
    external: tuple[str, ...]  # those started outside `catabot run` (stacks)
    roster: Mapping[str, str]  # name -> zid, as `catabot run` assigned them
    states_key: str
    states_producer: str
    body_ids: tuple[str, ...]  # the rows of every BodyStates
    vessels: dict[str, VesselInfo]  # scenario vessels (not traffic boats)
    traffic: tuple[str, ...]
    boats: dict[str, VesselInfo]  # the traffic boats, to observe and command from outside
    buoys: tuple[Buoy, ...]
    granted: int  # the last tick the clock had granted when asked (-1: not started)
    scenario: dict[str, Any] = field(repr=False)
    start: BodyStates = field(repr=False)  # every body at rest at its start pose (tick -1)

    @property
    def dt_s(self) -> float:
        return self.dt_ns / 1e9

    @property
    def ticks(self) -> int:
        return self.limits.ticks

    def states_stream(self) -> Stream:
        """`world/states`: every body in one BodyStates a tick, stamped at the tick's end."""
        check = checks.body_states(self.body_ids)
        return Stream(self.states_key, BodyStates, self.states_producer, 1, 0, 1, check)

    def new_roster(self) -> Roster:
        return Roster(self.roster)


def parse(data: Any, source: str) -> WorldInfo:
    """A `WorldInfo` from the decoded JSON answer; ClientError names what is malformed."""
    try:
        return _parse(data)
    except (KeyError, TypeError, ValueError, AttributeError, CataBotError) as exc:
        raise ClientError(
            f"malformed world info from {source}: {type(exc).__name__} {exc}"
        ) from None


def _parse(d: Mapping[str, Any]) -> WorldInfo:
    if d.get("v") != VERSION:
        raise ValueError(f"layout version {d.get('v')!r}, this client reads {VERSION}")
    c, p = d["clock"], d["participants"]
    bodies = d["bodies"]
    vessels = [_vessel(v) for v in d["vessels"]]
    return WorldInfo(
        name=str(d["world"]),
        seed=int(d["seed"]),
        dt_ns=int(d["dt_ns"]),
        duration_s=float(d["duration_s"]),
        limits=ClockLimits(
            int(c["dt_ns"]),
            int(c["ticks"]),
            int(c["window"]),
            str(c.get("digest", "")),
            float(c.get("deadline_s", 10.0)),
        ),
        participants=tuple(map(str, p["stepping"])),
        external=tuple(map(str, p["external"])),
        roster=Roster({str(k): str(v) for k, v in d["roster"].items()}).fixed,  # zids checked
        states_key=str(d["states"]["key"]),
        states_producer=str(d["states"]["producer"]),
        body_ids=tuple(str(b["id"]) for b in bodies),
        vessels={v.id: v for v in vessels},
        traffic=tuple(map(str, d["traffic"])),
        boats={b.id: b for b in map(_vessel, d.get("boats", []))},
        buoys=tuple(
            Buoy(str(b["id"]), int(b["row"]), float(b["x_m"]), float(b["y_m"])) for b in d["buoys"]
        ),
        granted=int(d.get("granted", -1)),
        scenario=dict(d["scenario"]),
        start=_start_states(d["start"], tuple(str(b["id"]) for b in bodies)),
    )


def _vessel(v: Mapping[str, Any]) -> VesselInfo:
    c = v["controller"]
    controller = None
    if c is not None:
        if c["command"] not in COMMANDS:
            raise ValueError(f"controller command {c['command']!r}")
        controller = ControllerInfo(
            str(c["participant"]),
            float(c["rate_hz"]),
            str(c["command"]),
            str(c["key"]),
            int(c["period_ticks"]),
        )
    sensors = [_sensor(s) for s in v["sensors"]]
    return VesselInfo(
        id=str(v["id"]),
        model=str(v["model"]),
        row=int(v["row"]),
        thrusters=int(v["thrusters"]),
        state_key=str(v["state_key"]),
        command_keys={str(k): str(x) for k, x in v["commands"].items()},
        controller=controller,
        sensors={s.name: s for s in sensors},
        kind="boat" if v.get("kind") == "boat" else "vessel",
    )


def _sensor(s: Mapping[str, Any]) -> SensorInfo:
    message = MESSAGE_TYPES[str(s["message"])]
    x, y, z = (float(a) for a in s["mount"]["xyz"])
    roll, pitch, yaw = (float(a) for a in s["mount"]["rpy"])
    return SensorInfo(
        name=str(s["name"]),
        type=str(s["type"]),
        rate_hz=float(s["rate_hz"]),
        period_ticks=int(s["period_ticks"]),
        key=str(s["key"]),
        frame=str(s["frame"]),
        mount_xyz=(x, y, z),
        mount_rpy=(roll, pitch, yaw),
        params=dict(s["params"]),
        message=message,
        producer=str(s["producer"]),
    )


def _start_states(d: Mapping[str, Any], ids: tuple[str, ...]) -> BodyStates:
    """Every body's start as physics starts it (the conductor sends World.start_states)."""
    n = len(ids)
    widths = {"position": 3, "orientation": 4, "linear_velocity": 3, "angular_velocity": 3}
    arrays = [np.asarray(d[k], dtype=np.float64).reshape(n, w) for k, w in widths.items()]
    if not all(np.isfinite(a).all() for a in arrays):
        raise ValueError("a start state is not finite")
    position, orientation, linear, angular = arrays
    zero = np.zeros((n, 3))
    return BodyStates(-1, 0, ids, position, orientation, linear, angular, zero, zero)
