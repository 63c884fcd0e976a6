"""What a model file's figures imply (catabot/world/model_checks.py): a boat designer's unit
and orientation slips, each of which had passed validation and run without a word."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from catabot.config.vessel import VesselModel, bundled_vessel_names, load_vessel_model
from catabot.world.model_checks import displacement, model_notes
from catabot.world.stability import metacentric_heights

CATAMARAN: dict[str, Any] = load_vessel_model("catabot").model_dump(mode="json")
BOX_OBJ = "".join(f"v {x} {y} {z}\n" for x in (-1, 1) for y in (-0.5, 0.5) for z in (0, 0.4))
BOX_OBJ += "f 1 2 3\nf 5 6 7\n"  # a 2 x 1 x 0.4 m box's corners: enough for its extent


def _notes(tmp_path: Path, **changes: Any) -> list[str]:
    (tmp_path / "hull.obj").write_text(BOX_OBJ)
    path = tmp_path / "boat.json"
    path.write_text(json.dumps(CATAMARAN | changes))
    return model_notes(load_vessel_model(str(path)), source=str(path), density=1025.0)


def test_the_bundled_models_have_nothing_to_note() -> None:
    for name in bundled_vessel_names():
        assert model_notes(load_vessel_model(name), source=name, density=1025.0) == [], name
    said = displacement(load_vessel_model("catabot"), 1025.0)
    assert (
        said == "in water of 1025 kg/m^3 it floats with 0.0537 m^3 under, 20 % of its hulls' volume"
    )


@pytest.mark.parametrize(
    ("changes", "note"),
    [
        ({"shape": {"mesh": {"file": "hull.obj", "scale": 1000}}}, "mesh is 1.05e+03 times the"),
        ({"shape": {"mesh": {"file": "hull.obj", "rpy_deg": [0, 90, 0]}}}, "longest along z"),
        ({"mass_kg": 0.055, "thrusters": []},  # with them: refused, 133 times its weight
         "radius of gyration about z is 17.7 m, more than its length"),
        ({"thrusters": [CATAMARAN["thrusters"][0] | {"max_forward_n": 1e4}]},  # thrown 25 m up
         "its thrusters together push 10000 N, 18.5 times its weight: racing craft stay under 2"),
        ({"added_mass": [2.75, 21, 79000, 12.8, 23.9, 6.4]}, "is 1.44e+03 times its mass"),
        ({"added_mass": [0, 0, 0.079, 0, 0, 0]}, "is 0.00144 times its mass"),
        ({"thrusters": [{**CATAMARAN["thrusters"][0], "position_m": [3.0, 0.4, -0.1]}]},
         "thruster 0 at (3, 0.4) m is 2.05 m outside every hull"),
        ({"damping": CATAMARAN["damping"] | {"lift_uv": [0.0, 0.0]}},
         "cannot hold a straight course above 1.74 m/s, below its top speed (1.87 m/s)"),
        ({"damping": {"linear": [0.0] * 6, "quadratic": [0.0] * 6}, "wind": None},  # "inf m/s"
         "above 0.00 m/s, and has no top speed (no surge damping nor wind areas)"),
        ({"damping": {"linear": [0.0] * 6, "quadratic": [0.0] * 6}},  # the air's drag alone
         "above 0.00 m/s, below its top speed (25.56 m/s)"),
        ({"cog_m": [5.0, 0.0, 0.19]},  # a trial's model: capsized in 2 s, validate said valid
         "its centre of gravity (5, 0) m lies outside every hull in plan view"),
        ({"hulls": [h | {"center_m": [h["center_m"][0], h["center_m"][1], 2.0]}
                    for h in CATAMARAN["hulls"]]},
         "its hulls' bottom is 1.85 m above z = 0, the waterline at rest (body frame)"),
        ({"inertia_kgm2": [v / 1000 for v in CATAMARAN["inertia_kgm2"]]},
         "radius of gyration about x is 0.0114 m, under 0.02 of its length"),
        ({"cog_m": [0.0, 0.0, 3.0]},  # a trial's model: capsized at 8.1 s, validate said valid
         "its metacentric height in roll is -0.23 m (floating upright): its centre of gravity "
         "(z 3 m) is above its metacentre (z 2.77 m), so it capsizes"),
    ],
)  # fmt: skip
def test_a_slip_is_noted(tmp_path: Path, changes: dict[str, Any], note: str) -> None:
    notes = _notes(tmp_path, **changes)
    assert any(note in n for n in notes), notes
    assert len(notes) <= 4  # one slip, one note (the mass in tonnes: its added mass, each axis)


def test_metacentric_heights_match_the_box_formula() -> None:
    """Two box hulls, 1.9 x 0.24 m, 0.8 m apart, 55 kg: draft V/A, z_B half of it below the
    waterline, BM = I/V with I = 2 (L B^3/12 + L B y^2) across and 2 B L^3/12 along."""
    model = load_vessel_model("catabot")
    volume, area = 55.0 / 1025.0, 2 * 1.9 * 0.24
    bottom = 0.09 - 0.15
    z_b = bottom + volume / area / 2
    across = 2 * (1.9 * 0.24**3 / 12 + 1.9 * 0.24 * 0.4**2)
    along = 2 * 0.24 * 1.9**3 / 12
    roll, pitch = metacentric_heights(model, 1025.0)
    assert roll == pytest.approx(z_b + across / volume - 0.19, abs=1e-4)
    assert pitch == pytest.approx(z_b + along / volume - 0.19, abs=1e-4)


def test_a_half_sunk_cylinders_metacentre_is_its_axis() -> None:
    """A cylinder lying along x, floating to its axis: B moves on a circle about the axis,
    so the metacentre is the axis (z_B = -4r/3pi, BM = 4r/3pi) and GM = -z_G."""
    r, length = 0.2, 2.0
    hull = {"shape": "cylinder", "center_m": [0.0, 0.0, 0.0], "length_m": length, "beam_m": 2 * r}
    data = CATAMARAN | {"hulls": [hull], "mass_kg": 1025.0 * math.pi * r**2 * length / 2,
                        "shape": None}  # fmt: skip
    model = VesselModel.model_validate(data | {"cog_m": [0.0, 0.0, -0.1]})
    roll, _ = metacentric_heights(model, 1025.0)
    assert roll == pytest.approx(0.1, abs=2e-3)
