"""A PhysicsWorld from a scenario: vessels at their resolved poses, and the environment."""

from __future__ import annotations

from catabot.config.scenario import Scenario
from catabot.config.vessel import VesselModel, load_vessel_model
from catabot.world.environment.current import CurrentField
from catabot.world.environment.wind import WindField
from catabot.world.terrain import load_terrain
from catabot.world.traffic_plan import all_buoys, all_vessels
from catabot.world.waves import WaveField
from services.physics.world import PhysicsWorld


def build_world(scenario: Scenario) -> tuple[PhysicsWorld, dict[str, VesselModel]]:
    vessels = all_vessels(scenario)  # the scenario's own, then the traffic boats
    models = {v.id: load_vessel_model(v.model) for v in vessels}
    starts = []
    for v in vessels:
        assert v.pose is not None, "poses are resolved before physics starts"
        starts.append((v.id, models[v.id], (v.pose.x_m, v.pose.y_m, 0.0, v.pose.yaw_rad)))
    buoys = all_buoys(scenario)
    world = PhysicsWorld(
        starts,
        dt_s=scenario.dt_ns / 1e9,
        water_density=scenario.water.density_kg_m3,
        waves=WaveField(scenario.water.waves, scenario.seed),
        terrain=load_terrain(scenario.terrain) if scenario.terrain is not None else None,
        current=CurrentField.from_config(scenario.water.current),
        wind=WindField(scenario.wind, seed=scenario.seed),
        buoys=[(b.id, (b.x_m, b.y_m)) for b in buoys],
        buoy_model=load_vessel_model("buoy") if buoys else None,
    )
    return world, models
