"""A PhysicsWorld from the resolved world: every body at its start pose, and the environment."""

from __future__ import annotations

import numpy as np

from catabot.world import rotations
from catabot.world.environment.wind import WindField
from catabot.world.world import World
from services.physics.world import PhysicsWorld


def build_world(world: World) -> PhysicsWorld:
    """Vessels (the scenario's, then traffic boats) and buoys in the world's row order."""
    scenario = world.scenario
    starts = [
        (v.id, v.model, (v.pose.x_m, v.pose.y_m, v.pose.z_m, v.pose.yaw_rad)) for v in world.vessels
    ]
    buoys = world.buoys
    physics = PhysicsWorld(
        starts,
        dt_s=scenario.dt_ns / 1e9,
        water_density=scenario.water.density_kg_m3,
        waves=world.waves,
        terrain=world.terrain,
        current=world.current,
        wind=WindField(scenario.wind, seed=scenario.seed),
        buoys=[(b.id, (b.pose.x_m, b.pose.y_m)) for b in buoys],
        buoy_model=buoys[0].model if buoys else None,
    )
    _off_rest(physics, world)
    return physics


def _off_rest(physics: PhysicsWorld, world: World) -> None:
    """Vessels that start tilted or under way, and in waves every body (on the surface,
    moving with it), placed exactly as `World.start_states` says (body-frame velocities
    turned into the map frame physics integrates in); on calm water the others keep the
    level start that records the same bytes as before these existed."""
    moved = [not (b.pose.level_at_surface and b.velocity.at_rest) for b in world.vessels]
    waves = not world.scenario.water.waves.is_calm
    rows = np.arange(len(world.bodies)) if waves else np.flatnonzero(moved)
    if rows.size == 0:
        return
    start = world.start_states()
    quat = start.orientation[rows]
    rot = rotations.matrices(quat)
    pose = np.concatenate([rotations.to_rotvec(quat), start.position[rows]], axis=1)
    angular, linear = start.angular_velocity[rows], start.linear_velocity[rows]
    velocity = np.einsum("nij,nkj->nki", rot, np.stack((angular, linear), axis=1))
    physics.place(rows, pose, velocity.reshape(-1, 6))
