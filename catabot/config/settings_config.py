"""The original CataBotSim `SettingsConfig.json`, mapped onto a CataBot scenario.

The original loader clamped or silently ignored bad values; here every key is checked (type
and range, as the original's UI allowed) and every key maps onto the feature it switched:

| key | becomes |
|---|---|
| imuActive, lidarActive, radarActive | `robot_0`'s IMU (100 Hz), LiDAR (5 Hz), radar (10 Hz) |
| minimapActive | `recording.ppi`: the radar's minimap (PPI) images in `dataset/` |
| screenshots*Active | a camera on `robot_0` (5 Hz) with those outputs |
| screenshotsSaveToFile | `recording.dataset`: the camera's frames written to `dataset/` |
| rainIntensity | `rain.rate_mm_h` |
| gpsLatitude, gpsLongitude | `origin` (the terrain image's bottom-left corner) |
| terrainFromFile, terrain* | `terrain` (the image path relative to the settings file) |
| boatsNumberActive, boatControlType | `traffic` (Circles, Waypoints; pose: boats hold station
  until an outside command drives them) |
| robotControlType | how `robot_0` is driven: Keyboard and cmd_vel both mean commands from
  outside (examples/teleop, a ROS stack); pose, the original's teleport, has no force-based
  equivalent and is reported, not silently dropped |
"""

from __future__ import annotations

import logging
from typing import Any

from catabot.config.base import ScenarioError

log = logging.getLogger("catabot.config.settings_config")

BOOL_KEYS = (
    "radarActive",
    "lidarActive",
    "imuActive",
    "minimapActive",
    "screenshotsSaveToFile",
    "screenshotsColorActive",
    "screenshotsSegmentationActive",
    "screenshotsDepthActive",
    "screenshotsNormalActive",
    "terrainFromFile",
)
NUMBER_RANGES = {
    "rainIntensity": (0.0, 50.0),
    "boatsNumberActive": (0, 100),
    "gpsLatitude": (-90.0, 90.0),
    "gpsLongitude": (-180.0, 180.0),
    "terrainHeightMin": (-11000.0, 9000.0),
    "terrainHeightMax": (-11000.0, 9000.0),
    "terrainPixelScale": (1e-3, 1e4),
}
CHOICES = {
    "robotControlType": ("Keyboard", "cmd_vel", "pose"),
    "boatControlType": ("Circles", "Waypoints", "pose"),
}
STRING_KEYS = ("terrainPathToElevationFile",)
KNOWN = set(BOOL_KEYS) | set(NUMBER_RANGES) | set(CHOICES) | set(STRING_KEYS)
DEFAULTS: dict[str, Any] = {  # the original's (reference/anchors.md)
    "radarActive": True,
    "lidarActive": True,
    "imuActive": True,
    "minimapActive": True,
    "screenshotsSaveToFile": False,
    "terrainFromFile": False,
    "terrainHeightMin": -35.0,
    "terrainHeightMax": 60.0,
    "terrainPixelScale": 5.0,
    "terrainPathToElevationFile": "New York River Elevation.png",
}
SCREENSHOTS = {
    "screenshotsColorActive": "color",
    "screenshotsDepthActive": "depth",
    "screenshotsNormalActive": "normals",
    "screenshotsSegmentationActive": "segmentation",
}


def is_settings_config(data: dict[str, Any]) -> bool:
    return bool(KNOWN & set(data)) and "vessels" not in data


