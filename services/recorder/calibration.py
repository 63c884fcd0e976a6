"""`dataset/calibration.json`: where every sensor sits on its vessel, and each camera's K.

Why: a perception user projecting LiDAR points into a camera image (KITTI's `calib.txt`
P2 and Tr, nuScenes' calibrated_sensor) found the mounts only in the scenario's parameters
and K only in run.mcap's CameraInfo. Both come from the ROS gateway's own definitions
(catabot/ros2/frames.py, convert_sensors.py), so the file, `/tf_static` and CameraInfo
agree. Body frame: the vessel's FLU frame (x forward, y left, z up) at its origin; a
camera's optical frame: z forward, x right, y down (its images'). A point p in a sensor's
frame is body_from_sensor @ [p, 1] in the body frame; both sensors on one vessel and
sampled at one stamp, the body's own pose cancels out.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from catabot.ros2.convert_sensors import camera_matrix
from catabot.ros2.frames import OPTICAL, mount, stabilised
from catabot.world.world import MountedSensor, World

FRAMES = ("body: the vessel's FLU frame (x forward, y left, z up) at its origin; a camera's "
          "optical frame: z forward, x right, y down (its images'); K: pixel (u, v)'s centre "
          "at (u, v), as OpenCV and ROS CameraInfo")  # fmt: skip


STABILISED = (
    "level, turned with the vessel's heading only: body_from_sensor's rotation is a "
    "level hull's; a tilted hull's radar frame is on /tf"
)


def calibration(world: World) -> dict[str, Any]:
    """Every scenario sensor by `<vessel>.<name>` (the dataset's and exports' names)."""
    sensors = {f"{s.vessel}.{s.config.name}": _sensor(s) for s in world.sensors}
    return {"frames": FRAMES, "sensors": sensors}


def _sensor(sensor: MountedSensor) -> dict[str, Any]:
    xyz, rot = mount(sensor)
    out: dict[str, Any] = {"type": sensor.config.type, "vessel": sensor.vessel,
                           "body_from_sensor": _matrix(rot, xyz)}  # fmt: skip
    if stabilised(sensor):
        out["stabilised"] = STABILISED
    if sensor.config.type == "camera":
        p = sensor.params
        out |= {"body_from_optical": _matrix(rot @ OPTICAL, xyz), "width": p.width,
                "height": p.height, "K": np.round(camera_matrix(sensor), 9).tolist()}  # fmt: skip
    return out


def _matrix(rot: np.ndarray, xyz: tuple[float, float, float]) -> list[list[float]]:
    """A 4 x 4 homogeneous transform, rounded to 1e-9 (no -0.0 or 6e-17 noise)."""
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rot, xyz
    return (np.round(out, 9) + 0.0).tolist()


def write_calibration(root: Path, world: World) -> None:
    root.mkdir(parents=True, exist_ok=True)
    text = json.dumps(calibration(world), indent=1) + "\n"
    (root / "calibration.json").write_text(text, encoding="utf-8")
