"""A vessel model's `shape` field: strictly checked, errors naming the field; a mesh file's
path is the model file's neighbour and must exist; `catabot scenario validate` and
`catabot run` refuse a custom model with a bad shape before anything starts."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from catabot.config.vessel import (
    VesselModelError,
    bundled_vessel_names,
    load_vessel_model,
    parse_vessel_model,
)
from catabot.config.vessel_shape import BoxPart, HullPart
from catabot.run.cli import main

CATABOT: dict[str, Any] = load_vessel_model("catabot").model_dump(mode="json")
BOX = {"type": "box", "center_m": [0.0, 0.0, 0.3], "size_m": [1.0, 0.5, 0.2]}
CYLINDER = {"type": "cylinder", "center_m": [0, 0, 0], "axis": "z", "length_m": 1, "diameter_m": 1}
VHULL = {"type": "vhull", "stern_x_m": -2.0, "length_m": 4.0, "beam_m": 1.2, "keel_z_m": -0.1,
         "chine_z_m": 0.0, "deck_z_m": 0.6, "bow_m": 1.0}  # fmt: skip


def _with_shape(shape: Any) -> dict[str, Any]:
    return {**CATABOT, "shape": shape}


def test_every_bundled_model_names_its_shape() -> None:
    for name in bundled_vessel_names():
        shape = load_vessel_model(name).shape
        assert shape is not None and shape.parts and shape.mesh is None, name
    parts = load_vessel_model("catabot").shape.parts  # type: ignore[union-attr]
    assert [type(p) for p in parts or []] == [HullPart, HullPart, BoxPart, BoxPart]


def test_a_model_dumped_and_read_back_keeps_its_shape() -> None:
    again = parse_vessel_model(json.loads(json.dumps(CATABOT)))
    assert again == load_vessel_model("catabot")


@pytest.mark.parametrize(
    ("shape", "message"),
    [
        ({"parts": [{**BOX, "type": "cone"}]}, r"shape\.parts\.0: .*'cone'.*'hull'"),
        ({"parts": [{**BOX, "size_m": [1.0, -0.5, 0.2]}]}, r"shape\.parts\.0\.box\.size_m\.1: "),
        ({"parts": [{**BOX, "size_m": [1.0, 0.5]}]}, r"size_m: must be a list of 3 numbers"),
        (
            {"parts": [{**BOX, "colour": "red"}]},
            r"shape\.parts\.0\.box\.colour: unknown field \(allowed: type, center_m, size_m\)",
        ),
        ({"parts": [{"type": "hull", "hull": 2}]}, r"shape\.parts\.0\.hull: must name one of"),
        (
            {"parts": [BOX, {"type": "hull", "hull": 1, "bow_m": 2.5}]},
            r"shape\.parts\.1\.bow_m: must be at most the hull's length \(1\.9\)",
        ),
        (
            {"parts": [{**CYLINDER, "axis": "w"}]},
            r"shape\.parts\.0\.cylinder\.axis: must be one of 'x', 'y' or 'z'",
        ),
        (
            {"parts": [{**VHULL, "keel_z_m": 0.1, "chine_z_m": 0.0}]},
            r"shape\.parts\.0\.vhull\.chine_z_m: must be above keel_z_m",
        ),
        (
            {"parts": [{**VHULL, "bow_m": 4.5}]},
            r"shape\.parts\.0\.vhull\.bow_m: must be at most length_m \(4\)",
        ),
        ({"parts": []}, r"shape\.parts: "),
        ({}, r"shape\.mesh: give exactly one of 'mesh' \(a file\) and 'parts'"),
        ({"parts": [BOX], "mesh": {"file": "a.obj"}}, r"shape\.mesh: give exactly one"),
        ({"mesh": {"file": "boat.dae"}}, r"shape\.mesh\.file: must be an OBJ, STL or glTF"),
        ({"mesh": {"file": "a.obj", "scale": 0}}, r"shape\.mesh\.scale\.0: must be > 0"),
        ({"mesh": {"file": "a.obj", "rpy_deg": [90]}}, r"rpy_deg: must be a list of 3 numbers"),
        ({"mesh": "a.obj"}, r"shape\.mesh: must be an object"),
    ],
)
def test_a_bad_shape_is_refused_naming_the_field(shape: Any, message: str) -> None:
    with pytest.raises(VesselModelError, match=message) as info:
        parse_vessel_model(_with_shape(shape), source="mine.json")
    assert str(info.value).startswith("vessel model 'mine.json': ")


def test_a_mesh_file_is_found_beside_its_model_and_must_exist(tmp_path: Path) -> None:
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "hull.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    model = tmp_path / "boat.json"
    model.write_text(json.dumps(_with_shape({"mesh": {"file": "meshes/hull.obj"}})))
    loaded = load_vessel_model(str(model))
    assert loaded.shape is not None and loaded.shape.mesh is not None
    assert loaded.shape.mesh.file == str(tmp_path / "meshes" / "hull.obj")
    model.write_text(json.dumps(_with_shape({"mesh": {"file": "meshes/gone.stl"}})))
    with pytest.raises(VesselModelError, match=r"shape\.mesh\.file: no such file .*gone\.stl"):
        load_vessel_model(str(model))


def _scenario(folder: Path, model: dict[str, Any]) -> str:
    (folder / "boat.json").write_text(json.dumps(model))
    scenario = {"name": "custom", "seed": 1, "duration_s": 1.0,
                "vessels": [{"id": "ego", "model": "boat.json"}]}  # fmt: skip
    path = folder / "scenario.json"
    path.write_text(json.dumps(scenario))
    return str(path)


@pytest.mark.parametrize(
    ("shape", "mesh_text", "message"),
    [
        ({"parts": [{"type": "hull", "hull": 5}]}, None, "shape.parts.0.hull: must name one of"),
        ({"mesh": {"file": "missing.obj"}}, None, "shape.mesh.file: no such file"),
        ({"mesh": {"file": "hull.obj"}}, "", "hull.obj': no triangles in it"),
        ({"mesh": {"file": "hull.stl"}}, "not a mesh at all", "hull.stl': no triangles in it"),
    ],
)
def test_validate_and_run_refuse_a_custom_model_with_a_bad_shape(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    shape: Any,
    mesh_text: str | None,
    message: str,
) -> None:
    if mesh_text is not None:
        (tmp_path / shape["mesh"]["file"]).write_text(mesh_text)
    path = _scenario(tmp_path, _with_shape(shape))
    for argv in (["scenario", "validate", path], ["run", path, "--out", str(tmp_path / "runs")]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert message in err and "boat.json" in err, err
        assert "Traceback" not in err
    assert not (tmp_path / "runs").exists(), "nothing may start"


def test_validate_accepts_a_custom_model_with_a_mesh(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "hull.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    path = _scenario(tmp_path, _with_shape({"mesh": {"file": "hull.obj", "scale": 2.0}}))
    assert main(["scenario", "validate", path]) == 0, capsys.readouterr().err


def test_a_model_file_refuses_true_for_a_number() -> None:
    with pytest.raises(
        VesselModelError, match=r"'m\.json': mass_kg: must be a number \(got true\)"
    ):
        parse_vessel_model({**CATABOT, "mass_kg": True}, source="m.json")
