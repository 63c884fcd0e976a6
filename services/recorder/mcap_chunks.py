"""An MCAP chunk being filled: its message records, their index, and the finished bytes.

Why chunks: a reader (Foxglove, `mcap`'s indexed reader) finds a topic's messages in a time
range from the summary's chunk indexes and the message index records after each chunk, so
it reads a few chunks instead of the whole file; Foxglove refuses an unindexed file over
1 GiB. The recorder fills chunks of about `CHUNK_BYTES` (closed before a message that would
start past it, so a chunk holds at least one message); messages of `BULK_BYTES` or more
(camera images, LiDAR clouds) fill chunks of their own, so reading a small topic (a boat's
odometry) does not decompress every image recorded beside it.

Everything is arrays: a tick's messages arrive as one block, their index entries as a few
NumPy arrays, and the message index records are built per channel at close, once per chunk.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass
from typing import Any

import numpy as np
from mcap.opcode import Opcode
from mcap.records import ChunkIndex
from numpy.typing import NDArray

from catabot.run.mcap_compression import ENTRY, compress

CHUNK_BYTES = 1 << 20  # uncompressed; the `mcap` writer's default
BULK_BYTES = 1 << 16  # a message this long (an image, a cloud) goes to the bulk chunk
_CHUNK_HEAD = struct.Struct("<BQQQQI")  # opcode, length, start, end, uncompressed size, crc
_INDEX_HEAD = struct.Struct("<BQHI")  # opcode, length, channel id, bytes of entries


@dataclass(frozen=True)
class Closed:
    """A finished chunk: its record followed by its message index records (`data`), and the
    chunk index the summary lists (offsets filled in once the file position is known)."""

    data: bytes
    chunk_length: int
    index_offsets: dict[int, int]  # channel id -> message index record, from the chunk start
    start: int
    end: int
    compression: str
    compressed_size: int
    uncompressed_size: int

    def index(self, at: int) -> ChunkIndex:
        """The summary's record for this chunk written at file offset `at`."""
        return ChunkIndex(
            message_start_time=self.start,
            message_end_time=self.end,
            chunk_start_offset=at,
            chunk_length=self.chunk_length,
            message_index_offsets={c: at + o for c, o in self.index_offsets.items()},
            message_index_length=len(self.data) - self.chunk_length,
            compression=self.compression,
            compressed_size=self.compressed_size,
            uncompressed_size=self.uncompressed_size,
        )


class OpenChunk:
    """Message records gathered for one chunk, with each record's channel, time and offset."""

    def __init__(self) -> None:
        self.clear()

    def clear(self) -> None:
        self._parts: list[Any] = []
        self.size = 0  # bytes of records so far
        self._channels: list[NDArray[np.integer]] = []
        self._offsets: list[NDArray[np.int64]] = []
        self._times: list[NDArray[np.int64]] = []

    def __bool__(self) -> bool:
        return self.size > 0

    def add(self, data: Any, channels: NDArray[np.integer], lengths: NDArray[np.int64],
            log_time: int) -> None:  # fmt: skip
        """Records `data` (bytes or a list of bytes): one per channel, of `lengths` bytes."""
        ends = np.cumsum(lengths)
        self._offsets.append(self.size + ends - lengths)
        self._channels.append(channels)
        self._times.append(np.full(len(channels), log_time, np.int64))
        self._parts.extend(data) if isinstance(data, list) else self._parts.append(data)
        self.size += int(ends[-1])

    def records(self) -> bytes:
        return b"".join(self._parts)

    def provisional(self) -> bytes:
        """This chunk as it stands, uncompressed and without CRC or index: what a flush puts
        after the file's last finished chunk, so a killed recorder loses no flushed tick.
        The next flush writes over it; closing writes the real chunk in its place."""
        records = self.records()
        start, end = self._span()
        return _chunk_record(start, end, len(records), 0, "", records)

    def close(self, compression: str) -> Closed:
        """The chunk record (compressed), then one message index record per channel."""
        records = self.records()
        data = compress(records, compression)
        start, end = self._span()
        chunk = _chunk_record(start, end, len(records), zlib.crc32(records), compression, data)
        indexes, offsets = _message_indexes(
            np.concatenate(self._channels),
            np.concatenate(self._times),
            np.concatenate(self._offsets),
            len(chunk),
        )
        return Closed(chunk + indexes, len(chunk), offsets, start, end, compression, len(data),
                      len(records))  # fmt: skip

    def _span(self) -> tuple[int, int]:
        times = np.concatenate(self._times)
        return int(times.min()), int(times.max())


def _chunk_record(start: int, end: int, size: int, crc: int, compression: str,
                  data: bytes) -> bytes:  # fmt: skip
    name = compression.encode()
    length = _CHUNK_HEAD.size - 9 + 4 + len(name) + 8 + len(data)
    head = _CHUNK_HEAD.pack(Opcode.CHUNK, length, start, end, size, crc)
    return b"".join((head, struct.pack("<I", len(name)), name, struct.pack("<Q", len(data)),
                     data))  # fmt: skip


def _message_indexes(
    channels: NDArray[np.integer], times: NDArray[np.int64], offsets: NDArray[np.int64], at: int
) -> tuple[bytes, dict[int, int]]:
    """Every channel's (log time, offset) entries in time order, one record a channel (ids
    ascending); and where each record starts, counted from the chunk's start (`at` = the
    chunk record's length, where the first index record goes)."""
    order = np.lexsort((offsets, times, channels))
    entries = np.empty(len(order), ENTRY)
    entries["log_time"], entries["offset"] = times[order], offsets[order]
    ids, first, counts = np.unique(channels[order], return_index=True, return_counts=True)
    parts: list[bytes] = []
    where: dict[int, int] = {}
    for chan, i, n in zip(ids.tolist(), first.tolist(), counts.tolist(), strict=True):
        where[chan] = at
        body = entries[i : i + n].tobytes()
        parts += [_INDEX_HEAD.pack(Opcode.MESSAGE_INDEX, 6 + len(body), chan, len(body)), body]
        at += _INDEX_HEAD.size + len(body)
    return b"".join(parts), where
