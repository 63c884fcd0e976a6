"""docs/MESSAGES.md is generated from the message definitions and says how to decode them."""

from __future__ import annotations

import dataclasses
import struct

import msgpack
import numpy as np

from catabot.bus import codec
from catabot.bus.messages import MESSAGE_TYPES, TwistCmd
from catabot.bus.reference import reference
from tests.paths import REPO


def test_docs_messages_md_is_up_to_date() -> None:
    written = (REPO / "docs" / "MESSAGES.md").read_text()
    assert written == reference(), (
        "docs/MESSAGES.md is out of date: python -m catabot.bus.reference > docs/MESSAGES.md"
    )


def test_every_message_and_field_is_in_the_reference() -> None:
    text = reference()
    for wire, cls in MESSAGE_TYPES.items():
        assert f"### `{wire}` ({cls.__name__})" in text
        for name in (f.name for f in dataclasses.fields(cls)):
            assert f"| `{name}` |" in text
    assert "| `surge` | float | m/s | **required** |" in text
    assert '| `mode` | str | - | optional, default `"back_and_forth"` |' in text


def test_an_array_built_from_the_documented_layout_decodes() -> None:
    """What a C++ or Rust client would write from the reference alone: ext type 1, one byte
    of header length, the msgpack header [dtype, shape], then little-endian C-order data."""
    values = [[1.0, -2.5, 3.25], [4.0, 5.0, 6.0]]
    header = msgpack.packb(["<f4", [2, 3]])
    data = bytes([len(header)]) + header + struct.pack("<6f", *[v for row in values for v in row])
    ext = b"\xc7" + bytes([len(data)]) + b"\x01" + data  # msgpack ext 8, type 1
    decoded = codec.unpack(ext)
    assert decoded.dtype == np.float32 and decoded.shape == (2, 3)
    np.testing.assert_array_equal(decoded, np.array(values, dtype=np.float32))


def test_a_twist_written_by_hand_in_another_key_order_decodes() -> None:
    payload = msgpack.packb({"yaw_rate": 0.1, "type": "twist_cmd", "surge": 1, "v": 1})
    assert codec.decode(payload, TwistCmd) == TwistCmd(1.0, 0.1)
