"""What a vessel model file's figures imply, said by `catabot scenario validate MODEL.json`.

Why: a boat designer's mistakes that no field's own limit catches passed validation and ran
without a word: a mesh in millimetres (a 4 km shape), a Y-up mesh standing on its transom, a
mass typed in tonnes (0.4 kg thrown 490 m up on its first tick), added mass in tonnes, a
thruster ahead of the bow. These notes compare the model's figures with each other (the
hulls against the mesh, the mass against the added mass and the inertia) and say what the
numbers look like; a note refuses nothing, as such a boat may be meant.
"""

from __future__ import annotations

import math

import numpy as np

from catabot.config.vessel import VesselModel
from catabot.config.waves import GRAVITY
from catabot.world.course import top_speed_mps, unstable_above_mps
from catabot.world.shapes import vessel_mesh
from catabot.world.stability import metacentric_heights

THRUST_TO_WEIGHT = 5.0  # over this a note: racing craft stay under 2, a jet ski near 1
SPREAD = 3.0  # a mesh this many times larger (or smaller) than the hulls is suspect
THRUSTER_ROOM_M = 0.5  # a thruster this far outside every hull's box is suspect
TINY_GYRATION = 0.02  # of the length: the bundled models' smallest is 0.10


def displacement(model: VesselModel, density: float) -> str:
    """How much of its hulls' volume the model needs under water to float."""
    needed = model.mass_kg / density
    whole = sum(h.volume_m3 for h in model.hulls)
    return (
        f"in water of {density:g} kg/m^3 it floats with {needed:.3g} m^3 under, "
        f"{100 * needed / whole:.0f} % of its hulls' volume"
    )


def model_notes(model: VesselModel, *, source: str, density: float) -> list[str]:
    """`density`: of the water it is said to float in (kg/m^3)."""
    return [*_mesh(model, source), *_thrusters(model), *_masses(model), *_course(model),
            *_balance(model), *_stability(model, density)]  # fmt: skip


def _stability(model: VesselModel, density: float) -> list[str]:
    """A centre of gravity above the metacentre (stability.py): it capsizes at rest."""
    heights = metacentric_heights(model, density)
    return [f"its metacentric height in {axis} is {gm:.3g} m (floating upright): its "
            f"centre of gravity (z {model.cog_m[2]:g} m) is above its metacentre "
            f"(z {model.cog_m[2] + gm:.3g} m), so it capsizes; lower cog_m or spread the hulls"
            for axis, gm in zip(("roll", "pitch"), heights, strict=True) if gm < 0]  # fmt: skip


def _balance(model: VesselModel) -> list[str]:
    """Where it floats: a centre of gravity beyond the hulls (a trial's model, 5 m forward on
    a 4.4 m boat, capsized in 2 s), hulls above the waterline z = 0 of the body frame."""
    lo, hi = model.hull_box()
    (x, y, _), notes = model.cog_m, []
    if not (lo[0] <= x <= hi[0] and lo[1] <= y <= hi[1]):
        notes.append(f"its centre of gravity ({x:g}, {y:g}) m lies outside every hull in plan "
                     "view: it floats heeled or trimmed over, or capsizes")  # fmt: skip
    if lo[2] > 0.0:
        notes.append(f"its hulls' bottom is {lo[2]:g} m above z = 0, the waterline at "
                     "rest (body frame): it sinks to float, thrusters and mounts too")  # fmt: skip
    return notes


def _course(model: VesselModel) -> list[str]:
    """A boat that cannot hold a straight course at speeds it reaches (course.py)."""
    top, limit = top_speed_mps(model), unstable_above_mps(model)
    if limit >= top:
        return []
    reach = (f"below its top speed ({top:.2f} m/s)" if math.isfinite(top) else
             "and has no top speed (no surge damping nor wind areas)")  # fmt: skip
    return [f"it cannot hold a straight course above {limit:.2f} m/s, {reach}: the added "
            "mass's Munk moment (A22 - A11) u v outgrows the sway and yaw damping Y_v N_r; "
            "give the hull's lift damping.lift_uv [Y_uv, N_uv] (N_uv > 0 cancels the Munk "
            "moment) or more yaw damping"]  # fmt: skip


def _mesh(model: VesselModel, source: str) -> list[str]:
    """The shape the sensors see against the hulls physics floats (units, orientation)."""
    mesh = vessel_mesh(model, source=source)
    if mesh is None:
        return []
    lo, hi = model.hull_box()
    hulls, shape = hi - lo, mesh.hi - mesh.lo
    ratio = float(np.max(shape) / np.max(hulls))
    notes = []
    if not 1 / SPREAD <= ratio <= SPREAD:
        notes.append(f"its mesh is {ratio:.3g} times the size of its hulls ({np.max(shape):.3g} "
                     f"against {np.max(hulls):.3g} m): a file in mm or cm wants `scale` "
                     "0.001 or 0.01")  # fmt: skip
    if int(np.argmax(shape)) != int(np.argmax(hulls)):
        axes = "xyz"
        notes.append(f"its mesh is longest along {axes[int(np.argmax(shape))]}, its hulls "
                     f"along {axes[int(np.argmax(hulls))]}: a Y-up file wants `rpy_deg` "
                     "[90, 0, 90] (body frame: x forward, y left, z up)")  # fmt: skip
    return notes


def _thrusters(model: VesselModel) -> list[str]:
    lo, hi = model.hull_box()
    notes, weight = [], model.mass_kg * GRAVITY
    push = max(model.thrust_totals().values())
    if push > THRUST_TO_WEIGHT * weight:
        notes.append(f"its thrusters together push {push:g} N, {push / weight:.3g} times its "
                     f"weight: racing craft stay under 2 (thrust in N, mass in kg?)")  # fmt: skip
    for i, t in enumerate(model.thrusters):
        x, y, _ = t.position_m
        off = max(lo[0] - x, x - hi[0], lo[1] - y, y - hi[1])
        if off > THRUSTER_ROOM_M:
            notes.append(f"thruster {i} at ({x:g}, {y:g}) m is {off:.2f} m outside every hull "
                         "in plan view (body frame: x forward, y left)")  # fmt: skip
    return notes


def _masses(model: VesselModel) -> list[str]:
    """Units: the added mass against the mass, the radii of gyration against the hulls."""
    lo, hi = model.hull_box()
    size = float(np.max(hi - lo))
    notes = []
    heave = model.added_mass[2]
    if heave > 10 * model.mass_kg or 0 < heave < 0.01 * model.mass_kg:
        notes.append(f"its heave added mass ({heave:g} kg) is {heave / model.mass_kg:.3g} times "
                     "its mass (a hull's is near its own): one of them in the wrong unit (kg, "
                     "not tonnes)?")  # fmt: skip
    for axis, inertia in zip("xyz", model.inertia_kgm2, strict=True):
        radius = float(np.sqrt(inertia / model.mass_kg))
        if radius > size:
            notes.append(f"its radius of gyration about {axis} is {radius:.3g} m, more than "
                         f"its length ({size:.3g} m): mass in tonnes, or inertia in another "
                         "unit?")  # fmt: skip
        elif radius < TINY_GYRATION * size:
            notes.append(f"its radius of gyration about {axis} is {radius:.3g} m, under "
                         f"{TINY_GYRATION:g} of its length ({size:.3g} m): inertia in another "
                         "unit (kg m^2)?")  # fmt: skip
    return notes
