"""The MCAP index finds every message of the recorder's unchunked files and of chunked ones,
stops at a torn tail, and refuses what is not MCAP."""

from __future__ import annotations

from pathlib import Path

import pytest
from mcap.writer import Writer

from catabot.run.mcap_index import McapIndex, McapIndexError


def _write(path: Path, *, chunked: bool, messages: int = 50) -> None:
    with open(path, "wb") as f:
        w = Writer(f, use_chunking=chunked, chunk_size=256)
        w.start(profile="", library="test")
        sid = w.register_schema("s", "jsonschema", b"{}")
        a = w.register_channel("/a", "json", sid)
        b = w.register_channel("/b", "json", sid)
        for k in range(messages):
            w.add_message(a, log_time=10 * k, publish_time=10 * k, data=b'{"k":%d}' % k)
            if k % 5 == 0:
                w.add_message(b, log_time=10 * k, publish_time=10 * k, data=b"[%d]" % k)
        w.finish()  # the summary repeats schemas and channels: they must not reset the index


@pytest.mark.parametrize("chunked", [False, True])
def test_every_message_found(tmp_path: Path, chunked: bool) -> None:
    _write(tmp_path / "f.mcap", chunked=chunked)
    index = McapIndex(tmp_path / "f.mcap")
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
    torn = McapIndex(tmp_path / "torn.mcap").channel("/a")
    assert torn is not None and len(torn) == 21


def test_other_files_are_refused(tmp_path: Path) -> None:
    (tmp_path / "x.mcap").write_bytes(b"not an mcap file at all")
    with pytest.raises(McapIndexError, match="not an MCAP file"):
        McapIndex(tmp_path / "x.mcap")
    with pytest.raises(McapIndexError, match="cannot read"):
        McapIndex(tmp_path / "missing.mcap")
