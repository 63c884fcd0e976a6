"""McapWriter writes chunked, indexed files that the reference `mcap` reader accepts: CRCs,
summary, chunk and message indexes, every compression."""

from __future__ import annotations

import io
import struct
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap.records import Chunk, MessageIndex
from mcap.stream_reader import CRCValidationError, StreamReader

from catabot.run.mcap_compression import decompress
from services.recorder.mcap_read import read_mcap_messages
from services.recorder.mcap_writer import McapWriter


def _write(path: Path, compression: str = "none") -> None:
    with open(path, "wb") as f:
        writer = McapWriter(f, profile="", library="test", compression=compression)
        schema = writer.register_schema("s", "jsonschema", b"{}")
        a = writer.register_channel("/a", "json", schema, metadata={})
        b = writer.register_channel("/b", "json", schema, metadata={})
        writer.add_messages([a, b], [0, 0], 100, [b'{"x":1}', b'{"y":2}'])
        writer.add_messages([], [], 150, [])  # an empty tick writes nothing
        writer.add_messages([a], [1], 200, [b'{"x":3}'])
        writer.finish()


@pytest.mark.parametrize("compression", ["none", "zstd", "lz4"])
def test_reader_sees_every_message_and_the_statistics(tmp_path: Path, compression: str) -> None:
    path = tmp_path / "t.mcap"
    _write(path, compression)
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        stats = summary.statistics
        assert (stats.message_count, stats.channel_count, stats.schema_count) == (3, 2, 1)
        assert (stats.message_start_time, stats.message_end_time) == (100, 200)
        assert stats.channel_message_counts == {1: 2, 2: 1}
        assert stats.chunk_count == len(summary.chunk_indexes) == 1
        (index,) = summary.chunk_indexes
        assert index.compression == {"none": ""}.get(compression, compression)
        assert sorted(index.message_index_offsets) == [1, 2]
        got = [(c.topic, m.sequence, m.log_time, m.data) for _, c, m in reader.iter_messages()]
    assert got == [
        ("/a", 0, 100, b'{"x":1}'),
        ("/b", 0, 100, b'{"y":2}'),
        ("/a", 1, 200, b'{"x":3}'),
    ]


def test_crcs_are_checked_and_right(tmp_path: Path) -> None:
    path = tmp_path / "t.mcap"
    _write(path)
    records = list(StreamReader(str(path), validate_crcs=True).records)  # raises on a bad CRC
    assert type(records[-1]).__name__ == "Footer"
    good = path.read_bytes()
    data = bytearray(good)
    data[data.index(b'{"y":2}')] ^= 0xFF  # one flipped byte in a chunk
    path.write_bytes(bytes(data))
    with pytest.raises(CRCValidationError, match="crc validation failed in Chunk"):
        list(StreamReader(str(path), validate_crcs=True).records)
    data = bytearray(good)
    data[good.index(b"\x07", good.index(b'{"x":3}'))] ^= 0x40  # the message index record
    path.write_bytes(bytes(data))
    with pytest.raises(CRCValidationError, match="crc validation failed in DataEnd"):
        list(StreamReader(str(path), validate_crcs=True).records)


def test_mismatched_lengths_are_refused(tmp_path: Path) -> None:
    with open(tmp_path / "t.mcap", "wb") as f:
        writer = McapWriter(f, profile="", library="test")
        with pytest.raises(ValueError, match="2 channels, 1 sequences and 2 payloads"):
            writer.add_messages([1, 2], [0], 0, [b"", b""])
        with pytest.raises(ValueError, match=r"no channel registered with id\(s\) \[7\]"):
            writer.add_messages([7], [0], 0, [b""])
        with pytest.raises(ValueError, match="1 channels and 2 sequences for 2"):
            writer.add_block(np.array([1]), np.array([0, 1]), 0, np.zeros((2, 3), np.uint8))
        with pytest.raises(ValueError, match=r"no channel registered with id\(s\) \[9\]"):
            writer.add_block(np.array([9]), np.array([0]), 0, np.zeros((1, 3), np.uint8))


def test_a_block_writes_the_same_bytes_as_one_message_at_a_time(tmp_path: Path) -> None:
    payloads = np.arange(12, dtype=np.uint8).reshape(3, 4)
    for name, add in (
        ("one", lambda w: w.add_messages([1, 2, 1], [5, 0, 6], 70, [bytes(r) for r in payloads])),
        ("block", lambda w: w.add_block(np.array([1, 2, 1]), np.array([5, 0, 6]), 70, payloads)),
    ):
        with open(tmp_path / name, "wb") as f:
            writer = McapWriter(f, profile="", library="test")
            schema = writer.register_schema("s", "jsonschema", b"{}")
            writer.register_channel("/a", "json", schema, metadata={})
            writer.register_channel("/b", "json", schema, metadata={})
            add(writer)
            writer.finish()
    assert (tmp_path / "one").read_bytes() == (tmp_path / "block").read_bytes()
    with open(tmp_path / "block", "rb") as f:
        got = [(m.channel_id, m.sequence, m.data) for _, _, m in make_reader(f).iter_messages()]
    assert got == [
        (1, 5, bytes(payloads[0])),
        (2, 0, bytes(payloads[1])),
        (1, 6, bytes(payloads[2])),
    ]


