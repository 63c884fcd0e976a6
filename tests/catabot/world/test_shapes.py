"""Vessel shapes as meshes: the bundled models' primitives agree with their buoyancy hulls,
mesh files (OBJ, STL, glTF) are read and placed in the body frame, and a file that holds no
usable mesh is refused naming it."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import open3d as o3d
import pytest

from catabot.config.vessel import VesselModel, bundled_vessel_names, load_vessel_model
from catabot.config.vessel_shape import BoxPart
from catabot.world.shape_parts import parts_mesh
from catabot.world.shapes import MeshFileError, ShapeMesh, vessel_mesh

CELL_M = 0.01  # the waterplane is measured on a grid this fine


def _waterplane(mesh: ShapeMesh) -> tuple[float, float]:
    """Area (m^2) and centroid x (m) of the shape's section by the plane z = 0 (points
    inside by ray parity, Embree)."""
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(
        o3d.core.Tensor(mesh.vertices.astype(np.float32)),
        o3d.core.Tensor(mesh.triangles.astype(np.uint32)),
    )
    x = np.arange(mesh.lo[0], mesh.hi[0], CELL_M) + CELL_M / 2
    y = np.arange(mesh.lo[1], mesh.hi[1], CELL_M) + CELL_M / 2
    gx, gy = np.meshgrid(x, y)
    points = np.stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)], 1).astype(np.float32)
    inside = scene.compute_occupancy(o3d.core.Tensor(points), nsamples=5).numpy() > 0.5
    return inside.sum() * CELL_M**2, float(gx.ravel()[inside].mean())


def _hull_waterplane(model: VesselModel) -> tuple[float, float]:
    """What physics floats: each hull's section at z = 0 (a box's L x B, a cylinder's chord)."""
    areas, xs = [], []
    for h in model.hulls:
        if h.shape == "box":
            width = h.beam_m
        else:
            r, z = h.beam_m / 2, h.center_m[2]
            width = 2 * math.sqrt(max(r * r - z * z, 0.0))
        areas.append(h.length_m * width)
        xs.append(h.center_m[0])
    return sum(areas), float(np.average(xs, weights=areas))


@pytest.mark.parametrize("name", bundled_vessel_names())
def test_a_bundled_shape_agrees_with_its_buoyancy_hulls(name: str) -> None:
    """Same bottom (draft) and length; a waterplane within 10% of the hulls' in area and
    centre (so the boat the sensors see floats as physics floats it); and nothing below the
    hulls' box or outside it sideways but the buoy, a round float on a square hull."""
    model = load_vessel_model(name)
    mesh = vessel_mesh(model, source=name)
    assert mesh is not None
    lo, hi = model.hull_box()
    assert mesh.lo[2] == pytest.approx(lo[2], abs=0.01)
    assert mesh.hi[2] >= hi[2] - 0.01  # decks, cabins, frames stand above the hulls
    if name != "buoy":
        assert np.allclose(mesh.lo[:2], lo[:2], atol=0.01)
        assert np.allclose(mesh.hi[:2], hi[:2], atol=0.01)
    area, x = _waterplane(mesh)
    hull_area, hull_x = _hull_waterplane(model)
    assert area == pytest.approx(hull_area, rel=0.10)
    assert abs(x - hull_x) < 0.05 * (hi[0] - lo[0])


def test_the_catamarans_show_water_between_their_hulls() -> None:
    """At the waterline a catamaran is two sections with water between them, under a deck."""
    for name, gap in (("catabot", 0.28), ("wamv", 0.81)):
        mesh = vessel_mesh(load_vessel_model(name), source=name)
        assert mesh is not None
        between = np.abs(mesh.vertices[:, 1]) < gap
        low = mesh.vertices[between, 2]
        assert low.min() > 0.2, name  # nothing but the deck and above crosses the gap


def _model_with_mesh(folder: Path, mesh: dict[str, Any]) -> VesselModel:
    data = load_vessel_model("catabot").model_dump(mode="json") | {"shape": {"mesh": mesh}}
    (folder / "boat.json").write_text(json.dumps(data))
    return load_vessel_model(str(folder / "boat.json"))


@pytest.mark.parametrize("suffix", [".obj", ".stl", ".gltf"])
def test_a_mesh_file_is_read_and_placed_in_the_body_frame(tmp_path: Path, suffix: str) -> None:
    box = o3d.geometry.TriangleMesh.create_box(2.0, 1.0, 0.5)  # 0..2, 0..1, 0..0.5
    box.compute_vertex_normals()
    assert o3d.io.write_triangle_mesh(str(tmp_path / f"box{suffix}"), box)
    placed = {"file": f"box{suffix}", "scale": [1.0, 2.0, 1.0], "rpy_deg": [0.0, 0.0, 90.0],
              "offset_m": [0.5, 0.0, -0.1]}  # fmt: skip
    model = _model_with_mesh(tmp_path, placed)
    mesh = vessel_mesh(model, source="boat.json")
    assert mesh is not None and mesh.triangles.shape == (12, 3)
    # scaled to 2 x 2 x 0.5, turned 90 deg about z (x -> y, y -> -x), then moved
    assert np.allclose(mesh.lo, [-1.5, 0.0, -0.1], atol=1e-6)
    assert np.allclose(mesh.hi, [0.5, 2.0, 0.4], atol=1e-6)


@pytest.mark.parametrize(
    ("name", "content", "problem"),
    [
        ("empty.obj", b"", "no triangles in it"),
        ("points.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no triangles in it"),
        ("junk.stl", b"\x00\x01garbage" * 10, "no triangles in it"),
        ("nan.obj", b"v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "not finite"),
    ],
)
def test_a_mesh_file_without_a_usable_mesh_is_refused_naming_it(
    tmp_path: Path, name: str, content: bytes, problem: str
) -> None:
    (tmp_path / name).write_bytes(content)
    model = _model_with_mesh(tmp_path, {"file": name})
    with pytest.raises(MeshFileError, match=problem) as info:
        vessel_mesh(model, source="boat.json")
    assert f"vessel model 'boat.json': shape.mesh.file '{tmp_path / name}'" in str(info.value)


def test_a_mesh_file_removed_after_loading_is_refused_naming_it(tmp_path: Path) -> None:
    (tmp_path / "hull.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    model = _model_with_mesh(tmp_path, {"file": "hull.obj"})
    (tmp_path / "hull.obj").unlink()
    with pytest.raises(MeshFileError, match=r"hull\.obj': no such file"):
        vessel_mesh(model, source="boat.json")


def test_a_model_without_shape_has_no_mesh() -> None:
    data = load_vessel_model("catabot").model_copy(update={"shape": None})
    assert vessel_mesh(data, source="catabot") is None


@pytest.mark.parametrize("name", bundled_vessel_names())
def test_every_part_is_closed_and_wound_outwards(name: str) -> None:
    """Each primitive encloses its volume with triangles facing out (the viewer lights the
    outside): the divergence theorem gives the part's volume, positive."""
    model = load_vessel_model(name)
    assert model.shape is not None and model.shape.parts is not None
    for part in model.shape.parts:
        vertices, triangles = parts_mesh([part], model.hulls)
        a, b, c = (vertices[triangles[:, k]] for k in range(3))
        volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
        if isinstance(part, BoxPart):
            assert volume == pytest.approx(np.prod(part.size_m))
        assert volume > 0.0, (name, part)
