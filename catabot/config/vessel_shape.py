"""A vessel model's shape: what the ray-casting sensors (LiDAR, radar, camera) and the viewer
see of the vessel, as opposed to its buoyancy hulls (what floats it) and its hull box (what
physics collides).

A model names its shape in one of two ways:
- `{"mesh": {"file": "boat.obj", "scale": 0.01, "rpy_deg": [90, 0, 90], "offset_m": [0, 0, -0.2]}}`:
  a triangle mesh file (OBJ, STL or glTF, read by open3d), its path relative to the model
  file; a vertex v of the file is placed at R(rpy) (scale * v) + offset in the body frame
  (FLU); R turns by roll about x, then pitch about y, then yaw about z, in degrees. glTF
  files are Y-up with +Z forward, which `rpy_deg: [90, 0, 90]` turns into FLU.
- `{"parts": [...]}`: primitives in the body frame, built into one mesh when a run needs it
  (catabot/world/shape_parts.py). A `hull` part is one of the model's own buoyancy hulls,
  read from the same numbers physics floats, so shape and buoyancy cannot drift apart; a
  `box`, a `cylinder` (along x, y or z) and a `vhull` (a V-bottomed monohull, its bow
  tapered to a vertical stem) add what the hulls leave out (decks, cabins, frames).

A model without `shape` is seen as its hull box. Every field is checked here, strictly
(`Strict`: unknown keys refused); the mesh file itself (readable, non-empty, finite) is read
and checked where a run is prepared (catabot/world/shapes.py), not by every process that
loads the model.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BeforeValidator, Field, WithJsonSchema, field_validator, model_validator
from pydantic.types import FiniteFloat

from catabot.config.base import FieldProblem, Strict

MESH_SUFFIXES = (".obj", ".stl", ".gltf", ".glb")
PositiveFloat = Annotated[FiniteFloat, Field(gt=0)]
NonNegativeFloat = Annotated[FiniteFloat, Field(ge=0)]


def _three(what: str, *, number_ok: bool = False) -> BeforeValidator:
    """A list of 3 numbers (or, `number_ok`, one number meaning it 3 times), one message
    for the field rather than one per item."""

    def check(value: Any) -> Any:
        if number_ok and isinstance(value, int | float) and not isinstance(value, bool):
            return (value, value, value)
        if not isinstance(value, list | tuple) or len(value) != 3:
            alternative = "a number or " if number_ok else ""
            raise ValueError(f"must be {alternative}a list of 3 numbers {what}")
        return value

    return BeforeValidator(check)


Vec3 = Annotated[tuple[FiniteFloat, FiniteFloat, FiniteFloat], _three("[x, y, z]")]
Size3 = Annotated[
    tuple[PositiveFloat, PositiveFloat, PositiveFloat], _three("[length x, width y, height z]")
]
_POSITIVE = {"type": "number", "exclusiveMinimum": 0}
Scale3 = Annotated[
    tuple[PositiveFloat, PositiveFloat, PositiveFloat],
    _three("[x, y, z]", number_ok=True),
    WithJsonSchema({  # the schema said array only, and flagged the README's own example
        "anyOf": [_POSITIVE, {"type": "array", "items": _POSITIVE, "minItems": 3, "maxItems": 3}],
        "description": "one factor for every axis (0.001: a file in millimetres), or [x, y, z]",
    }),
]  # fmt: skip
Rpy3 = Annotated[tuple[FiniteFloat, FiniteFloat, FiniteFloat], _three("[roll, pitch, yaw]")]


class MeshFile(Strict):
    """A triangle mesh file and where its vertices go in the body frame."""

    file: Annotated[str, Field(min_length=1)]
    scale: Scale3 = (1.0, 1.0, 1.0)
    rpy_deg: Rpy3 = (0.0, 0.0, 0.0)
    offset_m: Vec3 = (0.0, 0.0, 0.0)

    @field_validator("file")
    @classmethod
    def _known_format(cls, value: str) -> str:
        if not value.lower().endswith(MESH_SUFFIXES):
            raise ValueError(f"must be an OBJ, STL or glTF file ({', '.join(MESH_SUFFIXES)})")
        return value


class HullPart(Strict):
    """Buoyancy hull `hull` (its index in `hulls`) as it is, the front `bow_m` of it
    tapered to a point: a box to a vertical wedge, a cylinder to a cone (0: square)."""

    type: Literal["hull"]
    hull: Annotated[int, Field(ge=0)]
    bow_m: NonNegativeFloat = 0.0


class BoxPart(Strict):
    """An axis-aligned box (a deck, a cabin, a frame member)."""

    type: Literal["box"]
    center_m: Vec3
    size_m: Size3


class CylinderPart(Strict):
    """A closed cylinder along a body axis (a buoy, a mast, a tube)."""

    type: Literal["cylinder"]
    center_m: Vec3
    axis: Literal["x", "y", "z"]
    length_m: PositiveFloat
    diameter_m: PositiveFloat


class VHullPart(Strict):
    """A monohull: V bottom from the keel (on the centreline) up to the chines, vertical
    sides up to the deck, full beam from the transom at `stern_x_m` until the last `bow_m`,
    which narrows to a vertical stem."""

    type: Literal["vhull"]
    stern_x_m: FiniteFloat
    length_m: PositiveFloat
    beam_m: PositiveFloat
    keel_z_m: FiniteFloat
    chine_z_m: FiniteFloat
    deck_z_m: FiniteFloat
    bow_m: NonNegativeFloat = 0.0
    center_y_m: FiniteFloat = 0.0

    @model_validator(mode="after")
    def _ordered(self) -> VHullPart:
        if not self.keel_z_m < self.chine_z_m:
            raise FieldProblem("chine_z_m", "must be above keel_z_m")
        if not self.chine_z_m < self.deck_z_m:
            raise FieldProblem("deck_z_m", "must be above chine_z_m")
        if self.bow_m > self.length_m:
            raise FieldProblem("bow_m", f"must be at most length_m ({self.length_m:g})")
        return self


Part = Annotated[HullPart | BoxPart | CylinderPart | VHullPart, Field(discriminator="type")]


class Shape(Strict):
    """Exactly one of `mesh` (a file) and `parts` (primitives)."""

    mesh: MeshFile | None = None
    parts: Annotated[list[Part], Field(min_length=1, max_length=256)] | None = None

    @model_validator(mode="after")
    def _one_kind(self) -> Shape:
        if (self.mesh is None) == (self.parts is None):
            raise FieldProblem("mesh", "give exactly one of 'mesh' (a file) and 'parts'")
        return self
