"""The static transforms say where each sensor model really looks from: every mount is
checked against the sensor model's own geometry (services/sensors), and the frames form a
tree under `map`."""

from __future__ import annotations

import numpy as np
from rosbags.typesys import Stores, get_typestore

from catabot.ros2 import frames, types
from catabot.ros2.convert import Converter
from catabot.ros2.names import Names
from catabot.world import rotations
from catabot.world.world import MountedSensor
from services.sensors.camera import OPTICAL_TO_BODY, CameraModel
from services.sensors.gps import GpsModel
from services.sensors.imu import ImuModel
from services.sensors.lidar import LidarModel
from services.sensors.mount import Mount
from tests.catabot.ros2.world_fixture import world

ROSBAGS = get_typestore(Stores.ROS2_JAZZY)


def _sensor(name: str) -> MountedSensor:
    return next(s for s in world().sensors if s.config.name == name)


def _transforms() -> dict[str, frames.Transform]:
    return {t.child: t for t in frames.static_transforms(Names(world()))}


def test_optical_frame_is_the_cameras() -> None:
    assert np.array_equal(frames.OPTICAL, OPTICAL_TO_BODY)


def test_mounts_are_the_models_own() -> None:
    scene = Mount(scene=object(), period_ns=50_000_000)
    lidar = LidarModel(_sensor("lidar").params, scene)
    xyz, rot = frames.mount(_sensor("lidar"))
    assert np.allclose(rot, lidar.mount_rot) and np.allclose(xyz, lidar.mount_xyz)
    camera = CameraModel(_sensor("cam").params, scene)
    xyz, rot = frames.mount(_sensor("cam"))
    assert np.allclose(rot @ frames.OPTICAL, camera.mount_rot)
    assert np.allclose(xyz, camera.mount_pos)
    imu = ImuModel(_sensor("imu").params, Mount())
    assert np.allclose(frames.mount(_sensor("imu"))[0], imu.lever_arm)
    gps = GpsModel(_sensor("gps").params, Mount())
    assert np.allclose(frames.mount(_sensor("gps"))[0], gps.antenna_offset)
    radar = _sensor("radar")
    assert frames.mount(radar)[0] == (0.0, 0.0, radar.params.antenna_height_m)


def test_static_transforms_carry_the_mounts() -> None:
    tf = _transforms()
    assert set(tf) == {"ego/imu", "ego/gps", "ego/lidar", "ego/radar", "ego/cam", "ego/cam_optical"}
    for name in ("imu", "gps", "lidar", "radar", "cam"):
        t = tf[f"ego/{name}"]
        xyz, rot = frames.mount(_sensor(name))
        assert t.parent == "ego/base_link" and t.translation == xyz
        assert np.allclose(rotations.matrix(t.rotation), rot)
    optical = tf["ego/cam_optical"]
    assert optical.parent == "ego/cam" and optical.translation == (0.0, 0.0, 0.0)
    assert np.allclose(rotations.matrix(optical.rotation), frames.OPTICAL)
    assert np.allclose(optical.rotation, (-0.5, 0.5, -0.5, 0.5))  # ROS's optical quaternion


def test_every_frame_reaches_map_through_tf_and_tf_static() -> None:
    w = world()
    convert = Converter(w)
    static = ROSBAGS.deserialize_cdr(convert.static_tf().data, types.TF)  # type: ignore[union-attr]
    dynamic = ROSBAGS.deserialize_cdr(convert.tf(w.start_states()), types.TF)
    parent = {
        t.child_frame_id: t.header.frame_id for t in [*static.transforms, *dynamic.transforms]
    }
    assert len(parent) == len(static.transforms) + len(dynamic.transforms)  # one parent each
    for frame in parent:
        seen = [frame]
        while seen[-1] != "map":
            assert seen[-1] in parent, f"{frame}: {seen} ends without reaching map"
            seen.append(parent[seen[-1]])
            assert len(seen) < 10
    bodies = {f"{b}/base_link" for b in w.body_ids}
    assert bodies <= set(parent) and {"ego/cam_optical", "ego/lidar"} <= set(parent)


def test_root_namespace_drops_the_frame_prefix() -> None:
    w = world(namespaces={"ego": "/"})
    assert w.scenario.ros is not None
    names = Names(w, w.scenario.ros)
    assert names.base_link("ego") == "base_link" and names.odom("ego") == "/odom"
    assert names.topic("ego", "cmd_vel") == "/cmd_vel"
    assert names.sensor_frame(_sensor("lidar")) == "lidar"
    assert names.base_link("other") == "other/base_link"
