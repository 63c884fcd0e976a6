"""The conductor's `world/info` queryable: the resolved world as JSON, for autonomy stacks.

A stack (catabot/client/) must join a run without the scenario file, DART or open3d: it
asks `catabot/<world>/world/info` (or `catabot/*/world/info` to find the running worlds) and
gets what the `World` resolved: every vessel with its model, thrusters, controller and
command keys, every sensor with its type, rate, period in ticks, key, frame and mount, the
traffic boats, the buoys, the participants, the clock's limits, the streams a stack reads
(key, producer, period) and the roster (name -> zid), so the client checks each sample's
sender as a participant does (catabot/bus/identity.py). `granted` is the last tick the clock
has granted (-1: the run has not started), which tells a late joiner it is too late.

The answer is built once (a function of the scenario and the roster); the callback only
adds `granted` and never blocks a Zenoh thread. Only the conductor declares it (in the
secure profile the router lets no one else: catabot/run/secure.py).
"""

from __future__ import annotations

import json
import logging
import math
import threading
from typing import Any

import numpy as np
import zenoh

from catabot.bus.identity import Roster
from catabot.bus.keys import Keys
from catabot.bus.settings import Schedule
from catabot.config.ros import RosConfig
from catabot.config.scenario import Scenario, services
from catabot.config.sensors import SENSOR_TYPES
from catabot.ros2 import frames
from catabot.ros2.names import Names
from catabot.world import rotations
from catabot.world.world import Body, MountedSensor, World

log = logging.getLogger("catabot.run.world_info")
VERSION = 1  # of the answer's layout; catabot/client/info.py refuses another
START_FIELDS = ("position", "orientation", "linear_velocity", "angular_velocity")


def describe(world: World, roster: Roster) -> dict[str, Any]:
    """Everything a joining stack needs, as plain JSON values."""
    s = world.scenario
    limits, states = world.clock_limits, world.streams.states
    names = Names(world, s.ros or RosConfig())
    stepping = world.participants
    return {
        "v": VERSION,
        "world": s.name,
        "seed": s.seed,
        "dt_ns": s.dt_ns,
        "duration_s": s.duration_ns / 1e9,
        "clock": {
            "dt_ns": limits.dt_ns,
            "ticks": limits.ticks,
            "window": limits.window,
            "digest": limits.digest,  # of the scenario: every participant checks Tick.digest
            "realtime_factor": s.clock.realtime_factor,
            "deadline_s": s.clock.deadline_s,
            "start_timeout_s": s.clock.start_timeout_s,
            "policy": s.clock.policy,
        },
        "participants": {
            "stepping": stepping,
            "services": [n for n in services(s) if n in stepping],
            "external": [n for n in stepping if n not in services(s)],
        },
        "roster": dict(roster.fixed),
        "states": {
            "key": states.key,
            "producer": states.producer,
            "period": states.period,
            "stamp_ticks": states.stamp_ticks,
        },
        "bodies": [_body(b) for b in world.bodies],
        "start": _start(world),
        "vessels": [_vessel(world, names, v) for v in world.vessels if v.kind == "vessel"],
        "traffic": list(world.boat_ids),
        "boats": [_vessel(world, names, v) for v in world.vessels if v.kind == "boat"],
        "buoys": [
            {"id": b.id, "row": b.row, "x_m": b.pose.x_m, "y_m": b.pose.y_m} for b in world.buoys
        ],
        "scenario": s.model_dump(mode="json"),
    }


def _body(b: Body) -> dict[str, Any]:
    pose = {"x_m": b.pose.x_m, "y_m": b.pose.y_m, "yaw_rad": b.pose.yaw_rad}
    return {"id": b.id, "kind": b.kind, "row": b.row, "pose": pose}


