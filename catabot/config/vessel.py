"""Vessel model files: hull geometry, mass properties, damping, thruster layout and shape.

A vessel model is its own JSON file (DESIGN.md §6), referenced from a scenario by a bundled
name (`"catabot"`, `"wamv"`) or by a path. The schema is strict (`extra="forbid"`) so that a
misspelt key is an error, not a silently ignored setting; new optional fields (added mass,
wind area, the shape sensors see: catabot/config/vessel_shape.py) extend it without
breaking existing files.

Frames and units (DESIGN.md §2): body frame FLU (x forward, y left, z up) with its origin at
the waterline-level reference point on the centreline; SI units, named in the field names.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BeforeValidator, Field, ValidationError, field_validator, model_validator
from pydantic.types import FiniteFloat

from catabot.config.base import ConfigError, FieldProblem, Strict, explain, read_json
from catabot.config.vessel_shape import HullPart, Shape
from catabot.config.waves import GRAVITY

BUNDLED_DIR = Path(__file__).parents[1] / "data" / "vessels"


def _length(n: int, what: str = "") -> BeforeValidator:
    """Reject a list of the wrong length with one message for the field, not one per item."""

    def check(value: Any) -> Any:
        if not isinstance(value, list | tuple) or len(value) != n:
            raise ValueError(f"must be a list of {n} numbers{what}")
        return value

    return BeforeValidator(check)


PositiveFloat = Annotated[FiniteFloat, Field(gt=0)]
NonNegativeFloat = Annotated[FiniteFloat, Field(ge=0)]
Vec3 = Annotated[tuple[FiniteFloat, FiniteFloat, FiniteFloat], _length(3, " [x, y, z]")]
Inertia3 = Annotated[
    tuple[PositiveFloat, PositiveFloat, PositiveFloat], _length(3, " [Ixx, Iyy, Izz]")
]
_N = NonNegativeFloat
_Six = tuple[_N, _N, _N, _N, _N, _N]
Dof6 = Annotated[_Six, _length(6, " [X_u, Y_v, Z_w, K_p, M_q, N_r]")]
AddedMass6 = Annotated[_Six, _length(6, " [X_udot, Y_vdot, Z_wdot, K_pdot, M_qdot, N_rdot]")]
WindCoefficients3 = Annotated[
    tuple[NonNegativeFloat, NonNegativeFloat, FiniteFloat], _length(3, " [C_x, C_y, C_n]")
]


class VesselModelError(ConfigError):
    """A vessel model file is missing, unreadable or invalid; the message names file and field."""


COLUMNS = (
    "buoyancy columns along (x) or across (y) the hull, at Gauss-Legendre points: a "
    "box's waterplane area and moments are exact at any count; across: 2 for a box, "
    "10 for a cylinder by default"
)


class Hull(Strict):
    """A parametric hull, discretised into vertical columns for buoyancy.

    `beam_m` is a box's width or a cylinder's diameter; a cylinder lies along body x.
    `columns_along` / `columns_across` set the buoyancy discretisation (None: a default per
    shape, more across for cylinders because their cross-section is curved;
    services/physics/hydro.py places them).
    """

    shape: Literal["box", "cylinder"]
    center_m: Vec3
    length_m: PositiveFloat
    beam_m: PositiveFloat
    height_m: PositiveFloat | None = None
    columns_along: Annotated[int, Field(ge=1, le=256, description=COLUMNS)] = 16
    columns_across: Annotated[int, Field(ge=1, le=64, description=COLUMNS)] | None = None

    @model_validator(mode="after")
    def _shape_fields(self) -> Hull:
        if self.shape == "box" and self.height_m is None:
            raise FieldProblem("height_m", "required when shape is 'box'")
        if self.shape == "cylinder" and self.height_m is not None:
            raise FieldProblem(
                "height_m", "only for shape 'box' (a cylinder's height is its beam_m)"
            )
        return self

    @property
    def vertical_extent_m(self) -> float:
        """Full height of the hull along body z."""
        return self.height_m if self.height_m is not None else self.beam_m

    @property
    def volume_m3(self) -> float:
        """What the hull displaces wholly under water."""
        if self.shape == "box":
            return self.length_m * self.beam_m * self.vertical_extent_m
        return self.length_m * math.pi * (self.beam_m / 2) ** 2

    @property
    def across(self) -> int:
        if self.columns_across is not None:
            return self.columns_across
        return 2 if self.shape == "box" else 10


class Damping(Strict):
    """Fossen damping per DOF [X_u, Y_v, Z_w, K_p, M_q, N_r]: tau = -(linear + quadratic*|v|)*v,
    and the hull's lift in a sideslip, `lift_uv` [Y_uv, N_uv]: Y += Y_uv |u| v, N += N_uv u v
    (u, v surge and sway through the water).

    Why lift: added mass brings the ideal fluid's Munk moment -(A22 - A11) u v, which turns
    a drifting hull broadside; a real hull's flow separates at its stern, and the lift there
    cancels much of it. Without it a boat with added mass is straight-line unstable above
    sqrt(Y_v N_r / ((m + A11) (A22 - A11))) (`scenario validate MODEL.json` says so).

    Units: linear N·s/m (surge, sway, heave) and N·m·s/rad (roll, pitch, yaw); quadratic
    N·s²/m² and N·m·s²/rad²; Y_uv N·s²/m² (< 0 resists the sideslip), N_uv kg (> 0 turns the
    bow into the sideslip, against the Munk moment).
    """

    linear: Dof6
    quadratic: Dof6
    lift_uv: tuple[Annotated[FiniteFloat, Field(le=0)], FiniteFloat] = Field(
        (0.0, 0.0), description="[Y_uv <= 0, N_uv]: Y += Y_uv |u| v (N s^2/m^2), N += N_uv u v (kg)"
    )  # Y_uv > 0 pushed a hull along its sideslip: negative sway damping above |u| = Y_v / Y_uv


class Thruster(Strict):
    """A fixed thruster; `yaw_rad` turns its thrust direction in the body xy plane (0: forward).

    A command c in [-1, 1] asks for c*max_forward_n (c >= 0) or c*max_reverse_n (c < 0);
    the delivered force follows with a first-order lag of `time_constant_s` (0: none).
    It pushes only while it is below the water surface (services/physics/wet.py), so
    `position_m` is below the waterline (z < 0, the body origin being at the waterline).
    """

    position_m: Vec3

    @field_validator("position_m")
    @classmethod
    def _below_the_waterline(cls, value: tuple[float, float, float]) -> tuple[float, ...]:
        if value[2] >= 0.0:
            raise ValueError(
                f"z = {value[2]:g} m: a thruster pushes only under water; put it below the "
                "waterline (z < 0)"
            )
        return value

    yaw_rad: FiniteFloat = 0.0
    max_forward_n: NonNegativeFloat
    max_reverse_n: NonNegativeFloat
    time_constant_s: NonNegativeFloat = 0.0


class WindArea(Strict):
    """Above-water windage: areas and drag coefficients (Fossen 2011 §10.1, simplified).

    With (u_a, v_a) the apparent wind (air velocity relative to the vessel, body frame),
    rho_a the air density, V_a^2 = u_a^2 + v_a^2 and gamma = atan2(v_a, u_a):
        X = 1/2 rho_a A_F C_x u_a |u_a|
        Y = 1/2 rho_a A_L C_y v_a |v_a|
        N = -1/2 rho_a A_L L C_n V_a^2 sin(2 gamma)   ( = -rho_a A_L L C_n u_a v_a )
    i.e. VRX's wind law with its lumped coefficients split into 1/2 rho_a A C. C_n > 0 turns
    the bow away from the wind (bow falls off downwind), as for a slender hull (Munk moment).
    Applied at the body origin: no heeling moment.
    """

    frontal_area_m2: NonNegativeFloat
    lateral_area_m2: NonNegativeFloat
    coefficients: WindCoefficients3
    length_m: PositiveFloat


MAX_THRUST_TO_WEIGHT = 100.0  # refused beyond: a unit slip (N as kN: x1000); over 5 a note


class VesselModel(Strict):
    """One vessel model file. Inertia is about the centre of gravity, in body axes."""

    name: Annotated[str, Field(min_length=1)]
    description: str = ""
    mass_kg: PositiveFloat
    inertia_kgm2: Inertia3
    cog_m: Vec3
    hulls: Annotated[list[Hull], Field(min_length=1)]
    damping: Damping
    thrusters: list[Thruster] = Field(default_factory=list)
    # Added mass magnitudes (>= 0, i.e. -X_udot ...), diagonal, about the body origin (kg, kg m^2).
    added_mass: AddedMass6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    wind: WindArea | None = None  # None: the wind exerts no force on this vessel
    shape: Shape | None = None  # what sensors see (catabot/config/vessel_shape.py); None: hull box

    @model_validator(mode="after")
    def _physical_inertia(self) -> VesselModel:
        ixx, iyy, izz = self.inertia_kgm2
        if ixx + iyy < izz or iyy + izz < ixx or izz + ixx < iyy:
            raise FieldProblem(
                "inertia_kgm2",
                "principal moments must satisfy the triangle inequality "
                f"(Ixx + Iyy >= Izz and cyclic), got {list(self.inertia_kgm2)}",
            )
        return self

    @model_validator(mode="after")
    def _plausible_thrust(self) -> VesselModel:
        """Thrust in another unit than the mass (kN, tonnes): 1 GN on a 55 kg boat passed,
        and its first tick ended the run blaming buoyancy. Over 5 times the weight is a note
        (world/model_checks.py): a 2 kg hull with two 51 N thrusters is 5.2."""
        weight = self.mass_kg * GRAVITY
        for field, total in self.thrust_totals().items():
            if total > MAX_THRUST_TO_WEIGHT * weight:
                forces = [getattr(t, field) for t in self.thrusters]
                raise FieldProblem(
                    f"thrusters.{int(np.argmax(forces))}.{field}",
                    f"the thrusters together give {total:g} N, {total / weight:.3g} "
                    f"times the boat's weight ({weight:.4g} N for mass_kg {self.mass_kg:g}), "
                    f"over {MAX_THRUST_TO_WEIGHT:g}: the thrust (N) or mass_kg in another unit?",
                )
        return self

    @model_validator(mode="after")
    def _righting_columns(self) -> VesselModel:
        """Buoyancy columns all on one line give no righting moment about it: an audit's
        monohull with `columns_across: 1` fell from a 3 degree heel onto its side."""
        for i, field, turn in ((1, "columns_across", "roll"), (0, "columns_along", "pitch")):
            count = max(h.across if i else h.columns_along for h in self.hulls)
            if count == 1 and len({h.center_m[i] for h in self.hulls}) == 1:
                raise FieldProblem(f"hulls.0.{field}", f"every buoyancy column lies at "
                                   f"{'xy'[i]} = {self.hulls[0].center_m[i]:g}, one line: no "
                                   f"righting moment in {turn}; give a hull 2 or more")  # fmt: skip
        return self

    def thrust_totals(self) -> dict[str, float]:
        """Every thruster's force summed (N): the refusal above and model_checks.py's note."""
        return {f: float(sum(getattr(t, f) for t in self.thrusters))
                for f in ("max_forward_n", "max_reverse_n")}  # fmt: skip

    @model_validator(mode="after")
    def _shape_hulls(self) -> VesselModel:
        """A `hull` part names one of this model's hulls, and its bow fits on it."""
        parts = self.shape.parts if self.shape is not None and self.shape.parts else []
        for i, part in enumerate(parts):
            if not isinstance(part, HullPart):
                continue
            where = f"shape.parts.{i}"
            if part.hull >= len(self.hulls):
                raise FieldProblem(
                    f"{where}.hull",
                    f"must name one of the {len(self.hulls)} hulls (0 to {len(self.hulls) - 1}), "
                    f"got {part.hull}",
                )
            if part.bow_m > self.hulls[part.hull].length_m:
                length = self.hulls[part.hull].length_m
                raise FieldProblem(
                    f"{where}.bow_m", f"must be at most the hull's length ({length:g})"
                )
        return self

    def sinks_in(self, density: float) -> str:
        """Why this model cannot float in water of `density` kg/m^3 ("" if it can): heavier
        than its hulls displace wholly under, it sinks to the bottom, and no figure of a run
        says so (a mass typed with an extra zero)."""
        most = density * sum(h.volume_m3 for h in self.hulls)
        if self.mass_kg <= most:
            return ""
        return (f"cannot float: its mass {self.mass_kg:g} kg is more than its hulls displace "
                f"wholly under water ({most:.0f} kg in water of {density:g} kg/m^3)")  # fmt: skip

    def hull_box(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The axis-aligned body-frame box (lo, hi corners, m) around every hull: the body's
        collision shape in physics, and what sensors see of a model without a `shape`."""
        centre = np.array([h.center_m for h in self.hulls], dtype=np.float64)
        half = np.array([(h.length_m, h.beam_m, h.vertical_extent_m) for h in self.hulls]) / 2
        return (centre - half).min(axis=0), (centre + half).max(axis=0)


def bundled_vessel_names() -> list[str]:
    """Names of the vessel models shipped with catabot."""
    return sorted(p.stem for p in BUNDLED_DIR.glob("*.json"))


def load_vessel_model(ref: str, *, base_dir: Path | None = None) -> VesselModel:
    """Load a vessel model by bundled name or JSON path (relative to `base_dir` if given)."""
    path = _resolve(ref, base_dir)
    data = read_json(path, what=f"vessel model '{ref}':", error=VesselModelError)
    return parse_vessel_model(data, source=ref, base_dir=path.parent)


def parse_vessel_model(
    data: Any, *, source: str = "<data>", base_dir: Path | None = None
) -> VesselModel:
    """Validate already-decoded JSON data; errors name `source`, the field path and the rule.
    A shape's mesh file is made absolute against `base_dir` (the model file's folder; the
    current directory if None) and must exist: every process then finds the same file."""
    if not isinstance(data, dict):
        raise VesselModelError(
            f"vessel model '{source}': must be a JSON object (got {type(data).__name__})"
        )
    try:
        model = VesselModel.model_validate(data)
    except ValidationError as exc:
        message = explain(exc, model=VesselModel)
        raise VesselModelError(f"vessel model '{source}': {message}") from None
    return _absolute_mesh(model, source, base_dir)


def _absolute_mesh(model: VesselModel, source: str, base_dir: Path | None) -> VesselModel:
    shape = model.shape
    if shape is None or shape.mesh is None:
        return model
    mesh = shape.mesh
    path = Path(mesh.file)
    if not path.is_absolute():
        path = (base_dir or Path.cwd()) / path
    if not path.is_file():
        raise VesselModelError(
            f"vessel model '{source}': shape.mesh.file: no such file {str(path)!r}"
        )
    placed = mesh.model_copy(update={"file": str(path)})
    return model.model_copy(update={"shape": shape.model_copy(update={"mesh": placed})})


def _resolve(ref: str, base_dir: Path | None) -> Path:
    """A bare name (no separator, no .json suffix) is bundled; anything else is a path."""
    is_path = ref.endswith(".json") or "/" in ref or "\\" in ref
    if not is_path:
        path = BUNDLED_DIR / f"{ref}.json"
        if not path.is_file():
            names = ", ".join(bundled_vessel_names())
            raise VesselModelError(
                f"vessel model '{ref}': unknown bundled name (bundled: {names}); "
                "give a path ending in .json to load a file"
            )
        return path
    path = Path(ref)
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    return path
