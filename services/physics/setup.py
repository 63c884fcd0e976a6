"""A PhysicsWorld from the resolved world: every body at its start pose, and the environment."""

from __future__ import annotations

from catabot.world.environment.wind import WindField
from catabot.world.waves import WaveField
from catabot.world.world import World
from services.physics.world import PhysicsWorld


def build_world(world: World) -> PhysicsWorld:
    """Vessels (the scenario's, then traffic boats) and buoys in the world's row order."""
    scenario = world.scenario
    starts = [(v.id, v.model, (v.pose.x_m, v.pose.y_m, 0.0, v.pose.yaw_rad)) for v in world.vessels]
    buoys = world.buoys
    return PhysicsWorld(
        starts,
        dt_s=scenario.dt_ns / 1e9,
        water_density=scenario.water.density_kg_m3,
        waves=WaveField(scenario.water.waves, scenario.seed),
        terrain=world.terrain,
        current=world.current,
        wind=WindField(scenario.wind, seed=scenario.seed),
        buoys=[(b.id, (b.pose.x_m, b.pose.y_m)) for b in buoys],
        buoy_model=buoys[0].model if buoys else None,
    )