def _vessel(world: World, names: Names, v: Body) -> dict[str, Any]:
    keys, c = world.keys, v.controller
    controls = {world.keys.vessel_of(x.key): x for x in world.streams.controls}
    control = controls.get(v.id)
    controller = None
    if c is not None and control is not None:
        controller = {
            "participant": c.participant,
            "rate_hz": c.rate_hz,
            "command": c.command,
            "key": control.key,
            "period_ticks": control.period,
        }
    return {
        "id": v.id,
        "kind": v.kind,
        "row": v.row,
        "model": v.model_ref,
        "thrusters": len(v.model.thrusters),
        "state_key": keys.vessel_state(v.id),
        "commands": {
            "thrust": keys.cmd_thrust(v.id),
            "twist": keys.cmd_twist(v.id),
            "waypoints": keys.cmd_waypoints(v.id),
        },
        "controller": controller,
        "sensors": [_sensor(world, names, m) for m in world.sensors if m.vessel == v.id],
    }


def _start(world: World) -> dict[str, list[list[float]]]:
    """Every body's start as physics starts it (World.start_states: pose, tilt, velocity):
    what a stack observes before the first state arrives."""
    start = world.start_states()
    return {name: getattr(start, name).tolist() for name in START_FIELDS}


def _sensor(world: World, names: Names, m: MountedSensor) -> dict[str, Any]:
    xyz, rot = frames.mount(m)
    return {
        "name": m.config.name,
        "type": m.config.type,
        "message": SENSOR_TYPES[m.config.type].message.TYPE,
        "rate_hz": m.config.rate_hz,
        "period_ticks": m.period,
        "key": m.key,
        "producer": world.sensor_owners[m.key],  # `sensors`, or its shard
        "frame": names.sensor_frame(m),
        "mount": {
            "xyz": list(xyz),
            "rpy": _rpy(rot),
            "quaternion": list(rotations.quaternion_of_matrix(rot)),
        },
        "params": m.params.model_dump(mode="json"),
    }


def _rpy(rot: np.ndarray) -> list[float]:
    """Roll, pitch, yaw (rad) of Rz(yaw) Ry(pitch) Rx(roll): the mount's turn in its body."""
    pitch = math.asin(max(-1.0, min(1.0, -float(rot[2, 0]))))
    roll = math.atan2(float(rot[2, 1]), float(rot[2, 2]))
    return [roll, pitch, rotations.yaw_of_matrix(rot)]


class WorldInfoDesk:
    """The queryable; answers `describe(...)` plus the clock's grant so far. The world is
    resolved on a thread of its own (a large traffic plan takes a while), so the conductor
    is ready at once; until it is served a query finds nothing and the client asks again."""

    def __init__(
        self, session: zenoh.Session, scenario: Scenario, roster: Roster, schedule: Schedule
    ) -> None:
        self.schedule, self.key = schedule, Keys(scenario.name).world_info()
        self._lock = threading.Lock()
        self._closed = False
        self._queryable: zenoh.Queryable | None = None
        self._answer: dict[str, Any] = {}
        self._behaviours: dict[str, str] = {}
        self.served = threading.Event()
        args = (session, scenario, roster)
        threading.Thread(target=self._serve, args=args, name="world-info", daemon=True).start()

    def _serve(self, session: zenoh.Session, scenario: Scenario, roster: Roster) -> None:
        try:
            world = World.resolve(scenario)
            self._answer = describe(world, roster)
            self._behaviours = {b.id: b.behaviour for b in world.traffic.boats}
        except Exception:  # the run goes on without it; the log says why
            log.exception("world/info cannot be served")
            return
        with self._lock:
            if not self._closed:
                self._queryable = session.declare_queryable(self.key, self._on_query)
                self.served.set()

    def _on_query(self, query: zenoh.Query) -> None:
        try:
            query.reply(self.key, json.dumps({**self._answer, "granted": self.schedule.granted}))
        except zenoh.ZError as exc:  # the asker gave up; nothing to do
            log.warning("could not answer a world info query: %s", exc)

    def behaviours(self) -> dict[str, str]:
        """Each traffic boat's planned behaviour (empty until the world is resolved)."""
        return self._behaviours

    def close(self) -> None:
        with self._lock:
            self._closed = True
            if self._queryable is not None:
                self._queryable.undeclare()
