"""LiDAR scans in `run.mcap` as ROS 2 `sensor_msgs/msg/PointCloud2` (CDR).

One point per return, in the sensor frame `<vessel>/<sensor>` (the stream `sensor/<vessel>/
<sensor>`), unorganised (height 1), little-endian, 24 bytes a point:

    x y z intensity: float32 at 0, 4, 8, 12 | ring: uint16 at 16 | label: uint8 at 18 (the
    scene class, 0 for a raindrop) | rain: uint8 at 19 (1 = raindrop) | instance: int32 at 20

so Foxglove Studio and `ros2 bag` read it natively and can colour points by class or rain.
The bytes come from one structured NumPy array: no per-point Python.
"""

from __future__ import annotations

import typing

import numpy as np

from catabot.bus.messages import LidarScan, Message
from catabot.errors import CataBotError
from services.recorder.cdr import pointcloud2_encoder
from services.recorder.ros2_msgdefs import HEADER_DEPENDENCIES, concatenated

POINTCLOUD2 = "sensor_msgs/msg/PointCloud2"
_POINTCLOUD2_TEXT = """\
std_msgs/Header header
uint32 height
uint32 width
PointField[] fields
bool is_bigendian
uint32 point_step
uint32 row_step
uint8[] data
bool is_dense
"""
_POINTFIELD_TEXT = """\
uint8 INT8    = 1
uint8 UINT8   = 2
uint8 INT16   = 3
uint8 UINT16  = 4
uint8 INT32   = 5
uint8 UINT32  = 6
uint8 FLOAT32 = 7
uint8 FLOAT64 = 8
string name
uint32 offset
uint8  datatype
uint32 count
"""
POINTCLOUD2_MSGDEF = concatenated(
    _POINTCLOUD2_TEXT, {**HEADER_DEPENDENCIES, "sensor_msgs/PointField": _POINTFIELD_TEXT}
)
_LAYOUT = (  # name, NumPy type, sensor_msgs/PointField datatype
    ("x", "<f4", 7),
    ("y", "<f4", 7),
    ("z", "<f4", 7),
    ("intensity", "<f4", 7),
    ("ring", "<u2", 4),
    ("label", "u1", 2),
    ("rain", "u1", 2),
    ("instance", "<i4", 5),
)
POINT = np.dtype([(name, kind) for name, kind, _ in _LAYOUT])  # packed: offsets add up
_OFFSETS = np.cumsum([0] + [np.dtype(kind).itemsize for _, kind, _ in _LAYOUT])
FIELDS = [
    {"name": name, "offset": int(offset), "datatype": datatype, "count": 1}
    for (name, _, datatype), offset in zip(_LAYOUT, _OFFSETS, strict=False)
]


class PointCloudError(CataBotError, ValueError):
    """A stream that cannot carry a point cloud (not named sensor/<vessel>/<sensor>)."""


def sensor_frame(stream: str) -> str:
    """`sensor/<vessel>/<sensor>` -> `<vessel>/<sensor>`, the frame of the cloud."""
    parts = stream.strip("/").split("/")
    if len(parts) != 3 or parts[0] != "sensor":
        raise PointCloudError(f"{stream}: a LiDAR stream must be named sensor/<vessel>/<sensor>")
    return f"{parts[1]}/{parts[2]}"


def points(scan: LidarScan) -> np.ndarray:
    """The scan's returns as one structured array of POINT."""
    out = np.empty(len(scan.points), dtype=POINT)
    for i, axis in enumerate("xyz"):
        out[axis] = scan.points[:, i]
    out["intensity"], out["ring"] = scan.intensity, scan.ring
    out["label"], out["rain"], out["instance"] = scan.cls, scan.is_rain, scan.instance
    return out


def pointcloud_encoder(stream: str) -> typing.Callable[[Message, int], bytes]:
    """CDR encoder of the PointCloud2 of one LiDAR stream (cdr.py: the same bytes as
    mcap_ros2's dynamic serializer, without walking the definition per message)."""
    encode_cloud = pointcloud2_encoder(sensor_frame(stream), FIELDS, POINT.itemsize)

    def encode(msg: Message, stamp_ns: int) -> bytes:
        assert isinstance(msg, LidarScan)
        cloud = points(msg)
        return encode_cloud(cloud, len(cloud), stamp_ns)

    return encode
