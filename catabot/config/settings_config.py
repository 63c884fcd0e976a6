"""The original CataBotSim `SettingsConfig.json`, mapped onto a CataBot scenario.

The original loader clamped or silently ignored bad values; here every key is checked
(type and range, as the original's UI allowed) and every setting this version cannot
honour yet is reported by a warning instead of vanishing.
"""

from __future__ import annotations

import logging
from typing import Any

from catabot.config.base import ConfigError

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
NOT_YET = {
    "radarActive": "marine radar",
    "minimapActive": "the radar minimap",
    "screenshotsSaveToFile": "camera datasets",
    "terrainFromFile": "terrain from elevation images",
}


class SettingsConfigError(ConfigError):
    pass


def is_settings_config(data: dict[str, Any]) -> bool:
    return bool(KNOWN & set(data)) and "vessels" not in data


def map_settings_config(data: dict[str, Any], *, source: str) -> dict[str, Any]:
    """Check every key, then build the equivalent scenario dictionary."""
    from catabot.config.scenario import ScenarioError

    try:
        _check(data)
    except SettingsConfigError as exc:
        raise ScenarioError(f"settings file {source}: {exc}") from None
    _warn_unsupported(data, source)
    sensors = (
        [{"name": "imu", "type": "imu", "rate_hz": 100.0}] if data.get("imuActive", True) else []
    )
    sensors.append({"name": "gps", "type": "gps", "rate_hz": 10.0})
    if data.get("lidarActive", True):  # the original's OS1-like LiDAR at about 5 Hz
        sensors.append({"name": "lidar", "type": "lidar", "rate_hz": 5.0})
    return {
        "name": "settings-config",
        "origin": {
            "latitude_deg": data.get("gpsLatitude", 0.0),
            "longitude_deg": data.get("gpsLongitude", 0.0),
        },
        "rain": {"rate_mm_h": data.get("rainIntensity", 0.0)},
        "vessels": [{"id": "robot_0", "model": "catabot", "sensors": sensors}],
        "traffic": _traffic(data),
    }


def _traffic(data: dict[str, Any]) -> dict[str, Any]:
    """boatsNumberActive boats; Circles and Waypoints as in the original, `pose` (driven from
    outside) as boats holding their spawn point until an external command takes them."""
    kind = {"Circles": "circle", "Waypoints": "waypoints", "pose": "hold"}
    behaviour = kind[data.get("boatControlType", "Circles")]
    return {"count": int(data.get("boatsNumberActive", 0)), "behaviour_mix": {behaviour: 1.0}}


def _check(data: dict[str, Any]) -> None:
    unknown = sorted(set(data) - KNOWN)
    if unknown:
        raise SettingsConfigError(f"unknown key(s) {unknown}; known keys: {sorted(KNOWN)}")
    for key, value in data.items():
        if key in BOOL_KEYS and not isinstance(value, bool):
            raise SettingsConfigError(f"{key}: must be true or false (got {value!r})")
        if key in NUMBER_RANGES:
            lo, hi = NUMBER_RANGES[key]
            if (
                isinstance(value, bool)
                or not isinstance(value, int | float)
                or not lo <= value <= hi
            ):
                raise SettingsConfigError(
                    f"{key}: must be a number in [{lo}, {hi}] (got {value!r})"
                )
        if key in CHOICES and value not in CHOICES[key]:
            raise SettingsConfigError(f"{key}: must be one of {list(CHOICES[key])} (got {value!r})")
        if key in STRING_KEYS and not isinstance(value, str):
            raise SettingsConfigError(f"{key}: must be a string (got {value!r})")
    lo, hi = data.get("terrainHeightMin", -35.0), data.get("terrainHeightMax", 60.0)
    if lo >= hi:
        raise SettingsConfigError(f"terrainHeightMin ({lo}) must be below terrainHeightMax ({hi})")


def _warn_unsupported(data: dict[str, Any], source: str) -> None:
    for key, feature in NOT_YET.items():
        if data.get(key, key in ("radarActive", "lidarActive", "minimapActive")):
            log.warning(
                "%s: %s=true asks for %s, not in this CataBot version; ignored",
                source,
                key,
                feature,
            )
