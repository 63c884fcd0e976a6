"""The msgpack codec: round trips, zero-copy arrays, and clear refusals (DESIGN.md §5)."""

from __future__ import annotations

import dataclasses
import math

import msgpack
import numpy as np
import pytest

from catabot import codec
from catabot.codec import ARRAY_EXT, CodecError
from catabot.messages import (
    MESSAGE_TYPES,
    SCHEMA_VERSION,
    Ack,
    BodyStates,
    CameraFrame,
    End,
    GpsFix,
    ImuSample,
    LidarScan,
    Message,
    RadarSweep,
    ThrustCmd,
    Tick,
    TwistCmd,
    VesselState,
    WaypointsCmd,
)

SAMPLES: dict[str, Message] = {
    "tick": Tick(run="3f2a9c1d0b7e", tick=41, stamp_ns=410_000_000, dt_ns=10_000_000),
    "ack": Ack(run="3f2a9c1d0b7e", tick=41),
    "end": End(
        run="3f2a9c1d0b7e",
        tick=5999,
        reason="fault",
        error="participant 'sensors' missed the 10 s deadline of tick 6000",
    ),
    "vessel_state": VesselState(
        tick=120,
        stamp_ns=1_200_000_000,
        position=(12.5, -3.25, 0.084),
        orientation=(0.0012, -0.0031, 0.3826834323650898, 0.9238795325112867),
        linear_velocity=(1.42, -0.03, 0.001),
        angular_velocity=(0.0, 0.002, -0.2),
        linear_acceleration=(0.15, 0.0, -0.01),
        angular_acceleration=(0.0, 0.0, 1e-5),
    ),
    "body_states": BodyStates(
        tick=120,
        stamp_ns=1_200_000_000,
        ids=("ego", "boat_000", "buoy_0"),
        position=np.arange(9, dtype=np.float64).reshape(3, 3) / 3,
        orientation=np.tile([0.0, 0.0, 0.3826834323650898, 0.9238795325112867], (3, 1)),
        linear_velocity=np.full((3, 3), 1.42),
        angular_velocity=np.zeros((3, 3)),
        linear_acceleration=np.full((3, 3), -0.01),
        angular_acceleration=np.full((3, 3), 1e-5),
    ),
    "thrust_cmd": ThrustCmd(thrust=(0.8, -0.35), tick=7, stamp_ns=70_000_000),
    "twist_cmd": TwistCmd(surge=1.5, yaw_rate=-0.2, tick=-1, stamp_ns=0),
    "waypoints_cmd": WaypointsCmd(
        points=(10.0, 0.0, 10.0, 25.0), speed=5.0, tolerance=3.0, mode="loop"
    ),
    "imu": ImuSample(
        tick=99,
        stamp_ns=990_000_000,
        orientation=(0.0, 0.0, 0.0, 1.0),
        angular_velocity=(0.001, -0.002, 0.05),
        linear_acceleration=(0.02, 0.01, 9.80665),
    ),
    "gps": GpsFix(
        tick=100,
        stamp_ns=1_000_000_000,
        latitude=40.7003123,
        longitude=-74.0170456,
        altitude=1.2,
        horizontal_sigma=0.0,
        vertical_sigma=0.0,
    ),
    "lidar_scan": LidarScan(
        tick=20,
        stamp_ns=200_000_000,
        points=np.arange(12, dtype=np.float32).reshape(4, 3),
        intensity=np.array([1e-4, 2e-5, 3e-3, 4e-6], dtype=np.float32),
        ring=np.array([0, 1, 1, 31], dtype=np.uint16),
        cls=np.array([1, 2, 0, 3], dtype=np.uint8),
        instance=np.array([0, 0, 0, 2], dtype=np.int32),
        is_rain=np.array([False, False, True, False]),
        range_image=np.full((2, 3), np.inf, dtype=np.float32),
    ),
    "radar_sweep": RadarSweep(
        tick=21,
        stamp_ns=210_000_000,
        azimuth_start_rad=0.5,
        azimuth_end_rad=0.48,
        heading_rad=-1.0,
        range_m=250.0,
        beams=2,
        intensity=np.array([[0, 200, 0], [0, 0, 9]], dtype=np.uint8),
        ranges=np.array([90.0, np.inf], dtype=np.float32),
    ),
    "camera_frame": CameraFrame(
        tick=22,
        stamp_ns=220_000_000,
        width=3,
        height=2,
        hfov_rad=1.4,
        objects=1,
        color=np.zeros((2, 3, 3), dtype=np.uint8),
        depth=np.full((2, 3), np.inf, dtype=np.float32),
        normals=np.zeros((0,), dtype=np.uint8),
        segmentation=np.array([[0, 3, 3], [1, 1, 1]], dtype=np.uint8),
        instance=np.array([[0, 2, 2], [0, 0, 0]], dtype=np.uint16),
        boxes=np.array([[2, 3, 1, 0, 3, 1]], dtype=np.float32),
        box_flags=np.array([[0, 1]], dtype=np.uint8),
    ),
}

