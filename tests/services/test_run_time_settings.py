"""Run-time settings applied where they take effect: physics (wind, current, sea), sensors
(rain, sea, on/off, camera outputs) and traffic (a boat's behaviour)."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import numpy as np

from catabot.bus.settings import Change
from catabot.config import live
from catabot.config.load import parse_scenario
from catabot.config.scenario import Pose
from catabot.config.traffic import TrafficConfig
from catabot.world.traffic_plan import Boat
from catabot.world.world import World
from services.physics import settings as physics_settings
from services.physics.setup import build_world
from services.sensors.settings import SensorSettings
from services.traffic.behaviours import CIRCLE, HOLD, WAYPOINTS, Behaviours


def _scenario(**top: Any) -> Any:
    cam = {"name": "cam", "type": "camera", "rate_hz": 5.0, "params": {"width": 32, "height": 24}}
    return parse_scenario({"vessels": [{"id": "ego", "sensors": [cam]}], **top}, source="test")


def _drift(changes: list[Change], steps: int = 200) -> float:
    scenario = _scenario()
    world = build_world(World.resolve(scenario))
    specs = live.keys_of(scenario)
    for change in changes:
        physics_settings.apply(world, scenario, specs, change)
    for _ in range(steps):
        world.step()
    return float(world.state_arrays().position[0, 0])


def test_physics_takes_current_and_wind() -> None:
    still = _drift([])
    assert _drift([Change(0, "current", "[1.0,0.0]")]) > still + 0.5  # carried east
    assert _drift([Change(0, "wind.speed_mps", "20.0")]) > still  # blown east (toward 0 rad)
    west = [Change(0, "wind.speed_mps", "20.0"), Change(0, "wind.toward_rad", str(math.pi))]
    assert _drift(west) < still


def test_physics_and_sensors_take_the_sea() -> None:
    scenario = _scenario()
    world = build_world(World.resolve(scenario))
    physics_settings.apply(world, scenario, live.keys_of(scenario), Change(0, "waves", '"heavy"'))
    assert world.sea_method.startswith("vessel expansions")  # a sea, no longer calm


def test_sensor_settings_switch_rain_sensors_and_outputs() -> None:
    scenario = _scenario()
    scene = SimpleNamespace(rain_rate_mm_h=0.0)
    camera = SimpleNamespace(params=scenario.vessels[0].sensors[0].typed_params())
    switch = SensorSettings(scenario, scene, lambda v, s: f"sensor/{v}/{s}")  # type: ignore[arg-type]
    models = {"sensor/ego/cam": camera}
    switch.apply(Change(3, "rain", "25.0"), models)
    assert scene.rain_rate_mm_h == 25.0
    switch.apply(Change(3, "sensor.ego.cam.outputs.normals", "false"), models)
    assert camera.params.outputs.normals is False and camera.params.outputs.color is True
    switch.apply(Change(3, "sensor.ego.cam.enabled", "false"), models)
    assert switch.off == {"sensor/ego/cam"}
    switch.apply(Change(9, "sensor.ego.cam.enabled", "true"), models)
    assert switch.off == set()


def test_a_boat_changes_behaviour_from_where_it_is() -> None:
    boat = Boat("boat_000", "monohull", Pose(), "circle", 5.0, (0.0, 19.0), 19.0, 1)
    behaviours, cfg = Behaviours([boat]), TrafficConfig(count=1)
    here = np.array([10.0, 20.0])
    behaviours.set_behaviour(0, "hold", here, 0.5, cfg)
    assert behaviours.kind[0] == HOLD and behaviours.centre[0].tolist() == [10.0, 20.0]
    surge, _ = behaviours.command(here[None], np.array([0.5]), np.zeros((1, 2)))
    assert abs(surge[0]) < 0.5  # at its hold point: stays
    behaviours.set_behaviour(0, "circle", here, 0.0, cfg)
    assert behaviours.kind[0] == CIRCLE
    assert np.allclose(behaviours.centre[0], [10.0, 39.0])  # on its circle, heading along it
    behaviours.set_behaviour(0, "waypoints", here, 0.0, cfg)
    assert behaviours.kind[0] == WAYPOINTS
    assert np.allclose(behaviours.paths[0, :2], [[10.0, 20.0], [110.0, 20.0]])  # a patrol
