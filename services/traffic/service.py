"""The traffic service: each boat's behaviour turns its state into a twist set-point.

At every guidance tick k (a multiple of the period of `traffic.guidance_hz`) it reads the
boats' rows of the `BodyStates` tagged k-1 (at t_k; the plan's start poses at rest at
tick 0), runs the guidance laws for all boats at once and publishes every boat's set-point
in one `TwistBatch` on `world/cmd/twist` tagged k, which physics applies from tick k+1 (the
one-tick delay of DESIGN.md §4) and holds until the next one, as an autopilot's inner loop
holds its outer loop's last order. External control never fights these
set-points: physics lets an external twist or thrust (tick -1) outrank them until a
`WaypointsCmd` hands the boat back; a `WaypointsCmd` with a path makes this service steer
that path instead, and `mode="release"` restores the scenario behaviour.
"""

from __future__ import annotations

import sys
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from catabot.bus.inbox import Inputs
from catabot.bus.messages import BodyStates, Message, Tick, TwistBatch, WaypointsCmd
from catabot.bus.settings import changes_of
from catabot.config import live
from catabot.config.rates import guidance_period_ticks
from catabot.config.traffic import AvoidParams
from catabot.run.service import Built, ServiceContext, run_service
from catabot.world import rotations
from catabot.world.course import top_speed_mps
from catabot.world.placement import footprint_m
from catabot.world.world import World
from services.traffic.avoid import KeepClear, Obstacles
from services.traffic.behaviours import Behaviours
from services.traffic.outside import OutsidePaths


class TrafficService:
    def __init__(self, ctx: ServiceContext) -> None:
        world = ctx.world
        self.ids = world.traffic_blocks[ctx.name]  # every boat, or this shard's block
        mine = set(self.ids)
        boats = [b for b in world.traffic.boats if b.id in mine]
        self.row = {vid: i for i, vid in enumerate(self.ids)}
        self.keys = ctx.keys
        avoid = ctx.scenario.traffic.avoid
        clear, self.obstacles, self.obstacle_rows = keep_clear(world, self.ids, avoid)
        self.behaviours = Behaviours(boats, hold_gain=ctx.scenario.traffic.hold.gain, clear=clear)
        n = len(boats)
        self.pos = np.array([(b.pose.x_m, b.pose.y_m) for b in boats], dtype=np.float64)
        self.yaw = np.array([b.pose.yaw_rad for b in boats], dtype=np.float64)
        self.vel = np.zeros((n, 2))
        states = world.streams.guidance_states  # only the batches guidance reads
        self.states_key = states.key
        self.boat_rows = np.array([world.body(vid).row for vid in self.ids], dtype=np.intp)
        top = [top_speed_mps(world.body(vid).model) for vid in self.ids]
        self.outside = OutsidePaths(self.ids, top)  # said on the console
        waypoints = [s for s in world.streams.waypoints if ctx.keys.vessel_of(s.key) in self.row]
        (self.twists_key,) = [s.key for s in world.streams.twists if s.producer == ctx.name]
        self.period = guidance_period_ticks(ctx.scenario)
        self.traffic, self.specs = ctx.scenario.traffic, live.keys_of(ctx.scenario)
        self.participant = ctx.participant([states, *waypoints])

    def step(self, tick: Tick, inputs: Inputs) -> None:
        guide = tick.tick % self.period == 0
        for key, msgs in inputs.items():
            if key == self.states_key:
                self._take_states(msgs[-1])  # tagged k - 1: released at guidance ticks only
                continue
            i = self.row[self.keys.vessel_of(key)]
            for msg in msgs:
                if isinstance(msg, WaypointsCmd):
                    self._take_waypoints(i, msg, tick.stamp_ns)
        for change in changes_of(tick.settings):
            self._take_setting(change.key, change.decoded)
        if guide:
            self._guide(tick)

    def _guide(self, tick: Tick) -> None:
        surge, rate = self.behaviours.command(self.pos, self.yaw, self.vel, self.obstacles)
        batch = TwistBatch(tick.tick, tick.stamp_ns, self.ids, surge, rate)
        self.participant.publish(self.twists_key, batch)

    def _take_states(self, batch: Message) -> None:
        """The boats' rows of the batch, all at once."""
        assert isinstance(batch, BodyStates)  # of this world's rows: checked on arrival
        rows = self.boat_rows
        self.pos = batch.position[rows, :2].copy()
        self.yaw = rotations.yaw_of_quaternions(batch.orientation[rows])
        self.vel = batch.linear_velocity[rows, :2].copy()
        if self.obstacles is not None:
            rows = self.obstacle_rows
            xy = batch.position[rows, :2].copy()
            yaw = rotations.yaw_of_quaternions(batch.orientation[rows])
            velocity = rotations.turn_xy(batch.linear_velocity[rows, :2], yaw)
            turn = batch.angular_velocity[rows, 2].copy()  # body z: the yaw rate, near level
            self.obstacles = replace(self.obstacles, xy=xy, velocity=velocity, turn_rate=turn)

    def _take_setting(self, key: str, value: object) -> None:
        """A boat's behaviour changed at run time, from its pose at the last guidance tick."""
        spec = self.specs.get(key)
        if spec is not None and spec.kind == "behaviour" and spec.owner in self.row:
            i = self.row[spec.owner]
            self.behaviours.set_behaviour(
                i, str(value), self.pos[i], float(self.yaw[i]), self.traffic
            )

    def _take_waypoints(self, i: int, msg: WaypointsCmd, stamp_ns: int) -> None:
        """Adopt a path from outside, or release the boat (paths are checked on arrival:
        catabot/bus/checks.py), said on the console (outside.py)."""
        if msg.mode == "release":
            self.behaviours.release(i)
            self.outside.released(i, stamp_ns)
            return
        points = np.array(msg.points, dtype=np.float64).reshape(-1, 2)
        self.behaviours.set_path(i, points, msg.speed, loop=msg.mode == "loop", tol=msg.tolerance)
        self.outside.taken(i, msg, stamp_ns)


