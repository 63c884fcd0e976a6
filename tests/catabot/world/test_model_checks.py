"""What a model file's figures imply (catabot/world/model_checks.py): a boat designer's unit
and orientation slips, each of which had passed validation and run without a word."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from catabot.config.vessel import bundled_vessel_names, load_vessel_model
from catabot.world.model_checks import displacement, model_notes

CATAMARAN: dict[str, Any] = load_vessel_model("catabot").model_dump(mode="json")
BOX_OBJ = "".join(f"v {x} {y} {z}\n" for x in (-1, 1) for y in (-0.5, 0.5) for z in (0, 0.4))
BOX_OBJ += "f 1 2 3\nf 5 6 7\n"  # a 2 x 1 x 0.4 m box's corners: enough for its extent


def _notes(tmp_path: Path, **changes: Any) -> list[str]:
    (tmp_path / "hull.obj").write_text(BOX_OBJ)
    path = tmp_path / "boat.json"
    path.write_text(json.dumps(CATAMARAN | changes))
    return model_notes(load_vessel_model(str(path)), source=str(path))


def test_the_bundled_models_have_nothing_to_note() -> None:
    for name in bundled_vessel_names():
        assert model_notes(load_vessel_model(name), source=name) == [], name
    said = displacement(load_vessel_model("catabot"), 1025.0)
    assert (
        said == "in water of 1025 kg/m^3 it floats with 0.0537 m^3 under, 20 % of its hulls' volume"
    )


@pytest.mark.parametrize(
    ("changes", "note"),
    [
        ({"shape": {"mesh": {"file": "hull.obj", "scale": 1000}}}, "mesh is 1.05e+03 times the"),
        ({"shape": {"mesh": {"file": "hull.obj", "rpy_deg": [0, 90, 0]}}}, "longest along z"),
        ({"mass_kg": 0.055}, "radius of gyration about z is 17.7 m, more than its length"),
        ({"added_mass": [2.75, 21, 79000, 12.8, 23.9, 6.4]}, "is 1.44e+03 times its mass"),
        ({"added_mass": [0, 0, 0.079, 0, 0, 0]}, "is 0.00144 times its mass"),
        ({"thrusters": [{**CATAMARAN["thrusters"][0], "position_m": [3.0, 0.4, -0.1]}]},
         "thruster 0 at (3, 0.4) m is 2.05 m outside every hull"),
        ({"damping": CATAMARAN["damping"] | {"lift_uv": [0.0, 0.0]}},
         "cannot hold a straight course above 1.74 m/s, below its top speed (1.88 m/s)"),
        ({"cog_m": [5.0, 0.0, 0.19]},  # a trial's model: capsized in 2 s, validate said valid
         "its centre of gravity (5, 0) m lies outside every hull in plan view"),
        ({"hulls": [h | {"center_m": [h["center_m"][0], h["center_m"][1], 2.0]}
                    for h in CATAMARAN["hulls"]]},
         "its hulls' bottom is 1.85 m above z = 0, the waterline at rest (body frame)"),
        ({"inertia_kgm2": [v / 1000 for v in CATAMARAN["inertia_kgm2"]]},
         "radius of gyration about x is 0.0114 m, under 0.02 of its length"),
    ],
)  # fmt: skip
def test_a_slip_is_noted(tmp_path: Path, changes: dict[str, Any], note: str) -> None:
    notes = _notes(tmp_path, **changes)
    assert any(note in n for n in notes), notes
    assert len(notes) <= 4  # one slip, one note (the mass in tonnes: its added mass, each axis)
