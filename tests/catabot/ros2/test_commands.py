"""ROS commands become bus commands only when they are what their topic says: CDR of the
type, every value in range; anything else is refused with the reason."""

from __future__ import annotations

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from catabot.bus.messages import ThrustCmd, TwistCmd, WaypointsCmd
from catabot.config.ros import WaypointDefaults
from catabot.ros2 import commands

ROSBAGS = get_typestore(Stores.ROS2_JAZZY)
T = ROSBAGS.types
DEFAULTS = WaypointDefaults(speed_mps=3.0, tolerance_m=1.5, mode="loop")


def _twist(x: float, z: float, *, y: float = 0.0) -> bytes:
    v3 = T["geometry_msgs/msg/Vector3"]
    msg = T["geometry_msgs/msg/Twist"](linear=v3(x=x, y=y, z=0.0), angular=v3(x=0.0, y=0.0, z=z))
    return bytes(ROSBAGS.serialize_cdr(msg, "geometry_msgs/msg/Twist"))


def _thrust(values: list[float]) -> bytes:
    layout = T["std_msgs/msg/MultiArrayLayout"](dim=[], data_offset=0)
    msg = T["std_msgs/msg/Float64MultiArray"](layout=layout, data=np.array(values, np.float64))
    return bytes(ROSBAGS.serialize_cdr(msg, "std_msgs/msg/Float64MultiArray"))


def _path(points: list[tuple[float, float]], frame: str = "map") -> bytes:
    def header(f: str) -> object:
        return T["std_msgs/msg/Header"](
            stamp=T["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id=f
        )

    poses = [
        T["geometry_msgs/msg/PoseStamped"](
            header=header(frame),
            pose=T["geometry_msgs/msg/Pose"](
                position=T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0),
                orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            ),
        )
        for x, y in points
    ]
    msg = T["nav_msgs/msg/Path"](header=header(frame), poses=poses)
    return bytes(ROSBAGS.serialize_cdr(msg, "nav_msgs/msg/Path"))


def test_twist_drives_surge_and_yaw_rate() -> None:
    assert commands.twist(_twist(1.5, -0.25, y=9.0)) == TwistCmd(surge=1.5, yaw_rate=-0.25)


def _string(text: str) -> bytes:
    return bytes(ROSBAGS.serialize_cdr(T["std_msgs/msg/String"](data=text), "std_msgs/msg/String"))


def test_only_the_padding_to_a_4_byte_boundary_is_taken() -> None:
    """A String's 14 bytes may come padded to 16; a Twist's 52 take no padding, so a String
    one byte longer (an audit's, on a bridge key, which names no type) is no Twist."""
    assert commands.decode(_string("hello") + b"\0\0", "std_msgs/msg/String").data == "hello"
    with pytest.raises(commands.Malformed):
        commands.decode(_string("hello") + b"\0", "std_msgs/msg/String")
    with pytest.raises(commands.Malformed, match="53 bytes, 52 expected"):
        commands.twist(_string("?" * 44))


@pytest.mark.parametrize(
    "payload, reason",
    [
        (b"", "not little-endian CDR"),
        (b"garbage!", "not little-endian CDR"),
        (b"\x00\x00\x00\x00" + _twist(1.0, 0.0)[4:], "not little-endian CDR"),
        (_twist(1.0, 0.0)[:-3], "not a geometry_msgs/msg/Twist"),
        (_twist(1.0, 0.0) + b"\0" * 8, "not a geometry_msgs/msg/Twist"),
        (_string("hello"), "not a geometry_msgs/msg/Twist"),
        (_twist(float("nan"), 0.0), "twist not finite: linear.x nan, angular.z 0.0"),
        (_twist(1.0, float("inf")), "twist not finite: linear.x 1.0, angular.z inf"),
        (_twist(1e6, 0.0), "out of range"),
        (b"\x00\x01\x00\x00" + bytes(2_000_000), "too big"),
    ],
)
def test_bad_twists_are_refused_with_the_reason(payload: bytes, reason: str) -> None:
    with pytest.raises(commands.CommandError, match=reason):
        commands.twist(payload)


def test_a_twist_stamped_on_cmd_vel_is_refused_by_name() -> None:
    """Newer Nav2 publishes TwistStamped on cmd_vel: the refusal said only "CDR message
    size mismatch for 'geometry_msgs/msg/Twist'"."""
    header = T["std_msgs/msg/Header"](
        stamp=T["builtin_interfaces/msg/Time"](sec=3, nanosec=0), frame_id="base_link"
    )
    v3 = T["geometry_msgs/msg/Vector3"]
    twist = T["geometry_msgs/msg/Twist"](linear=v3(x=1.0, y=0.0, z=0.0), angular=v3(x=0, y=0, z=0))
    msg = T["geometry_msgs/msg/TwistStamped"](header=header, twist=twist)
    payload = bytes(ROSBAGS.serialize_cdr(msg, "geometry_msgs/msg/TwistStamped"))
    said = r"; it is a geometry_msgs/msg/TwistStamped: cmd_vel takes geometry_msgs/msg/Twist \("
    with pytest.raises(commands.Malformed, match=r"^not a geometry_msgs/msg/Twist.*" + said):
        commands.twist(payload)


def test_thrust_needs_one_value_per_thruster_in_range() -> None:
    assert commands.thrust(_thrust([0.5, -1.0]), 2) == ThrustCmd(thrust=(0.5, -1.0))
    with pytest.raises(commands.CommandError, match="3 thrust values for 2 thrusters"):
        commands.thrust(_thrust([0.1, 0.2, 0.3]), 2)
    with pytest.raises(commands.CommandError, match=r"in \[-1, 1\]"):
        commands.thrust(_thrust([0.5, 1.5]), 2)
    with pytest.raises(commands.CommandError, match="not a std_msgs"):
        commands.thrust(_twist(1.0, 0.0), 2)


def test_path_becomes_waypoints_and_an_empty_one_releases() -> None:
    got = commands.waypoints(_path([(1.0, 2.0), (30.0, -4.0)]), DEFAULTS)
    assert got == WaypointsCmd(points=(1.0, 2.0, 30.0, -4.0), speed=3.0, tolerance=1.5, mode="loop")
    assert commands.waypoints(_path([], frame=""), DEFAULTS).mode == "release"
    with pytest.raises(commands.CommandError, match="frame 'odom'"):
        commands.waypoints(_path([(1.0, 2.0)], frame="odom"), DEFAULTS)
    with pytest.raises(commands.CommandError, match="not finite"):
        commands.waypoints(_path([(float("nan"), 2.0)]), DEFAULTS)


def test_command_dispatches_by_topic_name() -> None:
    msg = commands.command("cmd_vel", _twist(0.5, 0.0), thrusters=2, defaults=DEFAULTS)
    assert isinstance(msg, TwistCmd)
    with pytest.raises(commands.CommandError, match="no command named"):
        commands.command("cmd_pos", b"", thrusters=2, defaults=DEFAULTS)