def keep_clear(
    world: World, ids: tuple[str, ...], avoid: AvoidParams
) -> tuple[KeepClear, Obstacles | None, NDArray[np.intp]]:
    """How the boats `ids` keep clear (services/traffic/avoid.py), what of at the start, and
    those bodies' rows in `BodyStates`."""
    radius = {b.model_ref: footprint_m(b.model) for b in world.bodies}
    own_r = np.array([radius[world.body(vid).model_ref] for vid in ids])
    buoys = world.buoys if avoid.buoys else ()
    anchors = np.array([(b.pose.x_m, b.pose.y_m) for b in buoys]).reshape(-1, 2)
    buoy_r = max((radius[b.model_ref] for b in buoys), default=0.0)
    pass_m = own_r + buoy_r + avoid.clearance_m if buoys else np.zeros(len(ids))
    clear = KeepClear(anchors, pass_m, own_r + avoid.clearance_m, avoid.lookahead_s)
    wanted = {"buoy": avoid.buoys, "boat": avoid.boats}
    bodies = [b for b in world.bodies if wanted.get(b.kind, avoid.vessels)]
    rows = np.array([b.row for b in bodies], dtype=np.intp)
    if not bodies:
        return clear, None, rows
    where = {b.id: k for k, b in enumerate(bodies)}
    xy = np.array([(b.pose.x_m, b.pose.y_m) for b in bodies])
    r = np.array([radius[b.model_ref] for b in bodies])
    itself = np.array([where.get(vid, -1) for vid in ids], np.intp)  # a boat's own obstacle
    under_way = np.array([b.kind != "buoy" for b in bodies])
    still = np.zeros(len(bodies))
    return clear, Obstacles(xy, r, itself, np.zeros_like(xy), still, under_way, home=xy), rows


def build(ctx: ServiceContext) -> Built:
    service = TrafficService(ctx)
    return service.participant, service.step, None


def main(argv: list[str] | None = None) -> int:
    return run_service("traffic", build, argv, shardable=True)


if __name__ == "__main__":
    sys.exit(main())
