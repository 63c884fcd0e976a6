"""Where every message of a `run.mcap` lies, found in one pass over the records.

Reading a recorded run back (replay into the viewer, dataset export, plots) needs a few
channels out of hundreds: a 100-boat run has an Odometry channel per boat and a `/tf`
message a tick, 680 000 records a simulated minute. `mcap`'s readers build a Python record
object per message (≈17 us each); here the records are walked with one `struct` call each
and only offsets are kept, so a channel's payloads can be sliced (or gathered with NumPy)
straight from the file's bytes. Uncompressed chunks (`recording.mcap_compression: none`)
and unchunked files are walked in place in the memory-mapped file; compressed chunks are
decompressed once into a memory-mapped temporary file (disk the size of the decompressed
data, not memory). A finished chunked file is indexed from its summary and the message
index records after each chunk (one NumPy array per chunk and channel, no record walked); a
file without them (unchunked, or a killed writer's) is walked to its last complete record.
"""

from __future__ import annotations

import mmap
import struct
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO

import numpy as np
from numpy.typing import NDArray

from catabot.errors import CataBotError
from catabot.run.mcap_compression import ENTRY, MAGIC, decompress

_HEAD = struct.Struct("<BQ")  # opcode, length of the record's body
_MESSAGE = struct.Struct("<HIQQ")  # channel id, sequence, log time, publish time
_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")
_FOOTER = struct.Struct("<BQQQI")  # opcode, length, summary start, summary offsets, crc
_INDEX_PAIR = struct.Struct("<HQ")  # channel id, message index record offset
OP_CHUNK_INDEX = 0x08
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
        self.finished = self.data[-len(MAGIC) :] == MAGIC  # else a killed writer's, or cut off
        self.channels: dict[str, Channel] = {}
        indexed = _from_summary(self.data, self.path)
        if indexed is not None:
            self.data, self.channels = indexed
        elif not _walk(self.data, self.channels):
            self.data, _ = _flat(self.data, self.path)
            _Walker(self.channels).walk(self.data, 0, len(self.data))

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
        groups = self.rows_by_length(chan)
        return groups[0][1] if len(groups) == 1 else None

    def rows_by_length(self, chan: Channel) -> list[tuple[NDArray[np.intp], NDArray[np.uint8]]]:
        """The payloads grouped by length: (message indices, (k, length) array) per length,
        shortest first (a /tf of every body and one of the scenario vessels alone)."""
        starts = np.asarray(chan.starts, dtype=np.int64)
        lengths = np.asarray(chan.ends, dtype=np.int64) - starts
        buffer = np.frombuffer(self.data, dtype=np.uint8)
        out = []
        for length in np.unique(lengths).tolist():
            index = np.flatnonzero(lengths == length)
            out.append((index, buffer[starts[index, None] + np.arange(length)]))
        return out


def _mapped(fileno: int) -> bytes | mmap.mmap:
    try:
        return mmap.mmap(fileno, 0, access=mmap.ACCESS_READ)
    except ValueError:  # an empty file cannot be mapped
        return b""


def _string(data: bytes | mmap.mmap, pos: int) -> tuple[str, int]:
    (n,) = _U32.unpack_from(data, pos)
    return bytes(data[pos + 4 : pos + 4 + n]).decode(), pos + 4 + n


def _walk(data: bytes | mmap.mmap, channels: dict[str, Channel]) -> bool:
    """Index a file in place: top-level records and those of uncompressed chunks, whose
    messages lie in the file as they are; False if a chunk is compressed (its messages must
    be decompressed first: `_flat`). A torn tail (a writer killed mid-record) ends the walk
    at the last complete record; the data section's end ends it too (the summary after it
    repeats schemas and channels)."""
    walker = _Walker(channels)
    try:
        walker.walk(data, len(MAGIC), len(data))
    except _Compressed:
        channels.clear()
        return False
    return True


