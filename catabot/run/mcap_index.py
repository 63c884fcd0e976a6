"""Where every message of a `run.mcap` lies, found in one pass over the records.

Reading a recorded run back (replay into the viewer, dataset export, plots) needs a few
channels out of hundreds: a 100-boat run has an Odometry channel per boat and a `/tf`
message a tick, 680 000 records a simulated minute. `mcap`'s readers build a Python record
object per message (≈17 us each); here the records of the recorder's unchunked files are
walked with one `struct` call each and only offsets are kept, so a channel's payloads can be
sliced (or gathered with NumPy) straight from the file's bytes. Chunked files, which other
writers produce, are read through `mcap`'s own reader into the same index.
"""

from __future__ import annotations

import mmap
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mcap.reader import make_reader
from numpy.typing import NDArray

from catabot.errors import CataBotError

MAGIC = b"\x89MCAP0\r\n"
_HEAD = struct.Struct("<BQ")  # opcode, length of the record's body
_MESSAGE = struct.Struct("<HIQQ")  # channel id, sequence, log time, publish time
_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")
OP_FOOTER, OP_SCHEMA, OP_CHANNEL, OP_MESSAGE, OP_CHUNK, OP_DATA_END = (
    0x02,
    0x03,
    0x04,
    0x05,
    0x06,
    0x0F,
)


class McapIndexError(CataBotError, ValueError):
    """A file that is not MCAP, or not readable as one."""


@dataclass
class Channel:
    """One channel and where its messages are: `stamps[i]` (log time, ns) and the payload
    `data[starts[i]:ends[i]]` of the index's buffer."""

    id: int
    topic: str
    encoding: str
    schema_name: str
    schema_encoding: str
    schema_data: bytes
    stamps: list[int] = field(default_factory=list)
    starts: list[int] = field(default_factory=list)
    ends: list[int] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.stamps)


class McapIndex:
    """Every channel of one MCAP file by topic, with its messages' stamps and offsets."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        try:
            with open(self.path, "rb") as f:
                self.data: bytes | mmap.mmap = _mapped(f.fileno())
        except OSError as exc:
            raise McapIndexError(f"{self.path}: cannot read ({exc.strerror})") from None
        if self.data[: len(MAGIC)] != MAGIC:
            raise McapIndexError(f"{self.path}: not an MCAP file (no magic bytes)")
        self.channels: dict[str, Channel] = {}
        if not _walk(self.data, self.channels):
            self.data = _read_chunked(self.path, self.channels)

    def topics(self) -> list[str]:
        return sorted(self.channels)

    def channel(self, topic: str) -> Channel | None:
        return self.channels.get(topic)

    def payload(self, chan: Channel, i: int) -> bytes:
        return bytes(self.data[chan.starts[i] : chan.ends[i]])

    def payloads(self, chan: Channel) -> list[bytes]:
        return [self.payload(chan, i) for i in range(len(chan))]

    def rows(self, chan: Channel) -> NDArray[np.uint8] | None:
        """Every payload of the channel as one (messages, length) array when all have one
        length (a batch decoder then reads fields at fixed offsets); None otherwise."""
        starts = np.asarray(chan.starts, dtype=np.int64)
        lengths = np.asarray(chan.ends, dtype=np.int64) - starts
        if len(starts) == 0 or (lengths != lengths[0]).any():
            return None
        buffer = np.frombuffer(self.data, dtype=np.uint8)
        return buffer[starts[:, None] + np.arange(int(lengths[0]))]


def _mapped(fileno: int) -> bytes | mmap.mmap:
    try:
        return mmap.mmap(fileno, 0, access=mmap.ACCESS_READ)
    except ValueError:  # an empty file cannot be mapped
        return b""


def _string(data: bytes | mmap.mmap, pos: int) -> tuple[str, int]:
    (n,) = _U32.unpack_from(data, pos)
    return bytes(data[pos + 4 : pos + 4 + n]).decode(), pos + 4 + n


def _walk(data: bytes | mmap.mmap, channels: dict[str, Channel]) -> bool:
    """Index an unchunked file in place; False if it holds chunks (read those with `mcap`).
    A torn tail (a writer killed mid-record) ends the walk at the last complete record; the
    data section's end ends it too (the summary after it repeats schemas and channels)."""
    schemas: dict[int, tuple[str, str, bytes]] = {}
    by_id: dict[int, Channel] = {}
    pos, size = len(MAGIC), len(data)
    unpack_head, unpack_message = _HEAD.unpack_from, _MESSAGE.unpack_from
    while pos + _HEAD.size <= size:
        opcode, length = unpack_head(data, pos)
        body, end = pos + _HEAD.size, pos + _HEAD.size + length
        if end > size or opcode in (OP_DATA_END, OP_FOOTER):
            break
        if opcode == OP_MESSAGE:
            chan_id, _, log_time, _ = unpack_message(data, body)
            chan = by_id[chan_id]
            chan.stamps.append(log_time)
            chan.starts.append(body + _MESSAGE.size)
            chan.ends.append(end)
        elif opcode == OP_SCHEMA:
            (sid,) = _U16.unpack_from(data, body)
            name, p = _string(data, body + 2)
            encoding, p = _string(data, p)
            (n,) = _U32.unpack_from(data, p)
            schemas[sid] = (name, encoding, bytes(data[p + 4 : p + 4 + n]))
        elif opcode == OP_CHANNEL:
            chan_id, sid = struct.unpack_from("<HH", data, body)
            topic, p = _string(data, body + 4)
            encoding, _ = _string(data, p)
            if chan_id in by_id:
                pos = end
                continue
            name, schema_encoding, schema_data = schemas.get(sid, ("", "", b""))
            chan = Channel(chan_id, topic, encoding, name, schema_encoding, schema_data)
            by_id[chan_id] = channels[topic] = chan
        elif opcode == OP_CHUNK:
            channels.clear()
            return False
        pos = end
    return True


def _read_chunked(path: Path, channels: dict[str, Channel]) -> bytes:
    """A chunked file through `mcap`'s reader: payloads are copied into one buffer."""
    parts: list[bytes] = []
    offset = 0
    try:
        with open(path, "rb") as f:
            for schema, chan, message in make_reader(f).iter_messages(log_time_order=False):
                found = channels.get(chan.topic)
                if found is None:
                    name, enc, data = (schema.name, schema.encoding, schema.data) if schema else (
                        "", "", b"")  # fmt: skip
                    found = Channel(chan.id, chan.topic, chan.message_encoding, name, enc, data)
                    channels[chan.topic] = found
                found.stamps.append(message.log_time)
                found.starts.append(offset)
                offset += len(message.data)
                found.ends.append(offset)
                parts.append(message.data)
    except Exception as exc:  # mcap raises its own error types for every kind of damage
        raise McapIndexError(f"{path}: cannot read its chunks ({exc})") from None
    return b"".join(parts)