DTYPES = ["bool", "u1", "u2", "u4", "u8", "i1", "i2", "i4", "i8", "f2", "f4", "f8"]


def _body(msg: Message) -> dict:
    return codec.unpack(codec.encode(msg))


def _payload(body: dict) -> bytes:
    return msgpack.packb(body, use_bin_type=True)


def _same(a: Message, b: Message) -> bool:
    """Field-by-field equality, arrays by value, dtype and shape (== on arrays is elementwise)."""
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
            if not (np.array_equal(x, y) and x.dtype == y.dtype and x.shape == y.shape):
                return False
        elif x != y:
            return False
    return type(a) is type(b)


def _root(arr: np.ndarray) -> object:
    base: object = arr
    while isinstance(base, np.ndarray) and base.base is not None:
        base = base.base
    return base


# -- messages -----------------------------------------------------------------------------


def test_samples_cover_every_message_type() -> None:
    assert set(SAMPLES) == set(MESSAGE_TYPES)
    for wire, msg in SAMPLES.items():
        assert type(msg) is MESSAGE_TYPES[wire]


@pytest.mark.parametrize("wire", sorted(MESSAGE_TYPES))
def test_message_round_trip(wire: str) -> None:
    msg = SAMPLES[wire]
    payload = codec.encode(msg)
    assert isinstance(payload, bytes)
    back = codec.decode(payload, type(msg))
    assert _same(back, msg)
    assert type(back) is type(msg)
    body = codec.unpack(payload)
    assert body["v"] == SCHEMA_VERSION
    assert body["type"] == wire


def test_body_states_rows_are_the_vessel_states_of_each_body() -> None:
    """A decoded batch keeps ids and float64 rows; a row is the per-body message, exactly."""
    batch = SAMPLES["body_states"]
    assert isinstance(batch, BodyStates)
    back = codec.decode(codec.encode(batch), BodyStates)
    assert back.ids == ("ego", "boat_000", "buoy_0")
    assert back.position.dtype == np.float64 and back.orientation.shape == (3, 4)
    row = back.row(1)
    assert row == VesselState(
        120,
        1_200_000_000,
        (1.0, 4 / 3, 5 / 3),
        (0.0, 0.0, 0.3826834323650898, 0.9238795325112867),
        (1.42, 1.42, 1.42),
        (0.0, 0.0, 0.0),
        (-0.01, -0.01, -0.01),
        (1e-5, 1e-5, 1e-5),
    )
    assert all(type(v) is float for v in row.position)
    assert back.rows() == [back.row(i) for i in range(3)]


def test_decode_accepts_memoryview_and_bytearray() -> None:
    payload = codec.encode(SAMPLES["gps"])
    assert codec.decode(memoryview(payload), GpsFix) == SAMPLES["gps"]
    assert codec.decode(bytearray(payload), GpsFix) == SAMPLES["gps"]


def test_tick_with_dropped_participants_round_trips() -> None:
    tick = Tick("r", 3, 30, 10, dropped=("sensors", "recorder"))
    assert codec.decode(codec.encode(tick), Tick) == tick


def test_optional_fields_take_their_defaults() -> None:
    body = {"v": SCHEMA_VERSION, "type": "thrust_cmd", "thrust": [0.5, 0.5]}
    cmd = codec.decode(_payload(body), ThrustCmd)
    assert cmd == ThrustCmd(thrust=(0.5, 0.5), tick=-1, stamp_ns=0)


def test_integers_are_accepted_where_floats_are_expected() -> None:
    body = _body(SAMPLES["twist_cmd"])
    body["surge"] = 2
    cmd = codec.decode(_payload(body), TwistCmd)
    assert cmd.surge == 2.0 and type(cmd.surge) is float
    body = _body(SAMPLES["thrust_cmd"])
    body["thrust"] = [1, 0]
    assert codec.decode(_payload(body), ThrustCmd).thrust == (1.0, 0.0)


def test_vectors_decode_as_tuples_of_floats() -> None:
    state = codec.decode(codec.encode(SAMPLES["vessel_state"]), VesselState)
    for f in dataclasses.fields(VesselState):
        value = getattr(state, f.name)
        if isinstance(value, tuple):
            assert all(type(v) is float for v in value)


# -- arrays -------------------------------------------------------------------------------


@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("shape", [(), (0,), (7,), (3, 5), (2, 3, 4), (0, 3)])
def test_array_round_trip(dtype: str, shape: tuple[int, ...]) -> None:
    rng = np.random.default_rng(42)
    n = math.prod(shape)
    if dtype == "bool":
        arr = rng.integers(0, 2, n).astype(bool).reshape(shape)
    elif dtype.startswith("f"):
        arr = (rng.standard_normal(n) * 100).astype(dtype).reshape(shape)
    else:
        info = np.iinfo(np.dtype(dtype))
        arr = rng.integers(info.min, info.max, n, dtype=dtype, endpoint=True).reshape(shape)
    back = codec.unpack(codec.pack({"a": arr}))["a"]
    assert isinstance(back, np.ndarray)
    assert back.dtype == np.dtype(dtype)
    assert back.shape == shape
    assert back.tobytes() == arr.tobytes()
    assert back.flags.writeable is False
    assert back.base is not None