class _Compressed(Exception):
    """A compressed chunk: the file cannot be indexed in place."""


class _Walker:
    """Schemas, channels and message offsets, from records in file order."""

    def __init__(self, channels: dict[str, Channel]) -> None:
        self.channels = channels
        self.schemas: dict[int, tuple[str, str, bytes]] = {}
        self.by_id: dict[int, Channel] = {}

    def walk(self, data: bytes | mmap.mmap, pos: int, size: int) -> None:
        """The records in data[pos:size]; a chunk's records are walked where they lie."""
        unpack_head, unpack_message = _HEAD.unpack_from, _MESSAGE.unpack_from
        while pos + _HEAD.size <= size:
            opcode, length = unpack_head(data, pos)
            body, end = pos + _HEAD.size, pos + _HEAD.size + length
            if end > size or opcode in (OP_DATA_END, OP_FOOTER):
                break
            if opcode == OP_MESSAGE:
                chan_id, _, log_time, _ = unpack_message(data, body)
                chan = self.by_id[chan_id]
                chan.stamps.append(log_time)
                chan.starts.append(body + _MESSAGE.size)
                chan.ends.append(end)
            elif opcode == OP_SCHEMA:
                self._schema(data, body)
            elif opcode == OP_CHANNEL:
                self._channel(data, body)
            elif opcode == OP_CHUNK:
                compression, records, _ = _chunk(data, body)
                if compression:
                    raise _Compressed
                self.walk(data, records, end)
            pos = end

    def _schema(self, data: bytes | mmap.mmap, body: int) -> None:
        (sid,) = _U16.unpack_from(data, body)
        name, p = _string(data, body + 2)
        encoding, p = _string(data, p)
        (n,) = _U32.unpack_from(data, p)
        self.schemas[sid] = (name, encoding, bytes(data[p + 4 : p + 4 + n]))

    def _channel(self, data: bytes | mmap.mmap, body: int) -> None:
        chan_id, sid = struct.unpack_from("<HH", data, body)
        topic, p = _string(data, body + 4)
        encoding, _ = _string(data, p)
        if chan_id in self.by_id:
            return
        name, schema_encoding, schema_data = self.schemas.get(sid, ("", "", b""))
        chan = Channel(chan_id, topic, encoding, name, schema_encoding, schema_data)
        self.by_id[chan_id] = self.channels[topic] = chan


def _chunk(data: bytes | mmap.mmap, body: int) -> tuple[str, int, int]:
    """A chunk record's compression, where its records start, and their uncompressed size."""
    (size,) = _U64.unpack_from(data, body + 16)
    compression, p = _string(data, body + 28)
    return compression, p + 8, size


def _flat(data: bytes | mmap.mmap, path: Path) -> tuple[bytes | mmap.mmap, dict[int, int]]:
    """The file's records with every chunk replaced by its records, decompressed: an
    unchunked record stream (no magic) that `_Walker` indexes in place. It goes to an
    unlinked temporary file beside the recording (its disk has held the data once) that is
    memory-mapped, so a recording of any length costs disk, not memory, as an uncompressed
    one does; the space is freed with the index. Also: where each chunk's records begin in
    it, by the chunk's offset in the file."""
    try:
        out = tempfile.TemporaryFile(dir=path.parent)  # noqa: SIM115 - mapped, then closed
    except OSError:  # a read-only folder
        out = tempfile.TemporaryFile()  # noqa: SIM115
    with out:
        bases = _decompressed(data, path, out)
        out.flush()
        return _mapped(out.fileno()), bases  # the map keeps the unlinked file's pages


