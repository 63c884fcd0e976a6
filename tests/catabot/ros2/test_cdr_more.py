"""cdr_more.py's encoders give rosbags' bytes for the same values, whatever the frame id's
length (every alignment residue before the 8-byte fields)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from catabot.ros2 import cdr_more, types

ROSBAGS = get_typestore(Stores.ROS2_JAZZY)
FRAMES = ["", "a", "ab", "abc", "ego/imu", "ego/gps1", "boat_007/cam_optical", "ümlaut"]
STAMPS = [0, 10, 1_500_000_001, 1_700_000_000_123_456_789]


def _pinned(data: bytes, typename: str) -> Any:
    msg = ROSBAGS.deserialize_cdr(data, typename)
    assert bytes(ROSBAGS.serialize_cdr(msg, typename)) == data
    return msg


def _stamp(msg: Any) -> int:
    return int(msg.header.stamp.sec) * 10**9 + int(msg.header.stamp.nanosec)


@pytest.mark.parametrize("frame", FRAMES)
def test_imu_bytes_are_rosbags_bytes(frame: str) -> None:
    cov = ([0.0] * 9, [float(i) for i in range(9)], [0.5] * 9)
    encode = cdr_more.imu_encoder(frame, cov)
    for k, stamp_ns in enumerate(STAMPS):
        values = [0.1 * k, -0.2, 0.3, 0.9, 1e-300, -5.0, 7.0, 0.0, 0.0, 9.81]
        msg = _pinned(encode(stamp_ns, values), types.IMU)
        assert (msg.header.frame_id, _stamp(msg)) == (frame, stamp_ns)
        o, w, a = msg.orientation, msg.angular_velocity, msg.linear_acceleration
        assert [o.x, o.y, o.z, o.w, w.x, w.y, w.z, a.x, a.y, a.z] == values
        assert list(msg.angular_velocity_covariance) == cov[1]
        assert list(msg.linear_acceleration_covariance) == cov[2]


@pytest.mark.parametrize("frame", FRAMES)
def test_navsatfix_bytes_are_rosbags_bytes(frame: str) -> None:
    encode = cdr_more.navsatfix_encoder(frame)
    msg = _pinned(encode(STAMPS[2], (43.7, -72.3, 12.5, 0.5, 2.0)), types.NAVSATFIX)
    assert (msg.latitude, msg.longitude, msg.altitude) == (43.7, -72.3, 12.5)
    assert (msg.status.status, msg.status.service) == (
        msg.status.STATUS_FIX,
        msg.status.SERVICE_GPS,
    )
    assert list(msg.position_covariance) == [0.25, 0, 0, 0, 0.25, 0, 0, 0, 4.0]
    assert msg.position_covariance_type == msg.COVARIANCE_TYPE_DIAGONAL_KNOWN


def test_twist_and_clock_bytes_are_rosbags_bytes() -> None:
    msg = _pinned(cdr_more.twist(1.25, -0.5), types.TWIST)
    assert (msg.linear.x, msg.linear.y, msg.angular.z) == (1.25, 0.0, -0.5)
    rows = cdr_more.twist_rows(np.array([1.0, float("nan")]), np.array([0.1, 0.2]))
    assert rows.shape == (2, 52) and rows[0].tobytes() == cdr_more.twist(1.0, 0.1)
    assert np.isnan(_pinned(rows[1].tobytes(), types.TWIST).linear.x)
    for stamp_ns in STAMPS:
        clock = _pinned(cdr_more.clock(stamp_ns), types.CLOCK).clock
        assert int(clock.sec) * 10**9 + int(clock.nanosec) == stamp_ns


@pytest.mark.parametrize("frame", FRAMES)
@pytest.mark.parametrize(
    "encoding, pixels",
    [
        ("rgb8", np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)),
        ("32FC1", np.array([[1.5, np.inf], [0.0, -2.0]], np.float32)),
        ("mono16", np.arange(7, dtype=np.uint16).reshape(1, 7)),
        ("mono8", np.zeros((0, 0), np.uint8)),
    ],
)
def test_image_bytes_are_rosbags_bytes(frame: str, encoding: str, pixels: np.ndarray) -> None:
    msg = _pinned(cdr_more.image_encoder(frame, encoding)(pixels, STAMPS[3]), types.IMAGE)
    assert (msg.header.frame_id, _stamp(msg), msg.encoding) == (frame, STAMPS[3], encoding)
    assert (msg.height, msg.width, msg.is_bigendian) == (*pixels.shape[:2], 0)
    assert msg.step * msg.height == pixels.nbytes and bytes(msg.data) == pixels.tobytes()


def test_restamper_changes_only_the_stamp() -> None:
    info = ROSBAGS.types[types.CAMERA_INFO]
    base = types.new(
        types.CAMERA_INFO, header=types.header(0, "ego/cam_optical"), height=4, width=6,
        distortion_model="plumb_bob", d=np.zeros(5), k=np.arange(9.0), r=np.eye(3).ravel(),
        p=np.arange(12.0), binning_x=0, binning_y=0,
        roi=types.new("sensor_msgs/msg/RegionOfInterest", x_offset=0, y_offset=0, height=0,
                      width=0, do_rectify=False),
    )  # fmt: skip
    assert isinstance(base, info)
    encode = cdr_more.restamper(types.serialize(base, types.CAMERA_INFO))
    for stamp_ns in STAMPS:
        msg = _pinned(encode(stamp_ns), types.CAMERA_INFO)
        assert _stamp(msg) == stamp_ns and list(msg.k) == list(range(9))
    with pytest.raises(ValueError, match="little-endian"):
        cdr_more.restamper(b"\x00\x00\x00\x00" + bytes(20))
