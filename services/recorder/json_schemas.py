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
from typing import Any

import numpy as np

from catabot.bus.fields import FieldSpec, fields_of
from catabot.bus.messages import Message


def schema_name(cls: type[Message]) -> str:
    """Schema names are namespaced so they never collide with ROS or Foxglove types."""
    return f"catabot.{cls.__name__}"


ARRAY_SCHEMA = {
    "type": "object",
    "properties": {
        "dtype": {"type": "string"},
        "shape": {"type": "array", "items": {"type": "integer"}},
        "data": {"type": "string", "contentEncoding": "base64"},
    },
}
SCALARS = {"int": "integer", "float": "number", "str": "string", "bool": "boolean"}


def _field_schema(f: FieldSpec) -> dict[str, Any]:
    """JSON Schema of one field; units and axis names go into its description."""
    described: dict[str, Any] = {"description": f"unit: {f.unit}"} if f.unit else {}
    if f.kind == "array":
        return ARRAY_SCHEMA
    if f.kind in ("vector", "names"):
        items = "string" if f.kind == "names" else "number"
        out = {**described, "type": "array", "items": {"type": items}}
        if f.axes is not None:
            out.update(minItems=len(f.axes), maxItems=len(f.axes))
            unit = f"; unit: {f.unit}" if f.unit else ""
            out["description"] = f"axes: {', '.join(f.axes)}{unit}"
        return out
    return {**described, "type": SCALARS.get(f.kind, "string")}


def _summary(cls: type[Message]) -> str:
    """First line of the class's own docstring (not the signature dataclass makes up)."""
    doc = (cls.__dict__.get("__doc__") or "").strip()
    return "" if doc.startswith(cls.__name__ + "(") else doc.split("\n", 1)[0]


def json_schema(cls: type[Message]) -> dict[str, Any]:
    """A JSON Schema of `cls` from its dataclass fields (non-finite floats are written null)."""
    fields = fields_of(cls)
    return {
        "title": schema_name(cls),
        "description": _summary(cls),
        "type": "object",
        "properties": {f.name: _field_schema(f) for f in fields},
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
