"""ROS 2 message definitions written into `run.mcap`, and the mapping onto them.

MCAP's `ros2msg` schema encoding carries the full text of a message and of every message it
uses, concatenated with `===...` separators and `MSG: pkg/Type` lines (the form rosbag2 writes).
The text is spelled out here, rather than read from a ROS installation, so recording needs no
ROS and Foxglove Studio or `ros2 bag` read the file as native `nav_msgs/msg/Odometry`.
"""

from __future__ import annotations

from catabot.bus.clock import NS_PER_S

ODOMETRY = "nav_msgs/msg/Odometry"
WORLD_FRAME = "map"

_SEPARATOR = "=" * 80

_ODOMETRY_TEXT = """\
# Estimate of a position and velocity in free space.
# The pose is in the frame given by header.frame_id;
# the twist is in the frame given by child_frame_id.
std_msgs/Header header
string child_frame_id
geometry_msgs/PoseWithCovariance pose
geometry_msgs/TwistWithCovariance twist
"""

_DEPENDENCIES = {
    "std_msgs/Header": """\
builtin_interfaces/Time stamp
string frame_id
""",
    "builtin_interfaces/Time": """\
int32 sec
uint32 nanosec
""",
    "geometry_msgs/PoseWithCovariance": """\
Pose pose
float64[36] covariance
""",
    "geometry_msgs/Pose": """\
Point position
Quaternion orientation
""",
    "geometry_msgs/Point": """\
float64 x
float64 y
float64 z
""",
    "geometry_msgs/Quaternion": """\
float64 x 0
float64 y 0
float64 z 0
float64 w 1
""",
    "geometry_msgs/TwistWithCovariance": """\
Twist twist
float64[36] covariance
""",
    "geometry_msgs/Twist": """\
Vector3 linear
Vector3 angular
""",
    "geometry_msgs/Vector3": """\
float64 x
float64 y
float64 z
""",
}


def concatenated(main: str, deps: dict[str, str]) -> str:
    """A message definition followed by its dependencies, in the format `mcap_ros2` parses."""
    parts = [main]
    for name, text in deps.items():
        parts.append(f"{_SEPARATOR}\nMSG: {name}\n{text}")
    return "\n".join(parts)


ODOMETRY_MSGDEF = concatenated(_ODOMETRY_TEXT, _DEPENDENCIES)
HEADER_DEPENDENCIES = {k: _DEPENDENCIES[k] for k in ("std_msgs/Header", "builtin_interfaces/Time")}
"""What every stamped message (Image, PointCloud2) depends on."""
"""`nav_msgs/msg/Odometry` with its dependencies, in the format `mcap_ros2` parses."""

TF_MESSAGE = "tf2_msgs/msg/TFMessage"
_TF_TEXT = """\
geometry_msgs/TransformStamped[] transforms
"""
TF_MSGDEF = concatenated(
    _TF_TEXT,
    {
        "geometry_msgs/TransformStamped": """\
std_msgs/Header header
string child_frame_id
Transform transform
""",
        **HEADER_DEPENDENCIES,
        "geometry_msgs/Transform": """\
Vector3 translation
Quaternion rotation
""",
        "geometry_msgs/Vector3": _DEPENDENCIES["geometry_msgs/Vector3"],
        "geometry_msgs/Quaternion": _DEPENDENCIES["geometry_msgs/Quaternion"],
    },
)
"""`tf2_msgs/msg/TFMessage`: every body's frame in `map`, one message a tick on `/tf`."""


def stamp(stamp_ns: int) -> dict[str, int]:
    """builtin_interfaces/Time from simulated nanoseconds (floor division keeps nanosec >= 0)."""
    sec, nanosec = divmod(stamp_ns, NS_PER_S)
    return {"sec": sec, "nanosec": nanosec}
