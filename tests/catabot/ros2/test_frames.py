"""The static transforms say where each sensor model really looks from: every mount is
checked against the sensor model's own geometry (services/sensors), and the frames form a
tree under `map`."""

from __future__ import annotations

from typing import Any

import numpy as np
from rosbags.typesys import Stores, get_typestore

from catabot.bus.messages import BodyStates
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
from services.sensors.radar import RadarModel
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
    assert set(tf) == {"ego/imu", "ego/gps", "ego/lidar", "ego/cam", "ego/cam_optical"}
    for name in ("imu", "gps", "lidar", "cam"):
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


def _tilted_states() -> BodyStates:
    """The start states with the ego rolled 12 deg, pitched -7 and heading 40, lifted 0.4 m."""
    states = world().start_states()
    states.orientation[0] = rotations.from_rpy(*np.radians([12.0, -7.0, 40.0]))
    states.position[0] = (3.0, -2.0, 0.4)
    return states


def _composed(states: BodyStates) -> tuple[np.ndarray, np.ndarray]:
    """The radar frame in `map` through /tf: map -> ego/base_link -> ego/radar."""
    message = ROSBAGS.deserialize_cdr(Converter(world()).tf(states), types.TF)
    tf = {t.child_frame_id: t for t in message.transforms}
    body, radar = tf["ego/base_link"].transform, tf["ego/radar"].transform
    assert tf["ego/radar"].header.frame_id == "ego/base_link"
    assert tf["ego/radar"].header.stamp.sec == states.stamp_ns // 10**9

    def pose(t: Any) -> tuple[np.ndarray, np.ndarray]:
        r = t.rotation
        return np.array([t.translation.x, t.translation.y, t.translation.z]), rotations.matrix(
            (r.x, r.y, r.z, r.w)
        )

    (p_body, r_body), (p_radar, r_radar) = pose(body), pose(radar)
    return p_body + r_body @ p_radar, r_body @ r_radar


def test_the_radar_frame_on_tf_is_the_level_one_the_model_sweeps_from() -> None:
    """A tilted hull: the frame /tf gives the radar is the model's own antenna position and
    its heading alone (the echoes, level in it, land at their true heights in map)."""
    states = _tilted_states()
    model = RadarModel(_sensor("radar").params, Mount(scene=object(), period_ns=50_000_000))
    swept: list[np.ndarray] = []

    def sweep(origin: np.ndarray, bearings: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        swept.append(origin)
        return np.zeros((len(bearings), 0)), np.zeros(len(bearings))

    model.sweep = sweep  # type: ignore[method-assign]
    sweep = model.sample(states.row(0), tick=3, stamp_ns=40_000_000)
    origin, rot = _composed(states)
    assert np.allclose(origin, swept[0], atol=1e-12)
    assert np.allclose(rot, rotations.rpy(0.0, 0.0, np.degrees(sweep.heading_rad)), atol=1e-12)
    assert not np.allclose(rot, rotations.matrix(states.orientation[0]), atol=0.1)  # tilted


def test_a_level_hull_gives_the_radar_the_hulls_own_turn() -> None:
    states = world().start_states()
    origin, rot = _composed(states)
    assert np.allclose(rot, rotations.matrix(states.orientation[0]), atol=1e-12)
    height = _sensor("radar").params.antenna_height_m
    assert np.allclose(origin, states.position[0] + (0.0, 0.0, height))
