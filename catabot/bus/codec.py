"""msgpack codec for bus messages (DESIGN.md §5).

A payload is a msgpack map `{"v": SCHEMA_VERSION, "type": <wire name>, <fields>...}`.
NumPy arrays travel as extension type 1 (header + raw little-endian bytes) and decode
as read-only views on the received buffer: no copy, so a 640x480 depth image costs one
`frombuffer`. Every decode validates version, type and each field, so a malformed
payload is refused with a message naming what is wrong instead of failing later.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import Any, TypeVar

import msgpack
import numpy as np

from catabot.bus.fields import fields_of
from catabot.bus.messages import MESSAGE_TYPES, SCHEMA_VERSION, Message
from catabot.errors import CataBotError

ARRAY_EXT = 1
SHOWN_UNKNOWN = 5  # unknown fields named in a refusal; the rest are counted
MAX_FIELDS = 64  # no message has half as many: a map of 8000 junk fields took 1.5 ms to read
ALLOWED_DTYPES = frozenset(
    np.dtype(t).str
    for t in ("bool", "u1", "u2", "u4", "u8", "i1", "i2", "i4", "i8", "f2", "f4", "f8")
)
M = TypeVar("M", bound=Message)


class CodecError(CataBotError, ValueError):
    """A payload that is not a valid message of a known type and schema version."""


def _array_to_ext(arr: np.ndarray) -> msgpack.ExtType:
    dtype = arr.dtype.newbyteorder("<") if arr.dtype.byteorder == ">" else arr.dtype
    if dtype.str not in ALLOWED_DTYPES:
        raise CodecError(f"arrays of dtype {arr.dtype} cannot be sent; use one of numeric/bool")
    shape = arr.shape  # before ascontiguousarray, which turns 0-d into 1-d
    arr = np.ascontiguousarray(arr, dtype=dtype)
    return msgpack.ExtType(ARRAY_EXT, _header(dtype.str, shape) + arr.tobytes())


@functools.lru_cache(maxsize=256)
def _header(dtype: str, shape: tuple[int, ...]) -> bytes:
    """An array extension's length-prefixed header: the same few shapes every tick."""
    header = msgpack.packb([dtype, list(shape)])
    return bytes([len(header)]) + header


def _ext_to_array(code: int, data: bytes) -> Any:
    if code != ARRAY_EXT:
        raise CodecError(f"unknown msgpack extension type {code}")
    try:
        hlen = data[0]
        dtype, shape = _parsed_header(data[1 : 1 + hlen])
        arr = np.frombuffer(data, dtype=dtype, offset=1 + hlen)
        return arr.reshape(shape)
    except CodecError:
        raise
    except Exception as exc:
        raise CodecError(f"malformed array extension: {exc}") from None


@functools.lru_cache(maxsize=256)
def _parsed_header(header: bytes) -> tuple[np.dtype, tuple[int, ...]]:
    """An array extension's dtype and shape, checked; the same few headers arrive every tick
    (a refused one raises, and is not kept)."""
    dtype_str, shape = msgpack.unpackb(header)
    if dtype_str not in ALLOWED_DTYPES:
        raise CodecError(f"array dtype {dtype_str!r} is not allowed")
    if not isinstance(shape, list) or not all(type(n) is int and n >= 0 for n in shape):
        raise CodecError(f"malformed array extension: shape {shape!r}")
    return np.dtype(dtype_str), tuple(shape)


def _default(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        return _array_to_ext(obj)
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"cannot encode {type(obj).__name__}")


def pack(value: Any) -> bytes:
    """Encode plain data (dicts, lists, numbers, strings, arrays)."""
    return msgpack.packb(value, default=_default, use_bin_type=True)


def unpack(payload: bytes | bytearray | memoryview, *, max_map_len: int = -1) -> Any:
    """Decode plain data; arrays come back as zero-copy read-only views. `max_map_len`:
    a map with more entries is refused at its header, before any is read."""
    try:
        return msgpack.unpackb(
            bytes(payload), ext_hook=_ext_to_array, raw=False, max_map_len=max_map_len
        )
    except CodecError:
        raise
    except Exception as exc:
        if "exceeds max_map_len" in str(exc):
            entries = str(exc).split()[0]
            raise CodecError(f"a map of {entries} entries: a message has {max_map_len} fields "
                             "at most") from None  # fmt: skip
        more = " ..." if len(payload) > 8 else ""
        why = str(exc) or f"{type(exc).__name__} in bytes {bytes(payload[:8]).hex(' ')}{more}"
        raise CodecError(f"not a msgpack payload: {why}") from None


def encode(msg: Message) -> bytes:
    body = {f.name: getattr(msg, f.name) for f in dataclasses.fields(msg)}
    body["v"] = SCHEMA_VERSION
    body["type"] = msg.TYPE
    return pack(body)