def map_settings_config(data: dict[str, Any], *, source: str) -> dict[str, Any]:
    """Check every key, then build the equivalent scenario dictionary (relative paths stay
    relative: the loader makes them absolute from the settings file's folder)."""
    _check(data, source)
    s = {**DEFAULTS, **data}
    if s.get("robotControlType") == "pose":
        log.warning(
            "%s: robotControlType 'pose' (teleporting robot_0) has no force-based equivalent; "
            "robot_0 takes cmd/twist or cmd/thrust from outside instead",
            source,
        )
    scenario: dict[str, Any] = {
        "name": "settings-config",
        "origin": {
            "latitude_deg": s.get("gpsLatitude", 0.0),
            "longitude_deg": s.get("gpsLongitude", 0.0),
        },
        "rain": {"rate_mm_h": s.get("rainIntensity", 0.0)},
        "vessels": [{"id": "robot_0", "model": "catabot", "sensors": _sensors(s)}],
        "traffic": _traffic(s),
        "recording": {"ppi": s["minimapActive"], "dataset": s["screenshotsSaveToFile"]},
    }
    if s["terrainFromFile"]:
        scenario["terrain"] = {
            "elevation_image": s["terrainPathToElevationFile"],
            "min_elevation_m": s["terrainHeightMin"],
            "max_elevation_m": s["terrainHeightMax"],
            "metres_per_pixel": s["terrainPixelScale"],
        }
    return scenario


def _sensors(s: dict[str, Any]) -> list[dict[str, Any]]:
    sensors: list[dict[str, Any]] = []
    if s["imuActive"]:
        sensors.append({"name": "imu", "type": "imu", "rate_hz": 100.0})
    sensors.append({"name": "gps", "type": "gps", "rate_hz": 10.0})
    if s["lidarActive"]:  # the original's OS1-like LiDAR at about 5 Hz
        sensors.append({"name": "lidar", "type": "lidar", "rate_hz": 5.0})
    if s["radarActive"]:  # one turn in 2 s; each sample holds the sector swept since the last
        sensors.append({"name": "radar", "type": "radar", "rate_hz": 10.0})
    outputs = {name: bool(s.get(key, False)) for key, name in SCREENSHOTS.items()}
    if any(outputs.values()):  # "screenshots multiple times per second" (paper §III-D)
        params = {"outputs": outputs}
        sensors.append({"name": "camera", "type": "camera", "rate_hz": 5.0, "params": params})
    return sensors


def _traffic(s: dict[str, Any]) -> dict[str, Any]:
    """boatsNumberActive boats; Circles and Waypoints as in the original, `pose` (driven from
    outside) as boats holding their spawn point until an external command takes them."""
    kind = {"Circles": "circle", "Waypoints": "waypoints", "pose": "hold"}
    behaviour = kind[s.get("boatControlType", "Circles")]
    return {"count": int(s.get("boatsNumberActive", 0)), "behaviour_mix": {behaviour: 1.0}}


def _check(data: dict[str, Any], source: str) -> None:
    unknown = sorted(set(data) - KNOWN)
    if unknown:
        _refuse(source, f"unknown key(s) {unknown}; known keys: {sorted(KNOWN)}")
    for key, value in data.items():
        problem = _problem(key, value)
        if problem:
            _refuse(source, f"{key}: {problem} (got {value!r})")
    lo, hi = data.get("terrainHeightMin", -35.0), data.get("terrainHeightMax", 60.0)
    if lo >= hi:
        _refuse(source, f"terrainHeightMin ({lo}) must be below terrainHeightMax ({hi})")


def _problem(key: str, value: Any) -> str:
    if key in BOOL_KEYS and not isinstance(value, bool):
        return "must be true or false"
    if key in NUMBER_RANGES:
        lo, hi = NUMBER_RANGES[key]
        number = isinstance(value, int | float) and not isinstance(value, bool)
        if not (number and lo <= value <= hi):
            return f"must be a number in [{lo}, {hi}]"
        if key == "boatsNumberActive" and not float(value).is_integer():
            return "must be a whole number of boats"
    if key in CHOICES and value not in CHOICES[key]:
        return f"must be one of {list(CHOICES[key])}"
    if key in STRING_KEYS and not (isinstance(value, str) and value):
        return "must be a non-empty string"
    return ""


def _refuse(source: str, message: str) -> None:
    raise ScenarioError(f"settings file {source}: {message}")
