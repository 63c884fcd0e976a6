"""Each sensor sample as ROS 2 messages, read back with rosbags: topics, frames, stamps,
covariances from the noise parameters, a known point where the sensor model puts it,
image sizes and encodings, and a CameraInfo that projects each pixel's ray onto it."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from catabot.bus.messages import (
    BodyStates,
    CameraFrame,
    GpsFix,
    ImuSample,
    LidarScan,
    RadarSweep,
    ThrustCmd,
    TwistBatch,
    TwistCmd,
)
from catabot.ros2 import types
from catabot.ros2.convert import Converter
from catabot.ros2.convert_sensors import normals_rgb
from services.sensors.camera import pinhole, pixel_rays
from services.sensors.mount import Mount
from services.sensors.radar import RadarModel
from tests.catabot.ros2.world_fixture import world

ROSBAGS = get_typestore(Stores.ROS2_JAZZY)
STAMP = 1_230_000_000


def _read(outs: list[Any]) -> dict[str, Any]:
    return {o.topic: ROSBAGS.deserialize_cdr(o.data, o.type) for o in outs}


def _stamp(msg: Any) -> int:
    return int(msg.header.stamp.sec) * 10**9 + int(msg.header.stamp.nanosec)


def test_imu_covariances_come_from_the_noise_parameters() -> None:
    w = world()
    p = next(s for s in w.sensors if s.config.name == "imu").params
    msg = ImuSample(3, STAMP, (0.0, 0.0, 0.1, 0.99), (0.1, 0.2, 0.3), (0.0, 0.1, 9.8))
    imu = _read(Converter(w).sensor("sensor/ego/imu", msg))["/ego/imu/imu"]
    assert imu.header.frame_id == "ego/imu" and _stamp(imu) == STAMP
    gyro, accel = (
        p.gyro_sigma**2 + p.gyro_bias_instability**2,
        p.accel_sigma**2 + p.accel_bias_instability**2,
    )
    assert np.allclose(imu.angular_velocity_covariance, np.diag([gyro] * 3).ravel())
    assert np.allclose(imu.linear_acceleration_covariance, np.diag([accel] * 3).ravel())
    assert (imu.linear_acceleration.z, imu.orientation.w) == (9.8, 0.99)


def test_navsatfix_is_the_gps_sample() -> None:
    fix = GpsFix(5, STAMP, 43.70441, -72.28872, 3.25, 0.5, 1.0)
    msg = _read(Converter(world()).sensor("sensor/ego/gps", fix))["/ego/gps/fix"]
    assert (msg.latitude, msg.longitude, msg.altitude) == (43.70441, -72.28872, 3.25)
    assert list(msg.position_covariance) == [0.25, 0, 0, 0, 0.25, 0, 0, 0, 1.0]
    assert msg.header.frame_id == "ego/gps" and msg.status.status == msg.status.STATUS_FIX


def test_lidar_points_keep_every_field() -> None:
    n = 5
    scan = LidarScan(
        1, STAMP, np.array([[8.0, 0.5, -0.25]] * n, np.float32),
        np.linspace(0, 1, n, dtype=np.float32), np.arange(n, dtype=np.uint16),
        np.array([4, 1, 0, 3, 2], np.uint8), np.array([3, 0, 0, 2, 0], np.int32),
        np.array([0, 0, 1, 0, 0], bool), np.zeros((2, 3), np.float32),
    )  # fmt: skip
    cloud = _read(Converter(world()).sensor("sensor/ego/lidar", scan))["/ego/lidar/points"]
    assert [f.name for f in cloud.fields] == [
        "x",
        "y",
        "z",
        "intensity",
        "ring",
        "label",
        "rain",
        "instance",
    ]
    assert (cloud.width, cloud.height, cloud.point_step, cloud.row_step) == (n, 1, 24, 24 * n)
    rows = np.frombuffer(bytes(cloud.data), np.uint8).reshape(n, 24)
    xyz = rows[:, :12].copy().view("<f4")
    assert np.array_equal(xyz, scan.points) and rows[:, 18].tolist() == [4, 1, 0, 3, 2]
    assert rows[:, 19].tolist() == [0, 0, 1, 0, 0] and rows[:, 16:18].copy().view(
        "<u2"
    ).ravel().tolist() == list(range(n))


def test_radar_echo_is_where_the_beam_points() -> None:
    w = world()
    sensor = next(s for s in w.sensors if s.config.name == "radar")
    model = RadarModel(sensor.params, Mount(scene=object(), period_ns=sensor.config.period_ns))
    intensity = np.zeros((3, 512), np.uint8)
    intensity[2, 100] = 200  # beam 2 (clockwise of the first), bin 100
    sweep = RadarSweep(
        9, STAMP, 1.0, 1.0 - 2 * model.step_rad, 0.3, 250.0, 3, intensity, np.zeros(3, np.float32)
    )
    cloud = _read(Converter(w).sensor("sensor/ego/radar", sweep))["/ego/radar/points"]
    x, y, z, strength = np.frombuffer(bytes(cloud.data), "<f4")
    r, azimuth = 100.5 * 250.0 / 512, 1.0 - 2 * model.step_rad
    assert math.isclose(x, r * math.cos(azimuth), rel_tol=1e-6) and math.isclose(
        y, r * math.sin(azimuth), rel_tol=1e-6
    )
    assert (z, strength, cloud.header.frame_id) == (0.0, 200.0, "ego/radar")


def test_radar_ppi_comes_once_per_turn() -> None:
    convert, turn = Converter(world()), 500_000_000  # 0.5 s a turn, a sweep every 50 ms
    topics = []
    for k in range(20):
        sweep = RadarSweep(
            k,
            k * 50_000_000,
            0.0,
            0.0,
            0.0,
            250.0,
            0,
            np.zeros((0, 512), np.uint8),
            np.zeros(0, np.float32),
        )
        topics.append([o.topic for o in convert.sensor("sensor/ego/radar", sweep)])
    ppi = [k for k, t in enumerate(topics) if "/ego/radar/ppi" in t]
    assert ppi == [9, 19] and turn // 50_000_000 == 10


def _frame() -> CameraFrame:
    h, w = 48, 64
    rng = np.random.default_rng(1)
    return CameraFrame(
        2, STAMP, w, h, 1.2, 0, rng.integers(0, 256, (h, w, 3), dtype=np.uint8),
        rng.random((h, w), dtype=np.float32), rng.integers(-127, 128, (h, w, 3), dtype=np.int8),
        rng.integers(0, 5, (h, w), dtype=np.uint8), rng.integers(0, 9, (h, w), dtype=np.uint16),
        np.zeros((0, 6), np.float32), np.zeros((0, 2), np.uint8),
    )  # fmt: skip


def test_camera_images_have_their_sizes_encodings_and_pixels() -> None:
    frame = _frame()
    got = _read(Converter(world()).sensor("sensor/ego/cam", frame))
    expected = {
        "image_raw": ("rgb8", frame.color),
        "depth": ("32FC1", frame.depth),
        "segmentation": ("mono8", frame.segmentation),
        "instance": ("mono16", frame.instance),
        "normals": ("rgb8", normals_rgb(frame.normals)),
    }
    for name, (encoding, pixels) in expected.items():
        img = got[f"/ego/cam/{name}"]
        assert (img.encoding, img.height, img.width) == (encoding, 48, 64)
        assert img.header.frame_id == "ego/cam_optical" and _stamp(img) == STAMP
        assert bytes(img.data) == np.ascontiguousarray(pixels).tobytes()
    ref = np.rint((frame.normals.astype(np.float32) / 127.0 + 1.0) * 127.5).clip(0, 255)
    assert np.array_equal(normals_rgb(frame.normals), ref.astype(np.uint8))  # dataset.py's PNGs


def test_camera_info_projects_each_pixel_ray_onto_its_pixel() -> None:
    w = world()
    info = _read(Converter(w).sensor("sensor/ego/cam", _frame()))["/ego/cam/camera_info"]
    assert (info.width, info.height, info.distortion_model) == (64, 48, "plumb_bob")
    p = next(s for s in w.sensors if s.config.name == "cam").params
    rays = pixel_rays(pinhole(p.width, p.height, p.hfov_deg)).astype(np.float64)
    k = np.asarray(info.k).reshape(3, 3)
    uvw = rays @ k.T
    uv = uvw[:, :2] / uvw[:, 2:]
    v, u = np.divmod(np.arange(p.width * p.height), p.width)
    assert np.allclose(uv, np.stack([u, v], axis=1), atol=1e-4)  # ROS: pixel u's centre at u
    assert np.allclose(np.asarray(info.p).reshape(3, 4)[:, :3], k)


def test_states_commands_and_set_points() -> None:
    w = world()
    convert = Converter(w)
    n = len(w.bodies)
    position, orientation = np.arange(n * 3.0).reshape(n, 3), np.tile([0, 0, 0.6, 0.8], (n, 1))
    zero = np.zeros((n, 3))
    states = BodyStates(
        0, STAMP, w.body_ids, position, orientation, zero + 1, zero + 0.5, zero, zero
    )
    odoms = [ROSBAGS.deserialize_cdr(d, types.ODOMETRY) for d in convert.odometry(states)]
    assert convert.odom_topics == ("/ego/odom", "/other/odom", "/boat_000/odom")
    for i, odom in enumerate(odoms):
        assert (odom.header.frame_id, odom.child_frame_id) == ("map", f"{w.body_ids[i]}/base_link")
        assert (
            odom.pose.pose.position.x == states.position[i, 0] and odom.twist.twist.angular.z == 0.5
        )
    assert len(Converter(w, boats=False).odometry(states)) == 2
    twist = ROSBAGS.deserialize_cdr(convert.command("ego", TwistCmd(1.5, -0.2)).data, types.TWIST)
    assert (twist.linear.x, twist.angular.z) == (1.5, -0.2)
    thrust = convert.command("other", ThrustCmd((0.25, -1.0)))
    assert thrust.topic == "/other/thrust"
    assert list(ROSBAGS.deserialize_cdr(thrust.data, types.FLOAT64_ARRAY).data) == [0.25, -1.0]
    rows = convert.boat_twists(TwistBatch(0, 0, w.boat_ids, np.array([2.0]), np.array([0.1])))
    assert ROSBAGS.deserialize_cdr(rows[0].tobytes(), types.TWIST).linear.x == 2.0
    with pytest.raises(ValueError, match="expected"):
        convert.odometry(BodyStates(0, 0, ("x",) * n, *states.arrays()))
    with pytest.raises(ValueError, match="a CameraFrame, not a ImuSample"):
        convert.sensor("sensor/ego/imu", _frame())
    with pytest.raises(ValueError, match="no sensor"):
        convert.sensor("sensor/ego/nothing", _frame())


def test_buoys_are_boxes_in_their_own_frames() -> None:
    buoys = ROSBAGS.deserialize_cdr(Converter(world()).buoys().data, types.MARKER_ARRAY)  # type: ignore[union-attr]
    (marker,) = buoys.markers
    assert marker.header.frame_id == "b1/base_link" and marker.frame_locked
    assert marker.type == marker.CUBE and marker.scale.z == 1.0
