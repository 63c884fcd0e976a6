"""The original simulator's SettingsConfig.json: accepted, mapped, and checked key by key."""

from __future__ import annotations

import json
import logging
from pathlib import Path
from typing import Any

import pytest

from catabot.config.scenario import ScenarioError, load_scenario, parse_scenario
from catabot.config.settings_config import is_settings_config

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
    assert _sensor_types(ORIGINAL_DEFAULTS) == ["imu", "gps", "lidar"]
    assert scenario.rain.rate_mm_h == 0.0


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
    assert _sensor_types({"gpsLatitude": 10.0}) == ["imu", "gps", "lidar"]


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
        ("terrainPathToElevationFile", 5, "a string"),
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


def test_unsupported_features_are_warned_about(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        parse_scenario(ORIGINAL_DEFAULTS, source="SettingsConfig.json")
    text = "\n".join(r.getMessage() for r in caplog.records if r.name == LOGGER)
    assert all(r.levelno == logging.WARNING for r in caplog.records if r.name == LOGGER)
    for key in ("radarActive", "minimapActive"):
        assert f"SettingsConfig.json: {key}=true" in text
    assert "lidarActive" not in text  # LiDAR exists: mapped, not warned about
    for key in ("screenshotsSaveToFile", "terrainFromFile", "rainIntensity", "boatsNumber"):
        assert key not in text  # off in the defaults: nothing to warn about


def test_requested_datasets_rain_and_traffic_are_warned_about(
    caplog: pytest.LogCaptureFixture,
) -> None:
    data = _settings(
        radarActive=False,
        lidarActive=False,
        minimapActive=False,
        screenshotsSaveToFile=True,
        terrainFromFile=True,
        rainIntensity=12.5,
        boatsNumberActive=10,
    )
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        scenario = parse_scenario(data, source="S.json")
    text = "\n".join(r.getMessage() for r in caplog.records if r.name == LOGGER)
    for key in ("screenshotsSaveToFile", "terrainFromFile"):
        assert key in text
    assert "rainIntensity" not in text  # mapped to the scenario's rain
    assert "boatsNumberActive" not in text  # mapped to the scenario's traffic
    assert scenario.traffic.count == 10 and scenario.traffic.behaviour_mix == {"circle": 1.0}
    for key in ("radarActive", "lidarActive", "minimapActive"):
        assert key not in text


def test_nothing_requested_nothing_warned(caplog: pytest.LogCaptureFixture) -> None:
    data = _settings(radarActive=False, lidarActive=False, minimapActive=False)
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        parse_scenario(data)
    assert [r for r in caplog.records if r.name == LOGGER] == []


def test_bad_files_warn_nothing(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        _error(_settings(rainIntensity=80))
    assert [r for r in caplog.records if r.name == LOGGER] == []