def test_image_and_point_cloud_are_zero_copy_views() -> None:
    rng = np.random.default_rng(7)
    image = rng.integers(0, 256, (480, 640, 3), dtype=np.uint8)
    cloud = rng.standard_normal((16384, 4)).astype(np.float32)
    payload = codec.pack({"image": image, "cloud": cloud, "stamp_ns": 5})
    assert len(payload) > image.nbytes + cloud.nbytes  # raw bytes, not lists of floats
    assert len(payload) < image.nbytes + cloud.nbytes + 200
    body = codec.unpack(payload)
    assert body["stamp_ns"] == 5
    for name, arr in (("image", image), ("cloud", cloud)):
        back = body[name]
        assert back.shape == arr.shape and back.dtype == arr.dtype
        np.testing.assert_array_equal(back, arr)
        assert back.flags.writeable is False
        assert back.base is not None
        # the view sits on the extension's own bytes: no copy into a new array
        assert isinstance(_root(back), bytes)
        assert len(_root(back)) > back.nbytes
        with pytest.raises(ValueError):
            back[0, 0] = 1


def test_the_exact_extension_bytes_are_viewed() -> None:
    arr = np.arange(12, dtype="<u2").reshape(3, 4)
    seen: list[bytes] = []

    def hook(code: int, data: bytes) -> object:
        seen.append(data)
        return codec._ext_to_array(code, data)

    back = msgpack.unpackb(codec.pack(arr), ext_hook=hook)
    assert _root(back) is seen[0]
    assert bytes(back.data) == arr.tobytes()


def test_non_contiguous_arrays_are_sent_in_c_order() -> None:
    arr = np.arange(24, dtype=np.int32).reshape(4, 6)
    for view in (arr.T, arr[::2, 1::2], np.asfortranarray(arr)):
        back = codec.unpack(codec.pack(view))
        np.testing.assert_array_equal(back, view)
        assert back.flags.c_contiguous


@pytest.mark.parametrize("dtype", [">u2", ">i4", ">i8", ">f4", ">f8", ">f2"])
def test_big_endian_input_is_converted(dtype: str) -> None:
    arr = np.array([[1, 2, 3], [-4 if "u" not in dtype else 4, 5, 6]], dtype=dtype)
    back = codec.unpack(codec.pack(arr))
    assert back.dtype == np.dtype(dtype).newbyteorder("<")
    assert back.dtype.byteorder in ("<", "=")
    np.testing.assert_array_equal(back, arr)
    ext = msgpack.unpackb(codec.pack(arr))  # the wire format: little-endian dtype and bytes
    assert ext.code == ARRAY_EXT
    dtype_str, shape = msgpack.unpackb(ext.data[1 : 1 + ext.data[0]])
    assert dtype_str == np.dtype(dtype).newbyteorder("<").str and shape == [2, 3]
    assert ext.data[1 + ext.data[0] :] == arr.astype(dtype_str).tobytes()


def test_numpy_scalars_pack_as_plain_numbers() -> None:
    body = codec.unpack(codec.pack({"f": np.float32(1.5), "i": np.int64(-3), "b": np.bool_(True)}))
    assert body == {"f": 1.5, "i": -3, "b": True}
    assert type(body["f"]) is float and type(body["i"]) is int


@pytest.mark.parametrize(
    "arr",
    [np.array(["a", "bc"]), np.array([object(), 1], dtype=object), np.array([1 + 2j])],
    ids=["str", "object", "complex"],
)
def test_unsupported_array_dtypes_are_refused(arr: np.ndarray) -> None:
    with pytest.raises(CodecError, match="cannot be sent"):
        codec.pack({"a": arr})


def test_unencodable_objects_are_refused() -> None:
    with pytest.raises(TypeError, match="cannot encode set"):
        codec.pack({"a": {1, 2}})


# -- refusals -----------------------------------------------------------------------------


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
        with pytest.raises(CodecError, match="not a msgpack payload"):
            codec.decode(junk, Ack)


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


@pytest.mark.parametrize("version", [0, 2, None, "1"])
def test_unknown_schema_version(version: object) -> None:
    body = _body(SAMPLES["ack"])
    if version is None:
        del body["v"]
    else:
        body["v"] = version
    with pytest.raises(CodecError) as info:
        codec.decode(_payload(body), Ack)
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
    assert "ack: unknown field(s) ['speed']" in str(info.value)
    assert "fields are ['run', 'tick']" in str(info.value)


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
