"""Where each sensor sits on its vessel, as ROS transforms: base_link -> sensor frame.

The mount geometry is each sensor type's own (services/sensors: the models' docstrings);
it is restated here from the parameters because the library never imports a service, and
tests/catabot/ros2/test_frames.py checks every type against the model's own pose, so the
two cannot drift. One `tf2_msgs/TFMessage` of the fixed mounts goes on `/tf_static` once.
A radar is stabilised (its sweep level, turned with the heading only), so its frame moves
against its vessel as the vessel rolls and pitches: `BodyFrames` sends it on `/tf` beside
the bodies, with the state it was swept from.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from catabot.bus.messages import BodyStates
from catabot.ros2 import types
from catabot.ros2.cdr import TfBatch
from catabot.ros2.names import MAP, Names
from catabot.world import rotations
from catabot.world.world import Body, MountedSensor

OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
"""The ROS optical frame (z forward, x right, y down) in the camera's FLU frame."""
IDENTITY = (0.0, 0.0, 0.0, 1.0)


STABILISED = frozenset({"radar"})
"""Sensor types whose frame is level, turned with the heading only (not the hull's turn)."""


def stabilised(sensor: MountedSensor) -> bool:
    return sensor.config.type in STABILISED


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
    """base_link -> every fixed sensor frame of every scenario vessel (not the radars:
    `BodyFrames`); cameras also frame -> optical frame (their images' frame)."""
    out = []
    for sensor in names.world.sensors:
        if stabilised(sensor):
            continue
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


class BodyFrames:
    """One `/tf` message of some bodies' frames (map -> base_link) and of their radars'
    (base_link -> the level frame at the antenna, turned with the heading: `levelling`)."""

    def __init__(self, names: Names, bodies: list[Body] | tuple[Body, ...]) -> None:
        rows = [b.row for b in bodies]
        self.rows = None if rows == list(range(len(names.world.bodies))) else np.array(rows)
        on = {b.id for b in bodies}
        radars = [s for s in names.world.sensors if stabilised(s) and s.vessel in on]
        self.radar_rows = np.array([names.world.body(s.vessel).row for s in radars], np.intp)
        self.antennas = np.array([mount(s)[0] for s in radars], np.float64).reshape(-1, 3)
        parents = [MAP] * len(bodies) + [names.base_link(s.vessel) for s in radars]
        children = [names.base_link(b.id) for b in bodies] + [names.sensor_frame(s) for s in radars]
        self._batch = TfBatch(parents, children)

    def encode(self, batch: BodyStates) -> bytes:
        position, orientation = batch.position, batch.orientation
        if self.rows is not None:
            position, orientation = position[self.rows], orientation[self.rows]
        if len(self.radar_rows):  # a radar or two: Python floats beat arrays (rotations.py)
            level = [rotations.levelling(q) for q in batch.orientation[self.radar_rows].tolist()]
            position = np.concatenate((position, self.antennas))
            orientation = np.concatenate((orientation, level))
        return self._batch.encode(batch.stamp_ns, position, orientation)