def _decompressed(data: bytes | mmap.mmap, path: Path, out: BinaryIO) -> dict[int, int]:
    bases: dict[int, int] = {}
    pos, size = len(MAGIC), len(data)
    while pos + _HEAD.size <= size:
        opcode, length = _HEAD.unpack_from(data, pos)
        end = pos + _HEAD.size + length
        if end > size or opcode in (OP_DATA_END, OP_FOOTER):
            break
        if opcode == OP_CHUNK:
            compression, records, uncompressed = _chunk(data, pos + _HEAD.size)
            bases[pos] = out.tell()
            try:
                out.write(decompress(memoryview(data)[records:end], compression, uncompressed))
            except Exception as exc:  # each library raises its own error types
                raise McapIndexError(f"{path}: chunk at byte {pos} unreadable ({exc})") from None
        elif opcode in (OP_SCHEMA, OP_CHANNEL, OP_MESSAGE):
            out.write(data[pos:end])
        pos = end
    return bases


def _from_summary(
    data: bytes | mmap.mmap, path: Path
) -> tuple[bytes | mmap.mmap, dict[str, Channel]] | None:
    """Every channel from a finished chunked file's summary and the message index records
    after each chunk, without walking a record: each (chunk, channel) index is one NumPy
    array of (log time, offset). None for a file without them (unchunked, or a killed
    writer's: no summary), which `_walk` reads."""
    footer = len(data) - len(MAGIC) - _FOOTER.size
    if footer < len(MAGIC) or data[-len(MAGIC) :] != MAGIC or data[footer] != OP_FOOTER:
        return None
    _, _, start, _, _ = _FOOTER.unpack_from(data, footer)
    channels: dict[str, Channel] = {}
    walker = _Walker(channels)
    walker.walk(data, start, footer)  # schemas and channels
    chunks = list(_chunk_indexes(data, start, footer))
    if start == 0 or not chunks or not all(offsets for _, offsets in chunks):
        return None
    if any(_chunk(data, at + _HEAD.size)[0] for at, _ in chunks):
        buffer, bases = _flat(data, path)
    else:
        buffer, bases = data, {at: _chunk(data, at + _HEAD.size)[1] for at, _ in chunks}
    found: dict[int, list[tuple[NDArray[np.uint64], NDArray[np.uint64]]]] = {}
    for at, offsets in chunks:
        for chan_id, where in offsets.items():
            (length,) = _U32.unpack_from(data, where + _HEAD.size + 2)
            entries = np.frombuffer(data, ENTRY, length // ENTRY.itemsize, where + 15)
            found.setdefault(chan_id, []).append((entries["log_time"],
                                                   entries["offset"] + bases[at]))  # fmt: skip
    view = np.frombuffer(buffer, np.uint8)
    for chan_id, parts in found.items():
        times = np.concatenate([t for t, _ in parts]).astype(np.int64)
        pos = np.concatenate([o for _, o in parts]).astype(np.int64)
        order = np.lexsort((pos, times))  # time order; file order among equal times
        times, pos = times[order], pos[order]
        lengths = view[pos[:, None] + 1 + np.arange(8)].copy().view("<u8").ravel()
        chan = walker.by_id[chan_id]
        chan.stamps = times.tolist()
        chan.starts = (pos + _HEAD.size + _MESSAGE.size).tolist()
        chan.ends = (pos + _HEAD.size + lengths.astype(np.int64)).tolist()
    return buffer, channels


def _chunk_indexes(
    data: bytes | mmap.mmap, pos: int, end: int
) -> Iterator[tuple[int, dict[int, int]]]:
    """(chunk offset, {channel id: message index record offset}) of each chunk index."""
    while pos + _HEAD.size <= end:
        opcode, length = _HEAD.unpack_from(data, pos)
        if opcode == OP_CHUNK_INDEX:
            body = pos + _HEAD.size
            (chunk,) = _U64.unpack_from(data, body + 16)
            (size,) = _U32.unpack_from(data, body + 32)
            pairs = [_INDEX_PAIR.unpack_from(data, body + 36 + i) for i in range(0, size, 10)]
            yield chunk, dict(pairs)
        pos += _HEAD.size + length
