"""A small world with one sensor of every type, mounted off-centre and turned, a traffic
boat and a buoy: what the conversion tests convert."""

from __future__ import annotations

from typing import Any

from catabot.config.load import parse_scenario
from catabot.world.world import World

SENSORS = [
    {"name": "imu", "type": "imu", "rate_hz": 100.0, "params": {"lever_arm": [0.2, -0.1, 0.3]}},
    {"name": "gps", "type": "gps", "rate_hz": 10.0, "params": {"antenna_offset": [-0.5, 0, 1]}},
    {"name": "lidar", "type": "lidar", "rate_hz": 10.0,
     "params": {"mount_xyz": [0.3, 0.1, 1.2], "mount_yaw_deg": 30.0, "mount_pitch_deg": 5.0}},
    {"name": "radar", "type": "radar", "rate_hz": 20.0, "params": {"rotation_period_s": 0.5}},
    {"name": "cam", "type": "camera", "rate_hz": 10.0,
     "params": {"width": 64, "height": 48, "hfov_deg": 70.0, "mount_xyz": [0.5, 0.0, 1.5],
                "mount_rpy_deg": [2.0, 10.0, -20.0]}},
]  # fmt: skip


def scenario(**ros: Any) -> dict[str, Any]:
    return {
        "name": "conv",
        "seed": 5,
        "vessels": [{"id": "ego", "sensors": SENSORS}, {"id": "other", "pose": {"x_m": 30.0}}],
        "buoys": [{"id": "b1", "x_m": 8.0, "y_m": 2.0}],
        "traffic": {"count": 1},
        "ros": ros,
    }


def world(**ros: Any) -> World:
    return World.resolve(parse_scenario(scenario(**ros)))
