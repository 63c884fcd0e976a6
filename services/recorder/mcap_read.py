"""Reading `run.mcap` back, also when its writer was killed: every complete record, decoded.

The recorder's own check of what it wrote (tests, `catabot view`), independent of the
writer: the `mcap` package's stream reader, bounded to the last complete record.
"""

from __future__ import annotations

import io
import json
import struct
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO

from mcap.exceptions import EndOfFile
from mcap.opcode import Opcode
from mcap.records import Channel, Schema
from mcap.records import Message as McapMessage
from mcap.stream_reader import MAGIC_SIZE, StreamReader
from mcap.well_known import MessageEncoding
from mcap_ros2.decoder import DecoderFactory

_RECORD_HEAD = struct.Struct("<BQ")  # opcode, length of the record body


@dataclass(frozen=True)
class ReadMessage:
    """One message read back: `decoded` is a dict (JSON) or a ROS 2 message object (CDR)."""

    topic: str
    schema_name: str
    log_time: int
    publish_time: int
    sequence: int
    data: bytes
    decoded: Any


class _Bounded(io.RawIOBase):
    """The first `limit` bytes of a file, so the stream reader never sees a torn record."""

    def __init__(self, f: BinaryIO, limit: int) -> None:
        super().__init__()
        self._f, self._left = f, limit

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: Any) -> int:
        view = memoryview(buffer).cast("B")[: self._left]
        n = self._f.readinto(view)  # type: ignore[attr-defined]
        self._left -= n
        return n


def _complete_length(f: BinaryIO) -> int:
    """Bytes up to the end of the last complete record (a killed writer leaves a torn tail)."""
    size = f.seek(0, io.SEEK_END)
    pos = MAGIC_SIZE
    while pos + _RECORD_HEAD.size <= size:
        f.seek(pos)
        opcode, length = _RECORD_HEAD.unpack(f.read(_RECORD_HEAD.size))
        end = pos + _RECORD_HEAD.size + length
        if end > size:
            break
        pos = end
        if opcode == Opcode.FOOTER:
            return min(size, pos + MAGIC_SIZE)
    return min(pos, size)


def _records(path: Path) -> Iterator[Any]:
    """Every complete record of the file, in file order; stops quietly at a torn tail."""
    with open(path, "rb") as f:
        limit = _complete_length(f)
        if limit < MAGIC_SIZE:
            return  # killed before anything reached the file
        f.seek(0)
        try:
            yield from StreamReader(_Bounded(f, limit)).records
        except EndOfFile:
            return  # no footer: the writer did not close; every complete record was read


def read_mcap_messages(path: Path) -> list[ReadMessage]:
    """Every message of an MCAP file in file order, decoded; tolerates a truncated tail.

    Works on a finished file and on one whose writer was killed before `close()`: messages
    up to the last complete record are returned (with `McapSink`, the last flushed tick).
    """
    ros2 = DecoderFactory()
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    out: list[ReadMessage] = []
    for record in _records(Path(path)):
        if isinstance(record, Schema):
            schemas[record.id] = record
        elif isinstance(record, Channel):
            channels[record.id] = record
        elif isinstance(record, McapMessage):
            chan = channels[record.channel_id]
            schema = schemas.get(chan.schema_id)
            out.append(_decoded(record, chan, schema, ros2))
    return out


def _decoded(
    record: McapMessage, chan: Channel, schema: Schema | None, ros2: DecoderFactory
) -> ReadMessage:
    if chan.message_encoding == MessageEncoding.JSON:
        decoded: Any = json.loads(record.data)
    else:
        decoder = ros2.decoder_for(chan.message_encoding, schema)
        decoded = decoder(record.data) if decoder else None
    return ReadMessage(
        topic=chan.topic,
        schema_name=schema.name if schema else "",
        log_time=record.log_time,
        publish_time=record.publish_time,
        sequence=record.sequence,
        data=bytes(record.data),
        decoded=decoded,
    )
