"""The sensors service: every sensor of every vessel, each at its own whole-tick period.

At tick k it samples from the newest vessel states (tagged k-1, stamped t_k: the state
at the start of this tick) and publishes samples tagged k stamped t_k. At tick 0 no
state has been published yet, so the scenario's start pose at rest stands in: it is
exactly the state physics starts from. Ray-casting sensors (LiDAR, radar, cameras) share one
Scene, built once; it needs every body's pose. Every state comes in one `BodyStates` per
tick (`world/states`), whose rows are looked up by body id.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

from catabot.bus.inbox import Inputs
from catabot.bus.messages import BodyStates, Message, Tick, VesselState
from catabot.bus.participant import Participant
from catabot.config.scenario import Pose, Scenario, VesselConfig
from catabot.run.service import Built, ServiceContext, run_service
from catabot.world.streams import BodyRows, body_ids, states_stream
from catabot.world.terrain import load_terrain
from catabot.world.traffic_plan import all_buoys, all_vessels
from catabot.world.waves import WaveField
from services.sensors.registry import Sensor, build_sensor
from services.sensors.scene import Scene, bodies_for

SCENE_SENSORS = ("lidar", "radar", "camera")  # types that cast rays into the shared Scene


@dataclass
class Mounted:
    vessel: str
    key: str
    period: int
    sensor: Sensor
    casts: bool  # a ray-casting sensor: it needs the Scene posed at its tick


class SensorsService:
    def __init__(self, ctx: ServiceContext) -> None:
        scenario = ctx.scenario
        self.scene = build_scene(scenario) if needs_scene(scenario) else None
        self.mounted = [
            Mounted(
                v.id,
                ctx.keys.sensor(v.id, s.name),
                s.period_ns // scenario.dt_ns,
                build_sensor(
                    s,
                    vessel_id=v.id,
                    seed=scenario.seed,
                    origin=scenario.origin,
                    dt_ns=scenario.dt_ns,
                    scene=self.scene,
                ),
                s.type in SCENE_SENSORS,
            )
            for v in scenario.vessels
            for s in v.sensors
        ]
        carriers = {m.vessel for m in self.mounted}
        self.states = {v.id: start_state(v) for v in scenario.vessels if v.id in carriers}
        # the scene needs every vessel's and buoy's pose; at tick 0, the start poses at rest,
        # then the newest batch's arrays
        self.poses = {vid: (s.position, s.orientation) for vid, s in start_states(scenario).items()}
        self.batch: BodyStates | None = None
        self.states_key = ctx.keys.world_states()
        self.rows = BodyRows(body_ids(scenario))
        self.participant = Participant(
            ctx.session, ctx.keys, ctx.name, inputs=[states_stream(ctx.keys)], peers=ctx.peers
        )

    def step(self, tick: Tick, inputs: Inputs) -> None:
        batches = inputs.get(self.states_key)
        if batches:
            self._take(batches[-1])
        due = [m for m in self.mounted if tick.tick % m.period == 0]
        if any(m.casts for m in due):
            self._pose_scene(tick)
        for m in due:
            sample = m.sensor.sample(self.states[m.vessel], tick=tick.tick, stamp_ns=tick.stamp_ns)
            self.participant.publish(m.key, sample)

    def _pose_scene(self, tick: Tick) -> None:
        """Every body where it is at this tick; only on ticks a ray-casting sensor is due
        (posing 100 boats each tick for a 10 Hz LiDAR cost ~0.05 ms a tick for nothing)."""
        assert self.scene is not None
        if self.batch is not None:
            b = self.batch
            self.scene.update_arrays(b.ids, b.position, b.orientation, tick.stamp_ns / 1e9)
        else:
            self.scene.update(self.poses, tick.stamp_ns / 1e9)

    def _take(self, batch: Message) -> None:
        """The carriers' states as `VesselState` (what sensors sample); the batch itself
        for the scene, which takes every body's pose straight from its arrays."""
        assert isinstance(batch, BodyStates)
        row = self.rows.check(batch)
        for vid in self.states:
            self.states[vid] = batch.row(row[vid])
        self.batch = batch


def needs_scene(scenario: Scenario) -> bool:
    return any(s.type in SCENE_SENSORS for v in scenario.vessels for s in v.sensors)


def build_scene(scenario: Scenario) -> Scene:
    """The ray-casting world, built once: terrain, the physics' waves, every body."""
    terrain = load_terrain(scenario.terrain) if scenario.terrain is not None else None
    return Scene(
        terrain=terrain,
        waves=WaveField(scenario.water.waves, scenario.seed),
        bodies=bodies_for(scenario),
        rain_rate_mm_h=scenario.rain.rate_mm_h,
    )


def start_states(scenario: Scenario) -> dict[str, VesselState]:
    """Every vessel (traffic included) and buoy at rest at its start pose."""
    states = {v.id: start_state(v) for v in all_vessels(scenario)}
    for b in all_buoys(scenario):
        states[b.id] = start_state(VesselConfig(id=b.id, pose=Pose(x_m=b.x_m, y_m=b.y_m)))
    return states


def start_state(vessel: VesselConfig) -> VesselState:
    """The vessel at rest at its start pose, as physics creates it at t = 0."""
    p = vessel.pose
    assert p is not None, "poses are resolved before services start"
    half = p.yaw_rad / 2
    zero = (0.0, 0.0, 0.0)
    quat = (0.0, 0.0, math.sin(half), math.cos(half))
    return VesselState(-1, 0, (p.x_m, p.y_m, 0.0), quat, zero, zero, zero, zero)


def build(ctx: ServiceContext) -> Built:
    service = SensorsService(ctx)
    return service.participant, service.step, None


def main(argv: list[str] | None = None) -> int:
    return run_service("sensors", build, argv)


if __name__ == "__main__":
    sys.exit(main())
