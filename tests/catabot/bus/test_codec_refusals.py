"""RefusalsThe msgpack codec: round trips, zero-copy arrays, and clear refusals (DESIGN.md §5)."""

from __future__ import annotations

import math

import msgpack
import pytest

from catabot.bus import codec
from catabot.bus.codec import ARRAY_EXT, CodecError
from catabot.bus.messages import (
    MESSAGE_TYPES,
    SCHEMA_VERSION,
    Ack,
    ImuSample,
    ThrustCmd,
    TwistCmd,
    VesselState,
)

# -- refusals -----------------------------------------------------------------------------
from tests.catabot.bus.codec_samples import SAMPLES, _body, _payload


def _ext(header: object, raw: bytes = b"", *, hlen: int | None = None) -> bytes:
    head = msgpack.packb(header)
    n = len(head) if hlen is None else hlen
    return msgpack.packb({"a": msgpack.ExtType(ARRAY_EXT, bytes([n]) + head + raw)})


@pytest.mark.parametrize(
    ("payload", "words"),
    [
        (_ext(["<f4", [3]], b"\0" * 11), ["malformed array extension"]),
        (_ext(["<f4", [2, 2]], b"\0" * 8), ["malformed array extension"]),
        (_ext(["<f4", [-1]], b"\0" * 8), ["malformed array extension", "shape"]),
        (_ext(["<f4", "2"], b"\0" * 8), ["malformed array extension", "shape"]),
        (_ext(["<f4", [1.5]], b"\0" * 8), ["malformed array extension", "shape"]),
        (_ext(["<f4"], b"\0" * 8), ["malformed array extension"]),
        (_ext(["|O", [1]], b"\0" * 8), ["array dtype", "not allowed"]),
        (_ext(["<U1", [1]], b"\0" * 4), ["array dtype", "not allowed"]),
        (_ext([["<f4"], [1]], b"\0" * 4), ["malformed array extension"]),
        (_ext(["<f4", [1]], b"\0" * 4, hlen=200), ["malformed array extension"]),
        (msgpack.packb({"a": msgpack.ExtType(ARRAY_EXT, b"")}), ["malformed array extension"]),
        (msgpack.packb({"a": msgpack.ExtType(5, b"xyz")}), ["unknown msgpack extension type 5"]),
    ],
    ids=[
        "bytes-not-multiple-of-itemsize",
        "shape-does-not-match-bytes",
        "negative-dimension",
        "shape-not-a-list",
        "float-dimension",
        "no-shape",
        "object-dtype",
        "str-dtype",
        "dtype-not-a-string",
        "header-length-past-end",
        "empty-extension",
        "other-extension-code",
    ],
)
def test_malformed_array_extension(payload: bytes, words: list[str]) -> None:
    with pytest.raises(CodecError) as info:
        codec.unpack(payload)
    for word in words:
        assert word in str(info.value)


def test_non_msgpack_bytes() -> None:
    for junk in (b"\xc1", b"\xc1\xc1garbage", b""):
        with pytest.raises(CodecError, match=r"not a msgpack payload: .") as info:
            codec.decode(junk, Ack)
        assert not str(info.value).endswith(": ")  # msgpack's FormatError says nothing
    with pytest.raises(CodecError, match=r"payload: FormatError in bytes c1 c1 c1$"):
        codec.decode(b"\xc1\xc1\xc1", Ack)


