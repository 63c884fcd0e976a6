"""`run.mcap`: every stream as an MCAP channel (DESIGN.md §7).

States are ROS 2 `nav_msgs/msg/Odometry`, LiDAR scans `sensor_msgs/msg/PointCloud2` (CDR); other
messages are JSON with a JSON Schema from their dataclass, so Foxglove Studio opens every channel.

Why it is written this way:
- Unchunked records, and bytes reach the file only in `flush()` (once per tick): a recorder
  killed at any moment leaves a file whose records are all complete up to the last tick,
  which `mcap_read.read_mcap_messages` reads without the summary that only `close()` writes.
- log time = publish time = `stamp_ns` and a per-channel sequence number: nothing in the file
  comes from the wall clock or a random source, so two identical runs give identical bytes.
"""

from __future__ import annotations

import io
import json
import struct
import typing
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
from mcap.well_known import MessageEncoding, SchemaEncoding
from mcap.writer import LIBRARY_IDENTIFIER
from numpy.typing import NDArray

from catabot.bus.messages import CameraFrame, LidarScan, Message, VesselState
from services.recorder import cdr, images, json_schemas, pointcloud, ros2_msgdefs
from services.recorder.csv_sink import RecorderError, write_whole
from services.recorder.mcap_writer import McapWriter

_ROS2 = {  # messages written as ROS 2 types: (type name, msgdef)
    VesselState: (ros2_msgdefs.ODOMETRY, ros2_msgdefs.ODOMETRY_MSGDEF),
    LidarScan: (pointcloud.POINTCLOUD2, pointcloud.POINTCLOUD2_MSGDEF),
    CameraFrame: (images.IMAGE, images.IMAGE_MSGDEF),  # one channel per output: images.py
}


class _TickBuffer(io.BufferedIOBase):
    """A write-only file whose bytes reach the disk only on flush (tick-atomic records); a
    flush that fails (a full disk) is cut back off, so the file ends with a whole record."""

    def __init__(self, path: Path) -> None:
        super().__init__()
        self._file = open(path, "wb", buffering=0)  # noqa: SIM115
        self._pending = bytearray()
        self._size = 0  # bytes of complete flushes

    def writable(self) -> bool:
        return True

    def write(self, data: Any) -> int:
        self._pending += data
        return len(data)

    def tell(self) -> int:
        return self._size + len(self._pending)

    def flush(self) -> None:
        if self._file.closed or not self._pending:
            return  # IOBase.close() flushes once more after our file is closed
        data = bytes(self._pending)
        self._pending.clear()
        write_whole(self._file, data, self._size)
        self._size += len(data)

    def close(self) -> None:
        if not self._file.closed:
            self.flush()
            self._file.close()
        super().close()


@dataclass
class _Channel:
    """A registered channel and how its messages become bytes (its sequence numbers are the
    writer's message counts: `McapWriter.written`)."""

    id: int
    cls: type[Message]
    encode: typing.Callable[[Message, int], bytes]