def decode(payload: bytes | bytearray | memoryview, expect: type[M]) -> M:
    """Decode and validate a payload that must be a message of type `expect`."""
    body = unpack(payload, max_map_len=MAX_FIELDS)
    if not isinstance(body, dict):
        raise CodecError(f"payload is a {type(body).__name__}, expected a map")
    if "v" not in body:
        raise CodecError(f'no "v": every payload carries the schema version, {SCHEMA_VERSION}')
    version = body.pop("v")
    if type(version) is not int or version != SCHEMA_VERSION:  # not True: msgpack's true == 1
        raise CodecError(f"schema version {version!r} is not supported (this is {SCHEMA_VERSION})")
    wire = body.pop("type", None)
    if wire != expect.TYPE:
        known = ", ".join(sorted(MESSAGE_TYPES))
        raise CodecError(
            f"message type {wire!r} where {expect.TYPE!r} was expected (known: {known})"
        )
    return expect(**_validated_fields(expect, body))


def _validated_fields(cls: type[Message], body: dict[str, Any]) -> dict[str, Any]:
    specs = _field_specs(cls)
    if not body.keys() <= specs.keys():
        raise CodecError(f"{cls.TYPE}: unknown field(s) {_unknown(body, specs)} "
                         f"({expected_fields(cls)})")  # fmt: skip
    out: dict[str, Any] = {}
    for name, (kind, length, required) in specs.items():
        if name not in body:
            if required:
                raise CodecError(f"{cls.TYPE}: missing field {name!r} ({expected_fields(cls)})")
            continue
        out[name] = _check(cls.TYPE, name, kind, length, body[name])
    return out


def _unknown(body: dict[Any, Any], specs: dict[str, Any]) -> str:
    """The first few unknown keys, named in order, and how many more: a map of millions of
    keys took 8 s to sort and name, and a 10 MB log line, for one sample."""
    unknown = [k for k in body if k not in specs]
    shown = sorted(unknown[:SHOWN_UNKNOWN], key=repr)  # keys may mix str and bytes
    more = len(unknown) - len(shown)
    said = ", ".join(text if len(text := repr(k)) <= 40 else text[:37] + "..." for k in shown)
    return said + (f" and {more} more" if more else "")


def expected_fields(cls: type[Message]) -> str:
    """What a malformed payload should have carried, for the one who sent it: `fields:
    surge, yaw_rate; optional: tick, stamp_ns` (docs/MESSAGES.md has the rest)."""
    specs = fields_of(cls)
    needed = ", ".join(f.name for f in specs if f.required) or "none"
    optional = ", ".join(f.name for f in specs if not f.required)
    return f"fields: {needed}" + (f"; optional: {optional}" if optional else "")


_SPECS: dict[type[Message], dict[str, tuple[str, int | None, bool]]] = {}


def _field_specs(cls: type[Message]) -> dict[str, tuple[str, int | None, bool]]:
    if cls not in _SPECS:
        _SPECS[cls] = _build_specs(cls)
    return _SPECS[cls]


def _build_specs(cls: type[Message]) -> dict[str, tuple[str, int | None, bool]]:
    return {f.name: (f.kind, f.length, f.required) for f in fields_of(cls)}


def _check(type_name: str, name: str, kind: str, length: int | None, value: Any) -> Any:
    """Validate one field; the common cases return before any message is formatted."""
    simple = _SIMPLE.get(kind)
    if simple is not None and type(value) is simple:
        if kind != "int" or -INT64 <= value < INT64:  # type: ignore[operator]
            return value
        raise CodecError(f"{type_name}.{name}: {value} is beyond a 64-bit signed integer")
    where = f"{type_name}.{name}"
    if kind == "str" and isinstance(value, str):
        return value
    if kind == "float" and type(value) in (int, float):
        return float(value)
    if kind == "array" and isinstance(value, np.ndarray):
        return value
    if kind == "vector" and isinstance(value, list | tuple):
        if length is not None and len(value) != length:
            raise CodecError(f"{where}: expected {length} numbers, got {len(value)}")
        if not all(type(v) in (int, float) for v in value):
            raise CodecError(f"{where}: every entry must be a number")
        return tuple(float(v) for v in value)
    if kind == "names" and isinstance(value, list | tuple) and set(map(type, value)) <= {str}:
        return tuple(value)  # map(type): a batch's 356 ids in ~10 us, not ~300 us
    raise CodecError(f"{where}: expected {kind}, got {type(value).__name__}")


_SIMPLE = {"int": int, "str": str, "float": float}
INT64 = 2**63  # stamps, ticks and counts are int64 everywhere they are stored (CSV, MCAP)


def finite(values: tuple[float, ...] | float) -> bool:
    """True when no entry is NaN or infinite (commands must be refused otherwise)."""
    seq = values if isinstance(values, tuple) else (values,)
    return all(math.isfinite(v) for v in seq)
