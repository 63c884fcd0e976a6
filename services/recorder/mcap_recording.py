"""What the recorder writes to `run.mcap` and `run.extra.mcap`: every stream as the ROS 2
topics the gateway publishes (catabot/ros2/convert.py, one conversion for both), and what
has no ROS 2 type as JSON beside it.

Topics of `run.mcap` (namespaces as `ros.namespaces`, default `/<vessel id>`):
`/tf` (the scenario vessels every tick, the traffic's boats and buoys with them at
`recording.traffic_rate_hz`), `/tf_static` (base_link -> every sensor frame, once at t = 0),
`/buoys` (MarkerArray, once), `/<ns>/odom` for every vessel and traffic boat,
`/<ns>/cmd_vel` and `/<ns>/thrust` (commands and the boats' set-points), and per sensor
`/<ns>/<sensor>/imu`, `fix`, `points`, `ppi`, `image_raw`, `depth`, `segmentation`,
`instance`, `normals`, `camera_info`. `run.extra.mcap` (only when needed): each camera's
`/<ns>/<camera>/labels` (its boxes, the dataset's labels.jsonl record), each radar's polar
sweeps (`/sensor/<vessel>/<radar>`: bins, azimuths, heading; the replay reads them) and any
message a future stream sends without a ROS 2 form (`/<stream>`, JSON of the whole message).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from catabot.bus.messages import CameraFrame, Message, RadarSweep, ThrustCmd, TwistCmd
from catabot.ros2 import types
from catabot.ros2.convert import Converter
from catabot.ros2.names import TF
from services.recorder import json_schemas
from services.recorder.batches import Block
from services.recorder.dataset import instances, labels
from services.recorder.mcap_sink import McapSink

LABELS_SCHEMA = {
    "title": "catabot.CameraLabels",
    "description": "a camera frame's 2D boxes (dataset/<vessel>.<camera>/labels.jsonl)",
    "type": "object",
    "properties": {
        "tick": {"type": "integer"},
        "stamp_ns": {"type": "integer"},
        "width": {"type": "integer"},
        "height": {"type": "integer"},
        "objects": {"type": "array", "items": {"type": "object"}},
    },
}


class McapRecording:
    def __init__(self, run_dir: Path, convert: Converter, *, compression: str) -> None:
        self.convert = convert
        self.bodies = instances(convert.world)
        self.compression = compression
        self.mcap = McapSink(run_dir / "run.mcap", compression=compression)
        self._extra_path = run_dir / "run.extra.mcap"
        self._extra: McapSink | None = None
        self._started = False

    def start(self) -> None:
        """What is written once, at t = 0: the sensor mounts and the buoys."""
        if self._started:
            return
        self._started = True
        for out in (self.convert.static_tf(), self.convert.buoys()):
            if out is not None:
                self.mcap.write(out.topic, out.type, out.data, stamp_ns=0)

    def block(self, block: Block) -> None:
        self.start()
        if block.family:
            self.mcap.declare(block.family, block.typename)
        if block.tf is not None:
            self.mcap.write(TF, types.TF, block.tf, stamp_ns=block.stamp_ns)
        for rows, matrix in block.groups:
            topics = [block.topics[i] for i in rows.tolist()]
            self.mcap.write_matrix(topics, block.typename, matrix, stamp_ns=block.stamp_ns)

    def message(self, stream: str, msg: Message) -> None:
        """A sample of `stream` (`sensor/...`, `vessel/<id>/cmd/...`); ValueError if its
        conversion refuses it (wrong type for the stream)."""
        self.start()
        stamp_ns = int(getattr(msg, "stamp_ns", 0))
        if self.convert.is_sensor(stream):
            for out in self.convert.sensor(stream, msg):
                self.mcap.write(out.topic, out.type, out.data, stamp_ns=stamp_ns)
            if isinstance(msg, CameraFrame):
                self._labels(stream, msg)
            elif isinstance(msg, RadarSweep):  # PointCloud2 keeps neither the bins nor heading
                self._json(stream, msg, stamp_ns)
        elif isinstance(msg, TwistCmd | ThrustCmd) and stream.startswith("vessel/"):
            out = self.convert.command(stream.split("/")[1], msg)
            self.mcap.write(out.topic, out.type, out.data, stamp_ns=stamp_ns)
        else:
            self._json(stream, msg, stamp_ns)

    def _json(self, stream: str, msg: Message, stamp_ns: int) -> None:
        """The whole message as JSON on `/<stream>` of run.extra.mcap."""
        schema = json_schemas.json_schema(type(msg))
        data = json_schemas.encode(msg)
        self.extra().write_json("/" + stream, str(schema["title"]), schema, data,
                                stamp_ns=stamp_ns)  # fmt: skip

    def _labels(self, stream: str, frame: CameraFrame) -> None:
        record: dict[str, Any] = labels(frame, {}, bodies=self.bodies)
        record.pop("files")
        _, vessel, camera = stream.split("/")
        topic = self.convert.names.topic(vessel, camera, "labels")
        data = json.dumps(record, separators=(",", ":")).encode()
        self.extra().write_json(topic, str(LABELS_SCHEMA["title"]), LABELS_SCHEMA, data,
                                stamp_ns=frame.stamp_ns)  # fmt: skip

    def extra(self) -> McapSink:
        """run.extra.mcap, opened when the first message without a ROS 2 type comes."""
        if self._extra is None:
            self._extra = McapSink(self._extra_path, profile="", compression=self.compression)
        return self._extra

    def flush(self) -> None:
        self.mcap.flush()
        if self._extra is not None:
            self._extra.flush()

    def close(self) -> None:
        self.mcap.close()
        if self._extra is not None:
            self._extra.close()