class McapSink:
    """Writes every stream to one MCAP file; `flush()` once per tick, `close()` at the end."""

    def __init__(self, path: Path) -> None:
        self._out = _TickBuffer(Path(path))
        # profile "": channels mix CDR and JSON. The file is valid from the first byte on.
        self._writer = McapWriter(
            typing.cast(BinaryIO, self._out), profile="", library=f"catabot {LIBRARY_IDENTIFIER}"
        )
        self._out.flush()
        self._schemas: dict[type[Message] | str, int] = {}  # by message class or ROS 2 type
        self._channels: dict[str, _Channel] = {}
        self._groups: dict[tuple[tuple[str, ...], type[Message]], NDArray[np.uint16]] = {}
        self._closed = False

    def write(self, stream: str, msg: Message, *, stamp_ns: int) -> None:
        """Add one message to channel `/<stream>`, stamped with simulated time."""
        chan = self._channel(stream, type(msg))
        try:
            data = chan.encode(msg, stamp_ns)
        except (ValueError, TypeError, IndexError, struct.error) as exc:
            raise RecorderError(f"{stream}: cannot encode {type(msg).__name__}: {exc}") from exc
        self._add([chan.id], stamp_ns, [data])

    def write_block(
        self,
        streams: Sequence[str],
        cls: type[Message],
        payloads: Sequence[bytes],
        *,
        stamp_ns: int,
    ) -> None:
        """`payloads[i]`, already encoded as the channel of `cls` expects, on `streams[i]`:
        the batch path (`services/recorder/batches.py`), one write for a whole tick."""
        if not streams:
            return
        ids = self._group(streams, cls)
        sequences = self._next_sequences(ids).tolist()
        self._writer.add_messages(ids.tolist(), sequences, stamp_ns, payloads)

    def write_matrix(
        self, streams: Sequence[str], cls: type[Message], payloads: Any, *, stamp_ns: int
    ) -> None:
        """`payloads` (k, L) bytes, row i on `streams[i]`: equal-length payloads (Odometry
        of bodies with equally long ids) go into the file as one block."""
        if not streams:
            return
        ids = self._group(streams, cls)
        self._writer.add_block(ids, self._next_sequences(ids), stamp_ns, payloads)

    def _group(self, streams: Sequence[str], cls: type[Message]) -> NDArray[np.uint16]:
        """The channel ids of `streams`, looked up once: a batch names the same streams every
        tick (per-stream work in every tick was a loop over 100 boats)."""
        if self._closed:
            raise RecorderError(f"{streams[0]}: the MCAP sink is closed")
        group = (tuple(streams), cls)
        ids = self._groups.get(group)
        if ids is None:
            if len(set(streams)) != len(streams):
                raise RecorderError(f"a stream appears twice in one block: {list(streams)}")
            ids = np.array([self._channel(stream, cls).id for stream in streams], np.uint16)
            self._groups[group] = ids
        return ids

    def _next_sequences(self, ids: NDArray[np.uint16]) -> NDArray[np.int64]:
        """Each channel's next sequence number (ids are distinct): its messages so far."""
        return self._writer.written(ids)

    def _add(self, ids: list[int], stamp_ns: int, payloads: list[bytes]) -> None:
        sequences = self._next_sequences(np.array(ids, np.uint16))
        self._writer.add_messages(ids, sequences.tolist(), stamp_ns, payloads)

    def write_ros2(
        self, stream: str, type_name: str, msgdef: str, data: bytes, *, stamp_ns: int
    ) -> None:
        """A message already in CDR, of a ROS 2 type no bus message maps to (`/tf`)."""
        if self._closed:
            raise RecorderError(f"{stream}: the MCAP sink is closed")
        chan = self._channels.get(stream)
        if chan is None:
            if type_name not in self._schemas:
                sid = self._writer.register_schema(type_name, SchemaEncoding.ROS2, msgdef.encode())
                self._schemas[type_name] = sid
            topic = "/" + stream.strip("/")
            cid = self._writer.register_channel(
                topic, MessageEncoding.CDR, self._schemas[type_name]
            )
            chan = self._channels[stream] = _Channel(cid, _Encoded, _already_encoded)
        elif chan.cls is not _Encoded:
            raise RecorderError(f"{stream}: a {type_name} on a channel of {chan.cls.__name__}")
        self._add([chan.id], stamp_ns, [data])

    def _channel(self, stream: str, cls: type[Message]) -> _Channel:
        if self._closed:
            raise RecorderError(f"{stream}: the MCAP sink is closed")
        chan = self._channels.get(stream) or self._register(stream, cls)
        if cls is not chan.cls:
            raise RecorderError(
                f"{stream}: a {cls.__name__} sample on a channel of {chan.cls.__name__}; "
                "not written"
            )
        return chan

    def _register(self, stream: str, cls: type[Message]) -> _Channel:
        if cls is VesselState:
            encoding, encode = MessageEncoding.CDR, _odometry_encoder(_vessel_of(stream))
        elif cls is LidarScan:
            encoding, encode = MessageEncoding.CDR, pointcloud.pointcloud_encoder(stream)
        elif cls is CameraFrame:
            encoding, encode = MessageEncoding.CDR, images.image_encoder(stream)
        else:
            encoding, encode = MessageEncoding.JSON, _json_encoder
        topic = "/" + stream.strip("/")
        channel_id = self._writer.register_channel(topic, encoding, self._schema(cls))
        chan = _Channel(channel_id, cls, encode)
        self._channels[stream] = chan
        return chan

    def _schema(self, cls: type[Message]) -> int:
        if cls not in self._schemas:
            if cls in _ROS2:
                name, msgdef = _ROS2[cls]
                sid = self._writer.register_schema(name, SchemaEncoding.ROS2, msgdef.encode())
            else:
                text = json.dumps(json_schemas.json_schema(cls), separators=(",", ":")).encode()
                sid = self._writer.register_schema(
                    json_schemas.schema_name(cls), SchemaEncoding.JSONSchema, text
                )
            self._schemas[cls] = sid
        return self._schemas[cls]

    def flush(self) -> None:
        """Put every record written so far into the file (call once per tick)."""
        # Unchunked, the writer hands each record to our buffer at once, so flushing the
        # buffer is enough.
        if not self._closed:
            self._out.flush()

    def close(self) -> None:
        """Write the summary and footer, then close the file."""
        if self._closed:
            return
        self._writer.finish()
        self._out.close()
        self._closed = True

    def __enter__(self) -> McapSink:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _vessel_of(stream: str) -> str:
    """`vessel/<id>/state` -> `<id>`, the Odometry child frame (the body frame)."""
    parts = stream.strip("/").split("/")
    if len(parts) == 3 and parts[0] == "vessel" and parts[2] == "state":
        return parts[1]
    raise RecorderError(f"{stream}: a VesselState stream must be named vessel/<id>/state")


def _odometry_encoder(vessel: str) -> typing.Callable[[Message, int], bytes]:
    """CDR encoder of one vessel's Odometry (mcap_ros2's writer always chunks, so we write
    our own unchunked records; cdr.py packs the same bytes as mcap_ros2's dynamic serializer
    at a fraction of its cost per message)."""
    odometry = cdr.odometry_encoder(ros2_msgdefs.WORLD_FRAME, vessel)

    def encode(msg: Message, stamp_ns: int) -> bytes:
        assert isinstance(msg, VesselState)
        return odometry(msg, stamp_ns)

    return encode


class _Encoded(Message):
    """Marks a channel fed with bytes already in its encoding (`write_ros2`)."""


def _already_encoded(msg: Message, stamp_ns: int) -> bytes:
    raise RecorderError("this channel takes bytes already encoded (McapSink.write_ros2)")


def _json_encoder(msg: Message, stamp_ns: int) -> bytes:
    return json_schemas.encode(msg)
