"""The original simulator's SettingsConfig.json: accepted, mapped, and checked key by key."""

from __future__ import annotations

import json
import logging
from pathlib import Path
from typing import Any

import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import load_scenario, parse_scenario
from catabot.config.settings_config import is_settings_config
from catabot.world.world import World
from tests.paths import BAY

# The original CataBotSim defaults (reference/anchors.md).
ORIGINAL_DEFAULTS: dict[str, Any] = {
    "radarActive": True,
    "lidarActive": True,
    "imuActive": True,
    "minimapActive": True,
    "rainIntensity": 0.0,
    "screenshotsSaveToFile": False,
    "screenshotsColorActive": False,
    "screenshotsSegmentationActive": False,
    "screenshotsDepthActive": False,
    "screenshotsNormalActive": False,
    "robotControlType": "Keyboard",
    "boatControlType": "Circles",
    "boatsNumberActive": 0,
    "gpsLatitude": 0.0,
    "gpsLongitude": 0.0,
    "terrainFromFile": False,
    "terrainHeightMin": -35.0,
    "terrainHeightMax": 60.0,
    "terrainPixelScale": 5.0,
    "terrainPathToElevationFile": "New York River Elevation.png",
}
LOGGER = "catabot.config.settings_config"


def _settings(**changes: Any) -> dict[str, Any]:
    data = dict(ORIGINAL_DEFAULTS)
    data.update(changes)
    return data


def _error(data: dict[str, Any]) -> str:
    with pytest.raises(ScenarioError) as info:
        parse_scenario(data, source="SettingsConfig.json")
    msg = str(info.value)
    assert msg.startswith("settings file SettingsConfig.json:")
    return msg


def _sensor_types(data: dict[str, Any]) -> list[str]:
    return [s.type for s in parse_scenario(data).vessels[0].sensors]


def test_original_defaults_are_accepted_and_mapped() -> None:
    assert is_settings_config(ORIGINAL_DEFAULTS)
    scenario = parse_scenario(ORIGINAL_DEFAULTS)
    assert scenario.origin.latitude_deg == 0.0
    assert scenario.origin.longitude_deg == 0.0
    assert [v.id for v in scenario.vessels] == ["robot_0"]
    assert scenario.vessels[0].model == "catabot"
    assert _sensor_types(ORIGINAL_DEFAULTS) == ["imu", "gps", "lidar", "radar"]
    assert scenario.rain.rate_mm_h == 0.0
    assert scenario.terrain is None  # terrainFromFile false
    assert scenario.recording.ppi and not scenario.recording.dataset


def test_lidar_and_rain_are_mapped() -> None:
    assert "lidar" not in _sensor_types(_settings(lidarActive=False))
    assert parse_scenario(_settings(rainIntensity=12.5)).rain.rate_mm_h == 12.5


def test_gps_origin_is_mapped() -> None:
    scenario = parse_scenario(_settings(gpsLatitude=40.7003, gpsLongitude=-74.017))
    assert scenario.origin.latitude_deg == 40.7003
    assert scenario.origin.longitude_deg == -74.017


def test_imu_on_and_off() -> None:
    assert "imu" in _sensor_types(_settings(imuActive=True))
    assert "imu" not in _sensor_types(_settings(imuActive=False))
    assert "gps" in _sensor_types(_settings(imuActive=False))


def test_a_partial_file_takes_the_original_defaults() -> None:
    scenario = parse_scenario({"gpsLatitude": 10.0})
    assert scenario.origin.latitude_deg == 10.0
    assert _sensor_types({"gpsLatitude": 10.0}) == ["imu", "gps", "lidar", "radar"]


def test_a_native_scenario_is_not_taken_for_a_settings_file() -> None:
    assert not is_settings_config({"vessels": [], "imuActive": True})
    assert not is_settings_config({"name": "x"})


def test_loaded_from_a_file(tmp_path: Path) -> None:
    path = tmp_path / "SettingsConfig.json"
    path.write_text(json.dumps(_settings(gpsLatitude=1.5)))
    assert load_scenario(path).origin.latitude_deg == 1.5
    path.write_text(json.dumps(_settings(rainIntensity=80)))
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert str(path) in str(info.value) and "rainIntensity" in str(info.value)


