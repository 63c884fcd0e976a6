"""The hand-written encoders (cdr.py, cdr_more.py) pack exactly the bytes rosbags' serializer
gives for the same values (an implementation no one here wrote: our bytes decode with it and
re-encode to themselves), and mcap_ros2's decoder (what mcap_read uses) reads them with the
definitions from types.msgdef."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from mcap.records import Schema
from mcap_ros2.decoder import DecoderFactory
from rosbags.typesys import Stores, get_typestore

from catabot.bus.messages import LidarScan, VesselState
from catabot.ros2 import cdr, types
from catabot.ros2.convert_sensors import LIDAR_FIELDS, LIDAR_POINT, lidar_points

# Lengths 0..8 with the NUL put every residue mod 4 and mod 8 before the float64s.
FRAMES = ["", "a", "ab", "abc", "ego", "ego1", "vessel", "boat_007", "ümlaut", "x" * 33]
STAMPS = [0, 10, 1_500_000_001, 1_700_000_000_123_456_789, -1]


def _state(k: int) -> VesselState:
    f = 0.1 * k + 0.25
    return VesselState(
        tick=k,
        stamp_ns=k,
        position=(f, -2.0 * f, 1e300),
        orientation=(0.0, -0.0, 0.5 * f, np.float64(0.75)),
        linear_velocity=(1, 2, 3),  # ints, as the dynamic serializer coerces them
        angular_velocity=(float("inf"), -f, 5e-324),
        linear_acceleration=(9.0, 9.0, 9.0),
        angular_acceleration=(9.0, 9.0, 9.0),
    )


ROSBAGS = get_typestore(Stores.ROS2_JAZZY)


def _pinned(data: bytes, typename: str) -> Any:
    """The message rosbags reads from `data`, checked to re-encode to exactly `data`."""
    msg = ROSBAGS.deserialize_cdr(data, typename)
    assert bytes(ROSBAGS.serialize_cdr(msg, typename)) == data
    return msg


def _check_odometry(msg: Any, state: VesselState, frame: str, child: str, stamp_ns: int) -> None:
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == divmod(stamp_ns, 10**9)
    assert (msg.header.frame_id, msg.child_frame_id) == (frame, child)
    pose, twist = msg.pose.pose, msg.twist.twist
    assert (pose.position.x, pose.position.y, pose.position.z) == state.position
    o = pose.orientation
    assert (o.x, o.y, o.z, o.w) == state.orientation
    assert (twist.linear.x, twist.linear.y, twist.linear.z) == state.linear_velocity
    assert (twist.angular.x, twist.angular.y, twist.angular.z) == state.angular_velocity
    assert list(msg.pose.covariance) == [0.0] * 36 == list(msg.twist.covariance)


@pytest.mark.parametrize("child", FRAMES)
@pytest.mark.parametrize("frame", ["map", "", "odom_frame"])
def test_odometry_bytes_are_rosbags_bytes(frame: str, child: str) -> None:
    encode = cdr.odometry_encoder(frame, child)
    for k, stamp_ns in enumerate(STAMPS[:4]):  # a negative stamp has no ROS 2 form
        state = _state(k)
        data = encode(state, stamp_ns)
        assert data[:4] == b"\x00\x01\x00\x00"
        _check_odometry(_pinned(data, types.ODOMETRY), state, frame, child, stamp_ns)


def _scan(n: int, seed: int) -> LidarScan:
    rng = np.random.default_rng(seed)
    return LidarScan(
        tick=seed,
        stamp_ns=seed,
        points=rng.normal(size=(n, 3)).astype(np.float32),
        intensity=rng.random(n, dtype=np.float32),
        ring=rng.integers(0, 64, n).astype(np.uint16),
        cls=rng.integers(0, 9, n).astype(np.uint8),
        instance=rng.integers(-1, 1000, n).astype(np.int32),
        is_rain=rng.random(n) < 0.1,
        range_image=np.zeros((4, 8), np.float32),
    )


@pytest.mark.parametrize("n", [0, 1, 7, 300])
@pytest.mark.parametrize("sensor", ["l", "li", "lid", "lidar", "top_lidar"])
def test_pointcloud2_bytes_are_rosbags_bytes(n: int, sensor: str) -> None:
    encode = cdr.pointcloud2_encoder(f"ego/{sensor}", LIDAR_FIELDS, LIDAR_POINT.itemsize)
    for stamp_ns in STAMPS[:4]:
        scan = _scan(n, stamp_ns % 97)
        cloud = lidar_points(scan)
        msg = _pinned(encode(cloud, len(cloud), stamp_ns), types.POINTCLOUD2)
        assert msg.header.frame_id == f"ego/{sensor}"
        assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == divmod(stamp_ns, 10**9)
        assert (msg.height, msg.width, msg.point_step) == (1, len(cloud), 24)
        assert bytes(msg.data) == cloud.tobytes()


def test_odometry_batch_equals_one_message_at_a_time() -> None:
    children = ("ego", "boat_000", "b", "buoy_0001")  # three template lengths
    rng = np.random.default_rng(3)
    values = rng.normal(size=(len(children), 13))
    batch = cdr.OdometryBatch("map", children).encode(1_234_567_890_123, values)
    for i, child in enumerate(children):
        one = cdr.odometry_packer("map", child)(1_234_567_890_123, values[i].tolist())
        assert batch[i] == one


def test_odometry_batch_refuses_a_wrong_shape() -> None:
    with pytest.raises(ValueError, match=r"shape \(2, 12\), not \(2, 13\)"):
        cdr.OdometryBatch("map", ("a", "b")).encode(0, np.zeros((2, 12)))


def test_tf_batch_decodes_as_tf2_msgs_with_every_frame() -> None:
    children = ("ego", "boat_000", "b")  # ids of three lengths: alignment differs per body
    rng = np.random.default_rng(5)
    pos, quat = rng.normal(size=(3, 3)), rng.normal(size=(3, 4))
    data = cdr.TfBatch("map", children).encode(2_500_000_001, pos, quat)
    decoded = _mcap_ros2(data, types.TF)
    _pinned(data, types.TF)
    assert [t.child_frame_id for t in decoded.transforms] == list(children)
    for i, t in enumerate(decoded.transforms):
        assert (t.header.frame_id, t.header.stamp.sec, t.header.stamp.nanosec) == (
            "map",
            2,
            500_000_001,
        )
        got = t.transform.translation
        assert (got.x, got.y, got.z) == tuple(pos[i])
        r = t.transform.rotation
        assert (r.x, r.y, r.z, r.w) == tuple(quat[i])
    with pytest.raises(ValueError, match="for 3 bodies"):
        cdr.TfBatch("map", children).encode(0, pos[:2], quat)


def _mcap_ros2(data: bytes, typename: str) -> Any:
    """`data` read by mcap_ros2's decoder with the definition written into run.mcap."""
    schema = Schema(id=1, name=typename, encoding="ros2msg", data=types.msgdef(typename).encode())
    decoder = DecoderFactory().decoder_for("cdr", schema)
    assert decoder is not None
    return decoder(data)


def test_odometry_and_pointcloud_read_back_with_mcap_ros2() -> None:
    state = _state(3)
    odom = _mcap_ros2(cdr.odometry_encoder("map", "ego/base_link")(state, 7), types.ODOMETRY)
    _check_odometry(odom, state, "map", "ego/base_link", 7)
    cloud = lidar_points(_scan(9, 1))
    data = cdr.pointcloud2_encoder("ego/l", LIDAR_FIELDS, 24)(cloud, len(cloud), 5)
    msg = _mcap_ros2(data, types.POINTCLOUD2)
    assert (msg.row_step, msg.is_bigendian, msg.is_dense) == (24 * 9, False, True)
    assert [(f.name, f.offset, f.datatype, f.count) for f in msg.fields] == [
        (f["name"], f["offset"], f["datatype"], f["count"]) for f in LIDAR_FIELDS
    ]
    assert bytes(msg.data) == cloud.tobytes()
