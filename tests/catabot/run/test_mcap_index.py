"""The MCAP index finds every message of the recorder's unchunked files and of chunked ones,
stops at a torn tail, and refuses what is not MCAP."""

from __future__ import annotations

import mmap
import shutil
from pathlib import Path

import pytest
from mcap.writer import CompressionType, Writer

from catabot.run.mcap_index import McapIndex, McapIndexError, _from_summary
from services.recorder.mcap_sink import McapSink


def _write(path: Path, *, chunked: bool, messages: int = 50, compression: str = "zstd") -> None:
    with open(path, "wb") as f:
        kind = CompressionType[compression.upper()]
        w = Writer(f, use_chunking=chunked, chunk_size=256, compression=kind)
        w.start(profile="", library="test")
        sid = w.register_schema("s", "jsonschema", b"{}")
        a = w.register_channel("/a", "json", sid, metadata={})
        b = w.register_channel("/b", "json", sid, metadata={})
        for k in range(messages):
            w.add_message(a, log_time=10 * k, publish_time=10 * k, data=b'{"k":%d}' % k)
            if k % 5 == 0:
                w.add_message(b, log_time=10 * k, publish_time=10 * k, data=b"[%d]" % k)
        w.finish()  # the summary repeats schemas and channels: they must not reset the index


@pytest.mark.parametrize(
    ("chunked", "compression"), [(False, "none"), (True, "none"), (True, "zstd"), (True, "lz4")]
)
def test_every_message_found(tmp_path: Path, chunked: bool, compression: str) -> None:
    _write(tmp_path / "f.mcap", chunked=chunked, compression=compression)
    index = McapIndex(tmp_path / "f.mcap")
    assert isinstance(index.data, mmap.mmap)  # the file, or its decompressed records' copy
    in_place = len(index.data) == (tmp_path / "f.mcap").stat().st_size
    assert in_place == (compression == "none")
    assert [p.name for p in tmp_path.iterdir()] == ["f.mcap"]  # the copy is unlinked
    assert index.topics() == ["/a", "/b"]
    a, b = index.channel("/a"), index.channel("/b")
    assert a is not None and b is not None
    assert len(a) == 50 and len(b) == 10 and b.stamps == [50 * k for k in range(10)]
    assert index.payload(a, 7) == b'{"k":7}' and index.payloads(b)[-1] == b"[45]"
    assert index.rows(b) is None  # "[0]", "[5]", "[10]": lengths differ
    assert a.schema_name == "s" and a.encoding == "json"


def test_a_torn_tail_ends_the_index_at_the_last_whole_record(tmp_path: Path) -> None:
    _write(tmp_path / "f.mcap", chunked=False)
    data = (tmp_path / "f.mcap").read_bytes()
    index = McapIndex(tmp_path / "f.mcap")
    a = index.channel("/a")
    assert a is not None
    cut = a.ends[20] + 3  # inside the record after message 20 of /a
    (tmp_path / "torn.mcap").write_bytes(data[:cut])
    torn = McapIndex(tmp_path / "torn.mcap")
    assert torn.channel("/a") is not None and len(torn.channel("/a") or ()) == 21
    assert index.finished and not torn.finished  # RecordedRun tells a reader it was cut off


@pytest.mark.parametrize("compression", ["none", "zstd"])
def test_the_recorders_chunks_and_a_killed_writers_tail(tmp_path: Path, compression: str) -> None:
    """Finished chunks and the open ones a flush left provisionally (no summary)."""
    sink = McapSink(tmp_path / "run.mcap", profile="", compression=compression, chunk_bytes=300)
    for k in range(30):
        sink.write_json("/a", "s", {}, b'{"k":%d}' % k, stamp_ns=k)
        sink.write_json("/big", "s", {}, bytes(70_000), stamp_ns=k) if k % 10 == 0 else None
        sink.flush()
    shutil.copyfile(tmp_path / "run.mcap", tmp_path / "killed.mcap")  # what a SIGKILL leaves
    sink.close()
    for name in ("killed.mcap", "run.mcap"):
        index = McapIndex(tmp_path / name)
        a, big = index.channel("/a"), index.channel("/big")
        assert a is not None and big is not None
        assert a.stamps == list(range(30)) and index.payload(a, 29) == b'{"k":29}'
        assert big.stamps == [0, 10, 20] and index.payload(big, 2) == bytes(70_000)


def test_a_damaged_chunk_is_named(tmp_path: Path) -> None:
    _write(tmp_path / "f.mcap", chunked=True, compression="zstd")
    data = bytearray((tmp_path / "f.mcap").read_bytes())
    at = data.index(b"zstd") + 4 + 8  # the first chunk's compressed bytes
    data[at : at + 4] = b"\x00" * 4  # not a zstd frame any more
    (tmp_path / "f.mcap").write_bytes(bytes(data))
    with pytest.raises(McapIndexError, match=r"f\.mcap: chunk at byte \d+ unreadable"):
        McapIndex(tmp_path / "f.mcap")


def test_other_files_are_refused(tmp_path: Path) -> None:
    (tmp_path / "x.mcap").write_bytes(b"not an mcap file at all")
    with pytest.raises(McapIndexError, match="not an MCAP file"):
        McapIndex(tmp_path / "x.mcap")
    with pytest.raises(McapIndexError, match="cannot read"):
        McapIndex(tmp_path / "missing.mcap")


@pytest.mark.parametrize("compression", ["none", "zstd", "lz4"])
def test_the_summary_and_message_indexes_give_what_a_walk_gives(
    tmp_path: Path, compression: str
) -> None:
    """A finished file is indexed from its summary (no record walked); without the footer
    (the last byte cut) the same file is walked: both find the same messages."""
    _write(tmp_path / "f.mcap", chunked=True, compression=compression, messages=300)
    data = (tmp_path / "f.mcap").read_bytes()
    (tmp_path / "cut.mcap").write_bytes(data[:-1])
    assert _from_summary(data, tmp_path) is not None and _from_summary(data[:-1], tmp_path) is None
    indexed, walked = McapIndex(tmp_path / "f.mcap"), McapIndex(tmp_path / "cut.mcap")
    assert indexed.topics() == walked.topics() == ["/a", "/b"]
    for topic in ("/a", "/b"):
        one, two = indexed.channel(topic), walked.channel(topic)
        assert one is not None and two is not None and len(one) == len(two) > 50
        assert one.stamps == two.stamps and indexed.payloads(one) == walked.payloads(two)
        assert one.schema_name == two.schema_name == "s"
