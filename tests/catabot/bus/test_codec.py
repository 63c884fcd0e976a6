"""The msgpack codec: round trips, zero-copy arrays, and clear refusals (DESIGN.md §5)."""

from __future__ import annotations

import dataclasses
import math

import msgpack
import numpy as np
import pytest

from catabot.bus import codec
from catabot.bus.codec import ARRAY_EXT, CodecError
from catabot.bus.messages import (
    MESSAGE_TYPES,
    SCHEMA_VERSION,
    BodyStates,
    GpsFix,
    ThrustCmd,
    Tick,
    TwistCmd,
    VesselState,
)

# -- messages -----------------------------------------------------------------------------
from tests.catabot.bus.codec_samples import DTYPES, SAMPLES, _body, _payload, _root, _same


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


def test_integers_beyond_int64_are_refused() -> None:
    """A stamp of 2**64 - 1 passed and was taken: every store of a stamp is int64."""
    body = _body(SAMPLES["twist_cmd"])
    body["stamp_ns"] = 2**64 - 1
    with pytest.raises(codec.CodecError, match=r"twist_cmd\.stamp_ns: 18446744073709551615 is "
                       r"beyond a 64-bit signed integer"):  # fmt: skip
        codec.decode(_payload(body), TwistCmd)
    body["stamp_ns"] = -(2**63)
    assert codec.decode(_payload(body), TwistCmd).stamp_ns == -(2**63)


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