def _many(path: Path, compression: str, chunk_bytes: int, ticks: int = 40) -> None:
    """`ticks` ticks of two small messages and, every 10th tick, one bulk (100 kB) one."""
    with open(path, "wb") as f:
        writer = McapWriter(
            f, profile="", library="test", compression=compression, chunk_bytes=chunk_bytes
        )
        schema = writer.register_schema("s", "jsonschema", b"{}")
        small = [writer.register_channel(t, "json", schema, metadata={}) for t in ("/a", "/b")]
        big = writer.register_channel("/img", "json", schema, metadata={})
        for tick in range(ticks):
            payloads = [b'{"t":%d}' % tick + b" " * 200] * 2
            writer.add_messages(small, [tick, tick], tick * 10, payloads)
            if tick % 10 == 0:
                writer.add_messages([big], [tick // 10], tick * 10, [bytes(100_000)])
        writer.finish()


@pytest.mark.parametrize("compression", ["none", "zstd", "lz4"])
def test_chunks_are_bounded_indexed_and_read_by_topic_and_time(
    tmp_path: Path, compression: str
) -> None:
    path = tmp_path / "t.mcap"
    _many(path, compression, chunk_bytes=2000)
    records = list(StreamReader(str(path), validate_crcs=True, emit_chunks=True).records)
    chunks = [r for r in records if isinstance(r, Chunk)]
    assert len(chunks) > 8
    for chunk in chunks:  # closed before the message that would start past the bound
        assert chunk.uncompressed_size < 2000 + 2 * 250 or chunk.uncompressed_size == 100_031
    indexes = [r for r in records if isinstance(r, MessageIndex)]
    assert sum(len(i.records) for i in indexes) == 40 * 2 + 4
    owner = {id(i): c for c in chunks for i in _indexes_after(records, c)}
    for index in indexes:  # every entry points at a message of its channel and log time
        chunk = owner[id(index)]
        data = decompress(chunk.data, chunk.compression, chunk.uncompressed_size)
        for log_time, offset in index.records:
            opcode, _, channel, _, at = struct.unpack_from("<BQHIQ", data, offset)
            assert (opcode, channel, at) == (0x05, index.channel_id, log_time)
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        assert summary is not None and len(summary.chunk_indexes) == len(chunks)
        bulk = [c for c in summary.chunk_indexes if c.uncompressed_size > 90_000]
        assert len(bulk) == 4 and all(list(c.message_index_offsets) == [3] for c in bulk)
        got = [(c.topic, m.log_time) for _, c, m in reader.iter_messages("/a", starting_at=300)]
    assert got == [("/a", t) for t in range(300, 400, 10)]


def _indexes_after(records: list[object], chunk: Chunk) -> list[MessageIndex]:
    """The message index records that follow `chunk` in the file."""
    out = []
    for record in records[records.index(chunk) + 1 :]:
        if not isinstance(record, MessageIndex):
            break
        out.append(record)
    return out


def test_same_messages_same_bytes_and_compression_is_checked(tmp_path: Path) -> None:
    for name in ("one", "two"):
        _many(tmp_path / name, "zstd", chunk_bytes=3000)
    assert (tmp_path / "one").read_bytes() == (tmp_path / "two").read_bytes()
    with pytest.raises(ValueError, match="compression 'gzip'; allowed: none, zstd, lz4"):
        McapWriter(io.BytesIO(), profile="", library="test", compression="gzip")


def test_the_tail_is_the_open_chunks_readable_without_a_summary(tmp_path: Path) -> None:
    out = io.BytesIO()
    writer = McapWriter(out, profile="", library="test", compression="zstd", chunk_bytes=400)
    schema = writer.register_schema("s", "jsonschema", b"{}")
    chan = writer.register_channel("/a", "json", schema, metadata={})
    for tick in range(5):
        writer.add_messages([chan], [tick], tick, [b'{"x":%d}' % tick + b" " * 150])
    (tmp_path / "killed.mcap").write_bytes(out.getvalue() + writer.tail())
    messages = read_mcap_messages(tmp_path / "killed.mcap")  # no DataEnd, no summary
    assert [m.sequence for m in messages] == [0, 1, 2, 3, 4]
    assert messages[-1].decoded == {"x": 4}


def _split_file(blocks: int) -> bytes:
    """Three ticks of 12 messages each, every tick's messages added in `blocks` blocks, in
    chunks of 100 bytes (as traffic set-points come in one block, or in one a shard)."""
    out = io.BytesIO()
    writer = McapWriter(out, profile="", library="test", compression="none", chunk_bytes=100)
    schema = writer.register_schema("s", "jsonschema", b"{}")
    channels = np.array([writer.register_channel(f"/{i}", "json", schema, metadata={})
                         for i in range(12)])  # fmt: skip
    payloads = np.zeros((12, 20), np.uint8)
    for tick in range(3):
        for part in np.array_split(np.arange(12), blocks):
            writer.add_block(channels[part], np.full(len(part), tick), tick * 10, payloads[part])
    writer.finish()
    return out.getvalue()


def test_the_bytes_do_not_depend_on_how_a_ticks_messages_came_in_blocks() -> None:
    """A chunk closed between two blocks of one tick: `run.mcap` differed with the number
    of traffic shards."""
    assert _split_file(1) == _split_file(3) == _split_file(12)
