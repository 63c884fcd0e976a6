"""Where each sensor sits on its vessel, as ROS transforms: base_link -> sensor frame.

The mount geometry is each sensor type's own (services/sensors: the models' docstrings);
it is restated here from the parameters because the library never imports a service, and
tests/catabot/ros2/test_frames.py checks every type against the model's own pose, so the
two cannot drift. One `tf2_msgs/TFMessage` of all of them goes on `/tf_static` once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from catabot.ros2 import types
from catabot.ros2.names import Names
from catabot.world import rotations
from catabot.world.world import MountedSensor

OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
"""The ROS optical frame (z forward, x right, y down) in the camera's FLU frame."""
IDENTITY = (0.0, 0.0, 0.0, 1.0)


@dataclass(frozen=True)
class Transform:
    parent: str
    child: str
    translation: tuple[float, float, float]
    rotation: tuple[float, float, float, float]  # x, y, z, w


def mount(sensor: MountedSensor) -> tuple[tuple[float, float, float], np.ndarray]:
    """The sensor frame in the body frame: translation (m) and rotation (sensor -> body)."""
    p, kind = sensor.params, sensor.config.type
    if kind == "imu":
        return _xyz(p.lever_arm), np.eye(3)
    if kind == "gps":
        return _xyz(p.antenna_offset), np.eye(3)
    if kind == "lidar":
        return _xyz(p.mount_xyz), rotations.rpy(0.0, p.mount_pitch_deg, p.mount_yaw_deg)
    if kind == "radar":  # stabilised: the sweep is level, turned with the heading only
        return (0.0, 0.0, float(p.antenna_height_m)), np.eye(3)
    if kind == "camera":
        return _xyz(p.mount_xyz), rotations.rpy(*p.mount_rpy_deg)
    raise ValueError(f"{sensor.seed_name}: no mount known for sensor type {kind!r}")


def _xyz(values: tuple[float, ...]) -> tuple[float, float, float]:
    x, y, z = (float(v) for v in values)
    return (x, y, z)


def static_transforms(names: Names) -> list[Transform]:
    """base_link -> every sensor frame of every scenario vessel; cameras also frame ->
    optical frame (their images' frame)."""
    out = []
    for sensor in names.world.sensors:
        xyz, rot = mount(sensor)
        frame = names.sensor_frame(sensor)
        quat = rotations.quaternion_of_matrix(rot)
        out.append(Transform(names.base_link(sensor.vessel), frame, xyz, quat))
        if sensor.config.type == "camera":
            optical = rotations.quaternion_of_matrix(OPTICAL)
            out.append(Transform(frame, names.optical_frame(sensor), (0.0, 0.0, 0.0), optical))
    return out


def tf_message(transforms: list[Transform], stamp_ns: int) -> bytes:
    """The transforms as one `tf2_msgs/msg/TFMessage` (rosbags' serializer: sent once)."""
    items = [
        types.new(
            "geometry_msgs/msg/TransformStamped",
            header=types.header(stamp_ns, t.parent),
            child_frame_id=t.child,
            transform=types.new(
                "geometry_msgs/msg/Transform",
                translation=types.new("geometry_msgs/msg/Vector3", **_fields("xyz", t.translation)),
                rotation=types.new("geometry_msgs/msg/Quaternion", **_fields("xyzw", t.rotation)),
            ),
        )
        for t in transforms
    ]
    return types.serialize(types.new(types.TF, transforms=items), types.TF)


def _fields(names: str, values: tuple[float, ...]) -> dict[str, float]:
    return dict(zip(names, values, strict=True))