@pytest.mark.parametrize(
    ("key", "value", "allowed"),
    [
        ("rainIntensity", 80, "[0.0, 50.0]"),
        ("rainIntensity", -0.5, "[0.0, 50.0]"),
        ("rainIntensity", "heavy", "[0.0, 50.0]"),
        ("rainIntensity", True, "[0.0, 50.0]"),
        ("boatsNumberActive", -1, "[0, 100]"),
        ("boatsNumberActive", 101, "[0, 100]"),
        ("gpsLatitude", 91.0, "[-90.0, 90.0]"),
        ("gpsLongitude", -181.0, "[-180.0, 180.0]"),
        ("terrainPixelScale", 0.0, "[0.001, 10000.0]"),
        ("robotControlType", "Joystick", "['Keyboard', 'cmd_vel', 'pose']"),
        ("boatControlType", "Zigzag", "['Circles', 'Waypoints', 'pose']"),
        ("imuActive", "true", "true or false"),
        ("radarActive", 1, "true or false"),
        ("terrainPathToElevationFile", 5, "a non-empty string"),
        ("boatsNumberActive", 2.5, "a whole number of boats"),
    ],
)
def test_bad_values_name_the_key_and_the_allowed_values(key: str, value: Any, allowed: str) -> None:
    msg = _error(_settings(**{key: value}))
    assert f"{key}:" in msg
    assert allowed in msg
    assert f"(got {value!r})" in msg


def test_unknown_key() -> None:
    msg = _error(_settings(rainIntensty=10.0))
    assert "unknown key(s) ['rainIntensty']" in msg
    assert "rainIntensity" in msg  # the known keys are listed


@pytest.mark.parametrize(("lo", "hi"), [(10.0, 10.0), (20.0, -5.0)])
def test_terrain_height_min_must_be_below_max(lo: float, hi: float) -> None:
    msg = _error(_settings(terrainHeightMin=lo, terrainHeightMax=hi))
    assert "terrainHeightMin" in msg and "terrainHeightMax" in msg
    assert "must be below" in msg


def test_every_key_maps_onto_its_feature_with_no_warning(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        scenario = parse_scenario(ORIGINAL_DEFAULTS, source="SettingsConfig.json")
    assert [r for r in caplog.records if r.name == LOGGER] == []
    radar = scenario.vessels[0].sensors[-1]
    assert (radar.type, radar.rate_hz) == ("radar", 10.0)
    assert not parse_scenario(_settings(minimapActive=False)).recording.ppi
    assert "radar" not in _sensor_types(_settings(radarActive=False))


def test_screenshots_become_a_camera_with_those_outputs() -> None:
    data = _settings(
        screenshotsSaveToFile=True, screenshotsColorActive=True, screenshotsDepthActive=True
    )
    scenario = parse_scenario(data)
    camera = scenario.vessels[0].sensors[-1]
    assert camera.type == "camera" and camera.rate_hz == 5.0
    outputs = camera.typed_params().outputs
    assert (outputs.color, outputs.depth, outputs.normals, outputs.segmentation) == (
        True, True, False, False
    )  # fmt: skip
    assert scenario.recording.dataset
    shown_only = parse_scenario(_settings(screenshotsSegmentationActive=True))
    assert "camera" in [s.type for s in shown_only.vessels[0].sensors]
    assert not shown_only.recording.dataset  # on the bus, not written to dataset/
    assert "camera" not in _sensor_types(_settings(screenshotsSaveToFile=True))


def test_terrain_from_file_is_read_relative_to_the_settings_file(tmp_path: Path) -> None:
    bay = BAY
    (tmp_path / "maps").mkdir()
    (tmp_path / "maps" / "river.png").write_bytes(bay.read_bytes())
    data = _settings(
        terrainFromFile=True,
        terrainPathToElevationFile="maps/river.png",
        terrainHeightMin=-20.0,
        terrainHeightMax=30.0,
        terrainPixelScale=4.0,
    )
    path = tmp_path / "SettingsConfig.json"
    path.write_text(json.dumps(data))
    scenario = load_scenario(path)
    assert scenario.terrain is not None
    assert scenario.terrain.elevation_image == str(tmp_path / "maps" / "river.png")
    assert (scenario.terrain.min_elevation_m, scenario.terrain.max_elevation_m) == (-20.0, 30.0)
    assert scenario.terrain.metres_per_pixel == 4.0
    world = World.resolve(scenario)  # robot_0 placed in open water on that terrain
    assert world.terrain is not None
    pose = world.body("robot_0").pose
    assert world.terrain.depth(pose.x_m, pose.y_m) > 0


def test_pose_control_of_the_robot_is_reported(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        parse_scenario(_settings(robotControlType="pose"), source="S.json")
    text = "\n".join(r.getMessage() for r in caplog.records if r.name == LOGGER)
    assert "S.json: robotControlType 'pose'" in text and "cmd/twist" in text


def test_nothing_requested_nothing_warned(caplog: pytest.LogCaptureFixture) -> None:
    data = _settings(radarActive=False, lidarActive=False, minimapActive=False)
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        parse_scenario(data)
    assert [r for r in caplog.records if r.name == LOGGER] == []


def test_bad_files_warn_nothing(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        _error(_settings(rainIntensity=80))
    assert [r for r in caplog.records if r.name == LOGGER] == []
