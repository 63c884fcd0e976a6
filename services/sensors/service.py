"""The sensors service: every sensor of every vessel, each at its own whole-tick period.

At tick k it samples from the newest body states (tagged k-1, stamped t_k: the state at the
start of this tick) and publishes samples tagged k stamped t_k. At tick 0 no state has been
published yet, so the world's start states stand in: exactly the state physics starts from.
Ray-casting sensors (LiDAR, radar, cameras) share one Scene, built once; it takes every
body's pose from the newest `BodyStates` (`world/states`).
"""

from __future__ import annotations

import sys
from dataclasses import dataclass

from catabot.bus.inbox import Inputs
from catabot.bus.messages import BodyStates, Message, Tick, VesselState
from catabot.bus.settings import changes_of
from catabot.config.sensors import SENSOR_TYPES
from catabot.run.service import Built, ServiceContext, run_service
from catabot.world.world import World
from services.sensors.own_view import OwnView
from services.sensors.registry import Sensor, build_sensor
from services.sensors.scene import Body, Scene
from services.sensors.settings import SensorSettings


@dataclass
class Mounted:
    row: int  # the carrier's row in BodyStates
    key: str
    period: int
    sensor: Sensor
    casts: bool  # a ray-casting sensor: it needs the Scene posed at its tick


class SensorsService:
    def __init__(self, ctx: ServiceContext) -> None:
        world = ctx.world
        mine = [s for s in world.sensors if world.sensor_owners[s.key] == ctx.name]
        casts = any(SENSOR_TYPES[s.config.type].casts for s in mine)
        self.scene = build_scene(world) if casts else None
        self.mounted = [
            Mounted(
                world.body(s.vessel).row,
                s.key,
                s.period,
                build_sensor(s, world, scene=self.scene),
                SENSOR_TYPES[s.config.type].casts,
            )
            for s in mine  # a shard's: every sensor of its vessels (catabot/world/shards.py)
        ]
        self.carrier_rows = sorted({m.row for m in self.mounted})
        self.batch = world.start_states()
        self.states = self._carriers(self.batch)
        self.states_key = ctx.keys.world_states()
        self.settings = SensorSettings(world, self.scene, ctx.keys.sensor)
        self.models = {m.key: m.sensor for m in self.mounted}
        self.own_view = OwnView([(s.key, s.seed_name, world.body(s.vessel).instance)
                                 for s in mine if SENSOR_TYPES[s.config.type].casts])  # fmt: skip
        self.participant = ctx.participant([world.streams.states])

    def step(self, tick: Tick, inputs: Inputs) -> None:
        for change in changes_of(tick.settings):
            self.settings.apply(change, self.models)
        self.settings.waves(tick.tick)
        batches = inputs.get(self.states_key)
        if batches:
            self._take(batches[-1])
        off = self.settings.off
        due = [m for m in self.mounted if tick.tick % m.period == 0 and m.key not in off]
        if any(m.casts for m in due):
            self._pose_scene(tick)
        for m in due:
            sample = m.sensor.sample(self.states[m.row], tick=tick.tick, stamp_ns=tick.stamp_ns)
            self.participant.publish(m.key, sample)
            self.own_view.check(m.key, sample)

    def _pose_scene(self, tick: Tick) -> None:
        """Every body where it is at this tick; only on ticks a ray-casting sensor is due
        (posing 100 boats each tick for a 10 Hz LiDAR cost ~0.05 ms a tick for nothing)."""
        assert self.scene is not None
        b = self.batch
        self.scene.update_arrays(b.ids, b.position, b.orientation, tick.stamp_ns / 1e9)

    def _take(self, batch: Message) -> None:
        """The batch for the scene (every pose from its arrays) and the carriers' rows as
        `VesselState` (what sensors sample)."""
        assert isinstance(batch, BodyStates)  # of this world's rows: checked on arrival
        self.batch = batch
        self.states = self._carriers(batch)

    def _carriers(self, batch: BodyStates) -> dict[int, VesselState]:
        """One `VesselState` per carrier (not per sensor: a row costs ~10 us)."""
        return {row: batch.row(row) for row in self.carrier_rows}


def build_scene(world: World) -> Scene:
    """The ray-casting world, built once: terrain, the physics' waves, every body's shape."""
    scenario = world.scenario
    return Scene(
        terrain=world.terrain,
        waves=world.waves,
        bodies=scene_bodies(world),
        rain_rate_mm_h=scenario.rain.rate_mm_h,
    )


def scene_bodies(world: World) -> list[Body]:
    """Every body of the world, in row order, as its model's shape (catabot/world/shapes.py)
    inside that shape's box, or as the box around its model's hulls for a model without
    one. Bodies of one model share one mesh: the scene builds one Embree scene per model."""
    boxes = {}
    for b in world.bodies:
        if b.model_ref not in boxes:
            mesh = world.shapes[b.model_ref]
            lo, hi = (mesh.lo, mesh.hi) if mesh is not None else b.model.hull_box()
            boxes[b.model_ref] = (tuple(lo.tolist()), tuple(hi.tolist()), mesh)
    return [Body(b.id, b.label_class, b.instance, *boxes[b.model_ref]) for b in world.bodies]


def build(ctx: ServiceContext) -> Built:
    service = SensorsService(ctx)
    return service.participant, service.step, None


def main(argv: list[str] | None = None) -> int:
    return run_service("sensors", build, argv, shardable=True)


if __name__ == "__main__":
    sys.exit(main())