def test_truncated_payload() -> None:
    payload = codec.encode(SAMPLES["vessel_state"])
    for cut in (1, len(payload) // 2, len(payload) - 1):
        with pytest.raises(CodecError, match="not a msgpack payload"):
            codec.decode(payload[:cut], VesselState)


def test_trailing_bytes_are_refused() -> None:
    with pytest.raises(CodecError, match="not a msgpack payload"):
        codec.decode(codec.encode(SAMPLES["ack"]) + b"\x00", Ack)


def test_not_a_map() -> None:
    with pytest.raises(CodecError, match="payload is a list, expected a map"):
        codec.decode(msgpack.packb([1, 2]), Ack)


@pytest.mark.parametrize("version", [0, 2, None, "1", True, 1.0])  # True == 1 == 1.0
def test_unknown_schema_version(version: object) -> None:
    body = _body(SAMPLES["ack"])
    if version is None:
        del body["v"]
    else:
        body["v"] = version
    with pytest.raises(CodecError) as info:
        codec.decode(_payload(body), Ack)
    if version is None:
        assert (
            str(info.value) == f'no "v": every payload carries the schema version, {SCHEMA_VERSION}'
        )
        return
    assert f"schema version {version!r} is not supported" in str(info.value)
    assert f"this is {SCHEMA_VERSION}" in str(info.value)


def test_unknown_type() -> None:
    body = _body(SAMPLES["ack"])
    body["type"] = "lidar_scan"
    with pytest.raises(CodecError) as info:
        codec.decode(_payload(body), Ack)
    msg = str(info.value)
    assert "'lidar_scan'" in msg and "'ack' was expected" in msg
    for wire in MESSAGE_TYPES:
        assert wire in msg  # the known types are listed


def test_wrong_type() -> None:
    with pytest.raises(CodecError, match=r"message type 'gps' where 'imu' was expected"):
        codec.decode(codec.encode(SAMPLES["gps"]), ImuSample)


def test_missing_type() -> None:
    body = _body(SAMPLES["ack"])
    del body["type"]
    with pytest.raises(CodecError, match="message type None where 'ack' was expected"):
        codec.decode(_payload(body), Ack)


def test_missing_field() -> None:
    body = _body(SAMPLES["vessel_state"])
    del body["orientation"]
    with pytest.raises(CodecError, match=r"vessel_state: missing field 'orientation'"):
        codec.decode(_payload(body), VesselState)


def test_unknown_field() -> None:
    body = _body(SAMPLES["ack"])
    body["speed"] = 3.0
    with pytest.raises(CodecError) as info:
        codec.decode(_payload(body), Ack)
    said = str(info.value)
    assert "ack: unknown field(s) 'speed' (fields: run, tick; optional: end, fault)" in said


def test_unknown_fields_of_mixed_key_types() -> None:
    """A bin key beside str keys must still give a CodecError, not a TypeError."""
    body = _body(SAMPLES["ack"])
    body[b"raw"] = 1
    body["speed"] = 2
    with pytest.raises(CodecError, match="unknown field"):
        codec.decode(_payload(body), Ack)


@pytest.mark.parametrize(
    ("wire", "field", "value", "words"),
    [
        ("ack", "tick", "7", ["ack.tick: expected int, got str"]),
        ("ack", "tick", 7.0, ["ack.tick: expected int, got float"]),
        ("ack", "tick", True, ["ack.tick: expected int, got bool"]),
        ("ack", "run", 5, ["ack.run: expected str, got int"]),
        ("gps", "latitude", "40.7", ["gps.latitude: expected float, got str"]),
        ("gps", "latitude", None, ["gps.latitude: expected float, got NoneType"]),
        ("vessel_state", "position", 1.0, ["vessel_state.position: expected vector"]),
        ("vessel_state", "position", [1.0, 2.0], ["vessel_state.position", "expected 3 numbers"]),
        ("imu", "orientation", [0, 0, 1], ["imu.orientation", "expected 4 numbers, got 3"]),
        ("imu", "angular_velocity", [0, "x", 1], ["imu.angular_velocity", "must be a number"]),
        ("thrust_cmd", "thrust", [0.5, None], ["thrust_cmd.thrust", "must be a number"]),
        ("thrust_cmd", "thrust", [True, 0.0], ["thrust_cmd.thrust", "must be a number"]),
        ("tick", "dropped", ["a", 3], ["tick.dropped: expected names"]),
    ],
)
def test_bad_field_values(wire: str, field: str, value: object, words: list[str]) -> None:
    msg = SAMPLES[wire]
    body = _body(msg)
    body[field] = value
    with pytest.raises(CodecError) as info:
        codec.decode(_payload(body), type(msg))
    for word in words:
        assert word in str(info.value)


def test_variable_length_vectors_accept_any_length() -> None:
    for thrust in ([], [0.1], [0.1, 0.2, 0.3, 0.4]):
        body = _body(SAMPLES["thrust_cmd"])
        body["thrust"] = thrust
        assert codec.decode(_payload(body), ThrustCmd).thrust == tuple(thrust)


def test_codec_error_is_a_value_error() -> None:
    assert issubclass(CodecError, ValueError)


# -- finite -------------------------------------------------------------------------------


def test_finite() -> None:
    assert codec.finite(1.0)
    assert codec.finite(0)
    assert codec.finite((0.5, -1.0, 1e300))
    assert codec.finite(())
    assert not codec.finite(math.nan)
    assert not codec.finite(math.inf)
    assert not codec.finite(-math.inf)
    assert not codec.finite((0.5, math.nan))
    assert not codec.finite((math.inf, 0.0))


def test_non_finite_values_survive_the_codec_for_finite_to_refuse() -> None:
    cmd = codec.decode(codec.encode(TwistCmd(surge=math.nan, yaw_rate=math.inf)), TwistCmd)
    assert math.isnan(cmd.surge) and cmd.yaw_rate == math.inf
    assert not codec.finite((cmd.surge, cmd.yaw_rate))


def test_a_map_of_many_unknown_fields_names_a_few_and_counts_the_rest() -> None:
    """Naming millions of keys took 8 s and a 10 MB line for one sample."""
    body = _body(SAMPLES["ack"])
    body |= {f"k{i}": i for i in range(50)}
    body["x" * 500] = 1
    with pytest.raises(CodecError) as info:
        codec.decode(_payload(body), Ack)
    said = str(info.value)
    assert "ack: unknown field(s) 'k0', 'k1', 'k2', 'k3', 'k4' and 46 more" in said
    assert len(said) < 200


def test_a_map_of_thousands_of_fields_is_refused_at_its_header() -> None:
    """A trial's 64 KB command of 8000 junk fields took physics 1.5 ms to read and refuse;
    at 2000 a second the run stopped. No message has 64 fields: the header says enough."""
    body = _body(SAMPLES["ack"]) | {f"k{i:05d}": 0 for i in range(8000)}
    with pytest.raises(CodecError, match="a map of 8006 entries: a message has 64 fields at most"):
        codec.decode(_payload(body), Ack)  # msgpack's header check: no field was read
