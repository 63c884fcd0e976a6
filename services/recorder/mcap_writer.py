"""A chunked, indexed MCAP writer that packs many messages in one call.

Why not `mcap.writer.Writer.add_message`: it builds each Message record field by field
through a `BytesIO` (~20 us a message), which with 100 boats (an Odometry and a twist
command each, every tick) was most of the recorder's time. Here a tick's messages become
bytes with one `struct` call each (or one NumPy fill for a block) and go into an open chunk
(mcap_chunks.py); a full chunk reaches the output compressed, followed by its message
index records. `finish()` writes the summary: schemas, channels, metadata and chunk indexes,
statistics and their offsets, so readers seek instead of scanning (DESIGN.md §7). Schema and channel
records go to the output at once, outside chunks, so they precede every chunk using them.
Other records are serialised by `mcap.records`; CRCs are computed as `mcap`'s writer does.

Chunks close on size alone, so the same messages give the same chunks and the same bytes.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Sequence
from typing import Any, BinaryIO

import numpy as np
from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import (
    Channel,
    ChunkIndex,
    DataEnd,
    Footer,
    Header,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
    SummaryOffset,
)  # fmt: skip
from numpy.typing import NDArray

from catabot.run.mcap_compression import COMPRESSIONS, MAGIC
from services.recorder.mcap_chunks import BULK_BYTES, CHUNK_BYTES, OpenChunk

# opcode, record length, channel id, sequence, log time, publish time; then the data
_MESSAGE_HEAD = struct.Struct("<BQHIQQ")
_MESSAGE_FIXED = _MESSAGE_HEAD.size - 9  # the record length counts what follows it
_HEAD_DTYPE = np.dtype(  # the same head as a packed NumPy record, for whole blocks
    [("opcode", "u1"), ("length", "<u8"), ("channel", "<u2"), ("sequence", "<u4"),
     ("log_time", "<u8"), ("publish_time", "<u8")]
)  # fmt: skip


class McapWriter:
    """Writes to `stream` (bytes reach the disk when the caller flushes it); `compression`
    "none", "zstd" or "lz4" for every chunk, chunks of about `chunk_bytes` uncompressed."""

    def __init__(
        self, stream: BinaryIO, *, profile: str, library: str, compression: str = "zstd",
        chunk_bytes: int = CHUNK_BYTES,
    ) -> None:  # fmt: skip
        if compression not in COMPRESSIONS:
            raise ValueError(f"compression {compression!r}; allowed: {', '.join(COMPRESSIONS)}")
        self._stream = stream
        self._compression = COMPRESSIONS[compression]
        self._chunk_bytes = chunk_bytes
        self._open = (OpenChunk(), OpenChunk())  # small messages, bulk (>= BULK_BYTES)
        self._times = [-1, -1]  # the log time each of them took last
        self._chunk_indexes: list[ChunkIndex] = []
        self._crc = 0
        self._schemas: list[Schema] = []
        self._channels: list[Channel] = []
        self._metadata: list[MetadataIndex] = []
        self._counts = np.zeros(1, np.int64)  # messages by channel id (ids start at 1)
        self._first = self._last = -1
        self._messages = 0
        self._write(MAGIC)
        self._record(Header(profile=profile, library=library))

    def register_schema(self, name: str, encoding: str, data: bytes) -> int:
        schema = Schema(id=len(self._schemas) + 1, name=name, encoding=encoding, data=data)
        self._schemas.append(schema)
        self._record(schema)
        return schema.id

    def register_channel(
        self, topic: str, message_encoding: str, schema_id: int, *, metadata: dict[str, str]
    ) -> int:
        channel = Channel(
            id=len(self._channels) + 1,
            topic=topic,
            message_encoding=message_encoding,
            schema_id=schema_id,
            metadata=metadata,
        )
        self._channels.append(channel)
        self._counts = np.append(self._counts, 0)
        self._record(channel)
        return channel.id

    def add_metadata(self, name: str, metadata: dict[str, str]) -> None:
        """A Metadata record, indexed in the summary (readers find it there)."""
        offset = self._stream.tell()
        builder = RecordBuilder()
        Metadata(name=name, metadata=metadata).write(builder)
        data = builder.end()
        self._write(data)
        self._metadata.append(MetadataIndex(offset=offset, length=len(data), name=name))

    def add_messages(
        self,
        channels: Sequence[int],
        sequences: Sequence[int],
        log_time: int,
        payloads: Sequence[bytes],
    ) -> None:
        """Message i on `channels[i]` with `sequences[i]`; one log (= publish) time for all."""
        if not len(channels) == len(sequences) == len(payloads):
            raise ValueError(
                f"{len(channels)} channels, {len(sequences)} sequences and {len(payloads)} "
                "payloads: one of each per message"
            )
        if not payloads:
            return
        ids = np.asarray(channels)
        self._count(ids)
        pack = _MESSAGE_HEAD.pack
        parts: list[Any] = []
        for chan, seq, data in zip(channels, sequences, payloads, strict=True):
            parts.append(pack(Opcode.MESSAGE, _MESSAGE_FIXED + len(data), chan, seq,
                              log_time, log_time))  # fmt: skip
            parts.append(data)
        lengths = np.fromiter(map(len, payloads), np.int64, len(payloads))
        self._note_times(log_time, len(payloads))
        chunk = self._chunk(int(lengths.max()), log_time)
        chunk.add(parts, ids, lengths + _MESSAGE_HEAD.size, log_time)

    def written(self, channels: NDArray[np.integer]) -> NDArray[np.int64]:
        """Messages written so far on each of `channels`: the sequence numbers their next
        messages take when, as in `McapSink`, every channel counts from 0 in steps of 1."""
        return self._counts[channels]

    def _count(self, channels: NDArray[np.integer]) -> None:
        """One more message on each of `channels` (ids may repeat); unknown ids refused
        before anything is counted or written."""
        unknown = channels[(channels < 1) | (channels >= len(self._counts))]
        if len(unknown):
            raise ValueError(f"no channel registered with id(s) {sorted(set(unknown.tolist()))}")
        np.add.at(self._counts, channels, 1)

    def _note_times(self, log_time: int, count: int) -> None:
        self._first = log_time if self._messages == 0 else min(self._first, log_time)
        self._last = max(self._last, log_time)
        self._messages += count

    def add_block(
        self, channels: NDArray[np.integer], sequences: NDArray[np.integer], log_time: int,
        payloads: NDArray[np.uint8],
    ) -> None:  # fmt: skip
        """k messages of one length at once, `payloads` (k, L) bytes: every record head is
        filled by NumPy and the block reaches the output in one write (no per-message work)."""
        k, length = payloads.shape
        if len(channels) != k or len(sequences) != k:
            raise ValueError(f"{len(channels)} channels and {len(sequences)} sequences for {k}")
        if k == 0:
            return
        self._count(channels)
        head = np.empty(k, _HEAD_DTYPE)
        head["opcode"], head["length"] = Opcode.MESSAGE, _MESSAGE_FIXED + length
        head["channel"], head["sequence"] = channels, sequences
        head["log_time"] = head["publish_time"] = log_time
        records = np.empty((k, _MESSAGE_HEAD.size + length), np.uint8)
        records[:, : _MESSAGE_HEAD.size] = head.view(np.uint8).reshape(k, -1)
        records[:, _MESSAGE_HEAD.size :] = payloads
        self._note_times(log_time, k)
        chunk = self._chunk(length, log_time)
        chunk.add(records.tobytes(), channels, np.full(k, records.shape[1], np.int64), log_time)

    def _chunk(self, longest: int, log_time: int) -> OpenChunk:
        """The open chunk for messages up to `longest` bytes, written out first if full, and
        only before a message of another log time: the messages of one time stay in one
        chunk however they come in blocks (the traffic's set-points in one block or in one a
        shard: `run.mcap`'s bytes differed with `traffic.shards`)."""
        kind = int(longest >= BULK_BYTES)
        chunk = self._open[kind]
        if chunk.size >= self._chunk_bytes and log_time != self._times[kind]:
            self._close(chunk)
        self._times[kind] = log_time
        return chunk

    def _close(self, chunk: OpenChunk) -> None:
        closed = chunk.close(self._compression)
        self._chunk_indexes.append(closed.index(self._stream.tell()))
        self._write(closed.data)
        chunk.clear()

    def tail(self) -> bytes:
        """The open chunks as provisional records (`OpenChunk.provisional`): the caller
        puts them after what was written, and writes over them at its next flush."""
        return b"".join(c.provisional() for c in self._open if c)

    def finish(self) -> None:
        """The open chunks, DataEnd, the summary (schemas, channels, chunk indexes,
        statistics, offsets) and the footer."""
        for chunk in self._open:
            if chunk:
                self._close(chunk)
        self._record(DataEnd(data_section_crc=self._crc))
        start = self._stream.tell()
        summary = RecordBuilder()
        offsets: list[SummaryOffset] = []
        for opcode, records in (
            (Opcode.SCHEMA, self._schemas),
            (Opcode.CHANNEL, self._channels),
            (Opcode.METADATA_INDEX, self._metadata),
            (Opcode.CHUNK_INDEX, self._chunk_indexes),
            (Opcode.STATISTICS, [self._statistics()]),
        ):
            if not records:
                continue
            group = summary.count
            for record in records:
                record.write(summary)
            offsets.append(SummaryOffset(opcode, start + group, summary.count - group))
        offset_start = start + summary.count
        for offset in offsets:
            offset.write(summary)
        data = summary.end()
        head = struct.pack("<BQQQ", Opcode.FOOTER, 20, start, offset_start)
        crc = zlib.crc32(head, zlib.crc32(data))
        self._stream.write(data)
        builder = RecordBuilder()
        Footer(summary_start=start, summary_offset_start=offset_start, summary_crc=crc).write(
            builder
        )
        self._stream.write(builder.end() + MAGIC)

    def _statistics(self) -> Statistics:
        return Statistics(
            message_count=self._messages,
            schema_count=len(self._schemas),
            channel_count=len(self._channels),
            attachment_count=0,
            metadata_count=len(self._metadata),
            chunk_count=len(self._chunk_indexes),
            message_start_time=max(self._first, 0),
            message_end_time=max(self._last, 0),
            channel_message_counts={c.id: int(self._counts[c.id]) for c in self._channels},
        )

    def _record(self, record: Any) -> None:
        builder = RecordBuilder()
        record.write(builder)
        self._write(builder.end())

    def _write(self, data: bytes) -> None:
        self._crc = zlib.crc32(data, self._crc)
        self._stream.write(data)
