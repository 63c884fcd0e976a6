"""JSON encoding and JSON Schema of bus messages, for MCAP channels without a ROS 2 type.

The schema is derived from the dataclass fields and their metadata (unit, axes) so that it
cannot drift from the messages; Foxglove Studio uses it to browse and plot every field.
JSON has no NaN or infinity, so non-finite floats are written as null; bulk NumPy arrays are
`{dtype, shape, data}` with base64 data (recorded images belong in `dataset/`, not here).
"""

from __future__ import annotations

import base64
import dataclasses
import json
import math
import typing
from typing import Any

import numpy as np

from catabot.bus.messages import Message


def schema_name(cls: type[Message]) -> str:
    """Schema names are namespaced so they never collide with ROS or Foxglove types."""
    return f"catabot.{cls.__name__}"


def _field_schema(hint: Any, meta: typing.Mapping[str, Any]) -> dict[str, Any]:
    """JSON Schema of one field; units and axis names go into its description."""
    unit, axes = meta.get("unit", ""), meta.get("axes")
    described: dict[str, Any] = {"description": f"unit: {unit}"} if unit else {}
    if hint is np.ndarray:
        return {
            "type": "object",
            "properties": {
                "dtype": {"type": "string"},
                "shape": {"type": "array", "items": {"type": "integer"}},
                "data": {"type": "string", "contentEncoding": "base64"},
            },
        }
    if typing.get_origin(hint) is tuple:
        out = {**described, "type": "array", "items": {"type": "number"}}
        if axes is not None:
            out.update(minItems=len(axes), maxItems=len(axes))
            out["description"] = f"axes: {', '.join(axes)}" + (f"; unit: {unit}" if unit else "")
        return out
    kinds = {int: "integer", float: "number", str: "string", bool: "boolean"}
    return {**described, "type": kinds.get(hint, "string")}


def _summary(cls: type[Message]) -> str:
    """First line of the class's own docstring (not the signature dataclass makes up)."""
    doc = (cls.__dict__.get("__doc__") or "").strip()
    return "" if doc.startswith(cls.__name__ + "(") else doc.split("\n", 1)[0]


def json_schema(cls: type[Message]) -> dict[str, Any]:
    """A JSON Schema of `cls` from its dataclass fields (non-finite floats are written null)."""
    hints = typing.get_type_hints(cls)
    fields = dataclasses.fields(cls)
    return {
        "title": schema_name(cls),
        "description": _summary(cls),
        "type": "object",
        "properties": {f.name: _field_schema(hints[f.name], f.metadata) for f in fields},
        "required": [f.name for f in fields],
    }


def _jsonable(value: Any) -> Any:
    """Plain JSON values: tuples as lists, NumPy scalars as Python numbers."""
    if isinstance(value, np.ndarray):
        arr = np.ascontiguousarray(value)
        data = base64.b64encode(arr.tobytes()).decode("ascii")
        return {"dtype": arr.dtype.str, "shape": list(arr.shape), "data": data}
    if isinstance(value, tuple | list):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None  # JSON has no NaN/inf; null keeps the file readable by every tool
    return value


def encode(msg: Message) -> bytes:
    """Compact, field-ordered JSON: the same message always gives the same bytes."""
    body = {f.name: _jsonable(getattr(msg, f.name)) for f in dataclasses.fields(msg)}
    return json.dumps(body, separators=(",", ":"), allow_nan=False).encode()
