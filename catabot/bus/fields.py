"""The fields of every message, read once from the dataclasses: the one description of a
message's shape that the codec (validation), the recorder's CSV layout and its JSON Schema
all use, so they cannot disagree.

Kinds: "int", "float", "str", "bool" (scalars); "vector" (a tuple of floats: fixed length
with axis names, or variable with `axes` None); "names" (a tuple of strings, a batch's ids);
"array" (a NumPy array: bulk data).
"""

from __future__ import annotations

import dataclasses
import typing
from dataclasses import dataclass

import numpy as np

from catabot.bus.messages import Message


@dataclass(frozen=True)
class FieldSpec:
    name: str
    kind: str
    unit: str
    axes: tuple[str, ...] | None  # a vector's axis names; None: its length is the data's
    required: bool  # no default: every payload must carry it
    summary: tuple[str, str] | None = None  # an array's one CSV column: (name, "len"|"count")

    @property
    def length(self) -> int | None:
        """A fixed-length vector's length (None for everything else)."""
        return len(self.axes) if self.kind == "vector" and self.axes else None


_FIELDS: dict[type[Message], tuple[FieldSpec, ...]] = {}


def fields_of(cls: type[Message]) -> tuple[FieldSpec, ...]:
    """The fields of `cls` in declaration order (read once per class, then cached)."""
    found = _FIELDS.get(cls)
    if found is None:
        found = _FIELDS[cls] = tuple(_spec(f, hint) for f, hint in _hinted(cls))
    return found


def _hinted(cls: type[Message]) -> list[tuple[dataclasses.Field[object], typing.Any]]:
    hints = typing.get_type_hints(cls)
    return [(f, hints[f.name]) for f in dataclasses.fields(cls)]


def _spec(f: dataclasses.Field[object], hint: typing.Any) -> FieldSpec:
    required = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    unit, axes = str(f.metadata.get("unit", "")), f.metadata.get("axes")
    if hint is np.ndarray:
        return FieldSpec(f.name, "array", unit, None, required, f.metadata.get("summary"))
    if typing.get_origin(hint) is tuple:
        kind = "names" if typing.get_args(hint)[0] is str else "vector"
        return FieldSpec(f.name, kind, unit, tuple(axes) if axes else None, required)
    return FieldSpec(f.name, hint.__name__, unit, (), required)
