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
from catabot.world.sea_change import SeaChange
from catabot.world.traffic_plan import Boat
from catabot.world.waves import WaveField
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
    resolved = World.resolve(scenario)
    world, sea = build_world(resolved), SeaChange(resolved.waves, dt_ns=scenario.dt_ns)
    physics_settings.take(world, scenario, live.keys_of(scenario), changes, tick=0, sea=sea)
    for _ in range(steps):
        world.step()
    return float(world.state_arrays().position[0, 0])


def test_physics_takes_current_and_wind() -> None:
    still = _drift([])
    assert _drift([Change(0, "current", "[1.0,0.0]")]) > still + 0.5  # carried east
    assert _drift([Change(0, "wind.speed_mps", "20.0")]) > still  # blown east (toward 0 rad)
    west = [Change(0, "wind.speed_mps", "20.0"), Change(0, "wind.toward_rad", str(math.pi))]
    assert _drift(west) < still


def _heave_peak(*, ramp: bool) -> float:
    """The ego's largest vertical acceleration over 14 s of a medium swell that turns heavy
    at 2 s (tick 200), built up (catabot/world/sea_change.py) or replaced in one tick."""
    scenario = _scenario(water={"waves": {"preset": "medium"}})
    resolved = World.resolve(scenario)
    world, sea = build_world(resolved), SeaChange(resolved.waves, dt_ns=scenario.dt_ns)
    specs, peak = live.keys_of(scenario), 0.0
    heavy = WaveField(live.wave_config(scenario, "heavy"), scenario.seed)
    for tick in range(1400):
        changes = [Change(tick, "waves", '"heavy"')] if tick == 200 else []
        if ramp:
            physics_settings.take(world, scenario, specs, changes, tick=tick, sea=sea)
        elif changes:
            world.set_waves(heavy)
        world.step()
        if tick >= 100:  # past the start's own settling
            peak = max(peak, abs(float(world.state_arrays().linear_acceleration[0, 2])))
    assert world.sea_method.startswith("vessel expansions")  # a sea, no longer calm
    return peak


def test_a_new_sea_builds_up_without_dropping_the_boats() -> None:
    """Replaced in one tick, the surface under a boat jumped by up to a wave: from medium to
    heavy swell a boat fell and landed at 26 m/s^2 (a user's run)."""
    built, sudden = _heave_peak(ramp=True), _heave_peak(ramp=False)
    assert built < 3.0 < sudden, (built, sudden)


def test_sensor_settings_switch_rain_sensors_and_outputs() -> None:
    scenario = _scenario()
    scene = SimpleNamespace(rain_rate_mm_h=0.0)
    camera = SimpleNamespace(params=scenario.vessels[0].sensors[0].typed_params())
    world = World.resolve(scenario)
    switch = SensorSettings(world, scene, lambda v, s: f"sensor/{v}/{s}")  # type: ignore[arg-type]
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
