"""ROS 2 message types from a maintained source: rosbags' ROS 2 Jazzy typestore.

Definitions (for MCAP's `ros2msg` schemas) and RIHS01 type hashes (for rmw_zenoh keys) come
from rosbags (`generate_msgdef`, `hash_rihs01`), not from a hand-kept copy, so they follow
the distribution; rosbags' own serializer is used where no hand-written encoder is faster
(`cdr.py`), and it is the reference every hand-written encoder is pinned to in the tests.
"""

from __future__ import annotations

from functools import cache
from typing import Any

from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Typestore

from catabot.bus.clock import NS_PER_S

DISTRO = Stores.ROS2_JAZZY

ODOMETRY = "nav_msgs/msg/Odometry"
PATH = "nav_msgs/msg/Path"
TF = "tf2_msgs/msg/TFMessage"
CLOCK = "rosgraph_msgs/msg/Clock"
IMU = "sensor_msgs/msg/Imu"
NAVSATFIX = "sensor_msgs/msg/NavSatFix"
POINTCLOUD2 = "sensor_msgs/msg/PointCloud2"
IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
TWIST = "geometry_msgs/msg/Twist"
FLOAT64_ARRAY = "std_msgs/msg/Float64MultiArray"
MARKER_ARRAY = "visualization_msgs/msg/MarkerArray"


@cache
def store() -> Typestore:
    """The Jazzy typestore, built once per process (~0.1 s)."""
    return get_typestore(DISTRO)


@cache
def msgdef(typename: str) -> str:
    """The `ros2msg` text of a type with its dependencies, as rosbag2 writes it in MCAP."""
    text, _ = store().generate_msgdef(typename, ros_version=2)
    return text


@cache
def rihs01(typename: str) -> str:
    """REP-2016 type hash, `RIHS01_<sha256 hex>`: the last chunk of an rmw_zenoh key."""
    return store().hash_rihs01(typename)


def dds_name(typename: str) -> str:
    """`pkg/msg/Name` -> `pkg::msg::dds_::Name_`, the type chunk of rmw_zenoh keys."""
    package, kind, name = typename.split("/")
    return f"{package}::{kind}::dds_::{name}_"


def new(typename: str, **fields: Any) -> Any:
    """A rosbags message object of `typename`."""
    return store().types[typename](**fields)


def serialize(msg: Any, typename: str) -> bytes:
    """CDR with its 4-byte encapsulation header (little-endian), as every ROS 2 RMW sends."""
    return bytes(store().serialize_cdr(msg, typename))


def deserialize(data: bytes, typename: str) -> Any:
    return store().deserialize_cdr(data, typename)


def stamp(stamp_ns: int) -> Any:
    """builtin_interfaces/Time of simulated nanoseconds (floor division: nanosec >= 0)."""
    sec, nanosec = divmod(stamp_ns, NS_PER_S)
    return new("builtin_interfaces/msg/Time", sec=sec, nanosec=nanosec)


def header(stamp_ns: int, frame_id: str) -> Any:
    return new("std_msgs/msg/Header", stamp=stamp(stamp_ns), frame_id=frame_id)
