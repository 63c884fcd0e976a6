"""`run.mcap` (ROS 2 only) and `run.extra.mcap` (the rest, JSON) (DESIGN.md §7).

`run.mcap` has the `ros2` profile and only CDR channels with `ros2msg` schemas from
rosbags' Jazzy store (catabot/ros2/types.py), so rosbags' `AnyReader`, `ros2 bag` and
Foxglove read it as a ROS 2 bag, each channel with the QoS the gateway offers on its topic
(catabot/ros2/bag.py: `ros2 bag play` offers them again). What has no ROS 2 type (camera
boxes and labels, or any future message without a conversion) goes to `run.extra.mcap`:
JSON with a JSON Schema.

Why it is written this way:
- Chunked and indexed (mcap_writer.py), compressed as `recording.mcap_compression` says, so
  Foxglove and `mcap`'s reader open a recording of any length by its summary.
- Bytes reach the file only in `flush()` (whole ticks): the finished chunks, then the open
  chunks as provisional uncompressed chunk records that the next flush writes over. A
  recorder killed at any moment leaves a file of complete records up to its last flush,
  which `mcap_read.read_mcap_messages` reads without the summary that only `close()` writes;
  a flush that fails (a full disk) is cut back to the last complete record.
- log time = publish time = `stamp_ns` and a per-channel sequence number: nothing in the file
  comes from the wall clock or a random source, so two identical runs give identical bytes.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import typing
from collections.abc import Sequence
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
from mcap.well_known import MessageEncoding, SchemaEncoding
from mcap.writer import LIBRARY_IDENTIFIER
from numpy.typing import NDArray

from catabot.ros2 import bag, types
from catabot.ros2.bag import offered_qos_profiles
from catabot.ros2.wire import topic_qos
from services.recorder.csv_sink import DiskError, RecorderError, write_whole
from services.recorder.mcap_chunks import CHUNK_BYTES
from services.recorder.mcap_writer import McapWriter

ROS2 = "ros2"  # the profile of run.mcap
DEFAULT_COMPRESSION = "zstd"  # `recording.mcap_compression`'s default (README, Performance)


class _TickBuffer(io.BufferedIOBase):
    """A write-only file whose bytes reach the disk only on flush (tick-atomic records), each
    flush followed by a provisional `tail` that the next one replaces; a flush that fails
    (a full disk) is cut back off, so the file ends with a whole record."""

    def __init__(self, path: Path) -> None:
        super().__init__()
        self._file = open(path, "wb", buffering=0)  # noqa: SIM115
        self._pending = bytearray()
        self._size = 0  # bytes of complete flushes
        self._tail = b""  # the provisional bytes on disk after them

    def writable(self) -> bool:
        return True

    def write(self, data: Any) -> int:
        self._pending += data
        return len(data)

    def tell(self) -> int:
        return self._size + len(self._pending)

    def flush(self, tail: bytes = b"") -> None:
        if self._file.closed or (not self._pending and tail == self._tail):
            return  # IOBase.close() flushes once more after our file is closed
        data = bytes(self._pending) + tail
        self._pending.clear()
        before, self._tail = self._tail, b""  # a failed write cuts the file back to _size
        self._file.seek(self._size)
        try:
            write_whole(self._file, data, self._size)
        except DiskError:
            self._restore(before)  # the last flush's open chunks were on disk: keep them
            raise
        self._size += len(data) - len(tail)
        if len(tail) < len(before):
            os.ftruncate(self._file.fileno(), self._size + len(tail))  # a longer tail before
        self._tail = tail

    def _restore(self, tail: bytes) -> None:
        """Put the previous provisional tail back after a failed flush (the space it took
        was just freed), so the file keeps every tick flushed before the disk filled."""
        with contextlib.suppress(DiskError):  # nothing written: the file ends at _size
            write_whole(self._file, tail, self._size)
            self._tail = tail

    def close(self) -> None:
        if not self._file.closed:
            self.flush(self._tail)  # the tail stays unless replaced (garbage collection)
            self._file.close()
        super().close()


class McapSink:
    """Writes one MCAP file: `flush()` once per tick, `close()` at the end. With the `ros2`
    profile every channel is CDR of a ROS 2 type; without a profile (`run.extra.mcap`) JSON."""

    def __init__(
        self, path: Path, *, profile: str = ROS2, compression: str = DEFAULT_COMPRESSION,
        chunk_bytes: int = CHUNK_BYTES,
    ) -> None:  # fmt: skip
        self.profile = profile
        self._out = _TickBuffer(Path(path))
        self._writer = McapWriter(
            typing.cast(BinaryIO, self._out),
            profile=profile,
            library=f"catabot {LIBRARY_IDENTIFIER}",
            compression=compression,
            chunk_bytes=chunk_bytes,
        )
        if profile == ROS2:  # what `ros2 bag play` needs to offer the gateway's QoS
            self._writer.add_metadata(bag.METADATA_NAME, bag.METADATA)
        self._out.flush()  # the file is valid from the first byte on
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, tuple[int, str]] = {}  # topic -> (channel id, schema name)
        self._groups: dict[tuple[tuple[str, ...], str], NDArray[np.uint16]] = {}
        self._closed = False

    def write(self, topic: str, typename: str, data: bytes, *, stamp_ns: int) -> None:
        """One CDR message of `typename` on `topic`, stamped with simulated time."""
        self._add([self._ros2(topic, typename)], stamp_ns, [data])

    def write_block(
        self, topics: Sequence[str], typename: str, payloads: Sequence[bytes], *, stamp_ns: int
    ) -> None:
        """`payloads[i]` on `topics[i]`, one write for a whole tick."""
        if topics:
            ids = self._group(topics, typename)
            self._writer.add_messages(
                ids.tolist(), self._sequences(ids).tolist(), stamp_ns, payloads
            )

    def write_matrix(
        self, topics: Sequence[str], typename: str, payloads: Any, *, stamp_ns: int
    ) -> None:
        """`payloads` (k, L) bytes, row i on `topics[i]`: equal-length payloads (Odometry of
        bodies with equally long frame ids, Twists) go into the file as one block."""
        if topics:
            ids = self._group(topics, typename)
            self._writer.add_block(ids, self._sequences(ids), stamp_ns, payloads)

    def declare(self, topics: Sequence[str], typename: str) -> None:
        """Channels for `topics`, in their order, before any of them is written: a batch
        split in blocks (traffic shards) then registers them as the whole batch would."""
        if topics:
            self._group(topics, typename)

    def write_json(
        self, topic: str, schema_name: str, schema: dict[str, Any], data: bytes, *, stamp_ns: int
    ) -> None:
        """A JSON message with its JSON Schema (the extras file only)."""
        if self.profile == ROS2:
            raise RecorderError(f"{topic}: JSON has no place in a ros2 MCAP (run.extra.mcap)")
        chan = self._channels.get(topic)
        if chan is None:
            text = json.dumps(schema, separators=(",", ":")).encode()
            sid = self._schema(schema_name, SchemaEncoding.JSONSchema, text)
            chan = self._register(topic, MessageEncoding.JSON, sid, schema_name)
        self._check(topic, chan, schema_name)
        self._add([chan[0]], stamp_ns, [data])

    def _ros2(self, topic: str, typename: str) -> int:
        if self.profile != ROS2:
            raise RecorderError(f"{topic}: CDR belongs in run.mcap")
        chan = self._channels.get(topic)
        if chan is None:
            sid = self._schema(typename, SchemaEncoding.ROS2, types.msgdef(typename).encode())
            chan = self._register(topic, MessageEncoding.CDR, sid, typename)
        self._check(topic, chan, typename)
        return chan[0]

    def _schema(self, name: str, encoding: str, data: bytes) -> int:
        if name not in self._schemas:
            self._schemas[name] = self._writer.register_schema(name, encoding, data)
        return self._schemas[name]

    def _register(self, topic: str, encoding: str, sid: int, name: str) -> tuple[int, str]:
        if self._closed:
            raise RecorderError(f"{topic}: the MCAP sink is closed")
        metadata = {"offered_qos_profiles": offered_qos_profiles(topic_qos(topic))}
        chan = (
            self._writer.register_channel(
                topic, encoding, sid, metadata=metadata if self.profile == ROS2 else {}
            ),
            name,
        )
        self._channels[topic] = chan
        return chan

    def _check(self, topic: str, chan: tuple[int, str], name: str) -> None:
        if self._closed:
            raise RecorderError(f"{topic}: the MCAP sink is closed")
        if chan[1] != name:
            raise RecorderError(f"{topic}: a {name} on a channel of {chan[1]}; not written")

    def _group(self, topics: Sequence[str], typename: str) -> NDArray[np.uint16]:
        """The channel ids of `topics`, looked up once: a batch names the same topics every
        tick (per-topic work in every tick was a loop over 100 boats)."""
        group = (tuple(topics), typename)
        ids = self._groups.get(group)
        if ids is None:
            if len(set(topics)) != len(topics):
                raise RecorderError(f"a topic appears twice in one block: {list(topics)}")
            ids = np.array([self._ros2(t, typename) for t in topics], np.uint16)
            self._groups[group] = ids
        elif self._closed:
            raise RecorderError(f"{topics[0]}: the MCAP sink is closed")
        return ids

    def _sequences(self, ids: NDArray[np.uint16]) -> NDArray[np.int64]:
        """Each channel's next sequence number (ids are distinct): its messages so far."""
        return self._writer.written(ids)

    def _add(self, ids: list[int], stamp_ns: int, payloads: list[bytes]) -> None:
        sequences = self._sequences(np.array(ids, np.uint16))
        self._writer.add_messages(ids, sequences.tolist(), stamp_ns, payloads)

    def flush(self) -> None:
        """Put every record written so far into the file (call between ticks): finished
        chunks for good, the open ones provisionally."""
        if not self._closed:
            self._out.flush(self._writer.tail())

    def close(self) -> None:
        """Write the summary and footer, then close the file."""
        if self._closed:
            return
        self._writer.finish()
        self._out.flush(b"")  # the open chunks are finished: no tail
        self._out.close()
        self._closed = True

    def __enter__(self) -> McapSink:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
