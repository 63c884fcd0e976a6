"""Camera frames in `run.mcap` as ROS 2 `sensor_msgs/msg/Image` (CDR), which Foxglove Studio
and `ros2 bag` show natively: one channel per output, `/sensor/<vessel>/<camera>/color`
(rgb8) and `/sensor/<vessel>/<camera>/depth` (32FC1, metres, inf where nothing was hit).
Segmentation and normals go to the labelled dataset (dataset.py), not to the MCAP: a viewer
needs the picture and the depth, a trainer the labels.
"""

from __future__ import annotations

import typing

import numpy as np
from mcap_ros2._dynamic import serialize_dynamic

from catabot.bus.messages import CameraFrame, Message
from services.recorder.ros2_msgdefs import HEADER_DEPENDENCIES, concatenated, stamp

IMAGE = "sensor_msgs/msg/Image"
_IMAGE_TEXT = """\
std_msgs/Header header
uint32 height
uint32 width
string encoding
uint8 is_bigendian
uint32 step
uint8[] data
"""
IMAGE_MSGDEF = concatenated(_IMAGE_TEXT, {**HEADER_DEPENDENCIES})
ENCODINGS = {"color": "rgb8", "depth": "32FC1"}


def outputs(frame: CameraFrame) -> list[str]:
    """The MCAP sub-channels this frame has data for ('color', 'depth')."""
    return [name for name in ENCODINGS if getattr(frame, name).size]


def _split(stream: str) -> tuple[str, str]:
    """`sensor/<vessel>/<camera>/<output>` -> (`<vessel>/<camera>` optical frame, output)."""
    parts = stream.strip("/").split("/")
    if len(parts) != 4 or parts[0] != "sensor" or parts[3] not in ENCODINGS:
        raise ValueError(f"{stream}: an image channel is sensor/<vessel>/<camera>/color|depth")
    return f"{parts[1]}/{parts[2]}", parts[3]


def image_encoder(stream: str) -> typing.Callable[[Message, int], bytes]:
    """CDR encoder of one output of one camera stream."""
    frame_id, output = _split(stream)
    serialize = serialize_dynamic(IMAGE, IMAGE_MSGDEF)[IMAGE]

    def encode(msg: Message, stamp_ns: int) -> bytes:
        assert isinstance(msg, CameraFrame)
        pixels = np.ascontiguousarray(getattr(msg, output))
        if output == "depth":
            pixels = pixels.astype("<f4", copy=False)
        height, width = pixels.shape[:2]
        return bytes(
            serialize(
                {
                    "header": {"stamp": stamp(stamp_ns), "frame_id": frame_id},
                    "height": height,
                    "width": width,
                    "encoding": ENCODINGS[output],
                    "is_bigendian": 0,
                    "step": pixels.nbytes // max(height, 1),
                    "data": pixels.tobytes(),
                }
            )
        )

    return encode
