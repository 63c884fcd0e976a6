"""McapWriter writes files that the reference `mcap` reader accepts, CRCs and summary."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap.stream_reader import CRCValidationError, StreamReader

from services.recorder.mcap_writer import McapWriter


def _write(path: Path) -> None:
    with open(path, "wb") as f:
        writer = McapWriter(f, profile="", library="test")
        schema = writer.register_schema("s", "jsonschema", b"{}")
        a = writer.register_channel("/a", "json", schema)
        b = writer.register_channel("/b", "json", schema)
        writer.add_messages([a, b], [0, 0], 100, [b'{"x":1}', b'{"y":2}'])
        writer.add_messages([], [], 150, [])  # an empty tick writes nothing
        writer.add_messages([a], [1], 200, [b'{"x":3}'])
        writer.finish()


def test_reader_sees_every_message_and_the_statistics(tmp_path: Path) -> None:
    path = tmp_path / "t.mcap"
    _write(path)
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        stats = summary.statistics
        assert (stats.message_count, stats.channel_count, stats.schema_count) == (3, 2, 1)
        assert (stats.message_start_time, stats.message_end_time) == (100, 200)
        assert stats.channel_message_counts == {1: 2, 2: 1}
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
    data = bytearray(path.read_bytes())
    data[data.index(b'{"y":2}')] ^= 0xFF  # one flipped byte in the data section
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
            writer.register_channel("/a", "json", schema)
            writer.register_channel("/b", "json", schema)
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
