"""Terrain: image formats and mapping, world orientation, bilinear heights, mesh, start checks."""

from __future__ import annotations

import re
import time
from pathlib import Path

import numpy as np
import pytest
import tifffile
from PIL import Image
from pydantic import ValidationError

from catabot.config.terrain import TerrainConfig, TerrainError
from catabot.world.terrain import MAX_MESH_TRIANGLES, Terrain, load_terrain
from tests.paths import NEW_YORK_RIVER

REAL_IMAGE = NEW_YORK_RIVER
LO, HI, MPP = -35.0, 60.0, 5.0
# 3 rows x 4 columns, row 0 = north; the bright pixel is the top-left one.
PIXELS = np.array([[255, 10, 20, 30], [40, 50, 60, 70], [80, 90, 100, 0]], dtype=np.uint8)


def config(path: Path, **extra: object) -> TerrainConfig:
    return TerrainConfig(elevation_image=str(path), metres_per_pixel=MPP, **extra)


def centre(row: int, col: int, rows: int = 3) -> tuple[float, float]:
    """World (x, y) of an image pixel's centre: y counts up from the bottom row."""
    return (col + 0.5) * MPP, (rows - 1 - row + 0.5) * MPP


@pytest.fixture()
def png8(tmp_path: Path) -> Path:
    path = tmp_path / "t8.png"
    Image.fromarray(PIXELS, mode="L").save(path)
    return path


def test_8bit_png_pixel_centres_and_orientation(png8: Path) -> None:
    terrain = load_terrain(config(png8))
    assert terrain.size_m == (4 * MPP, 3 * MPP)
    for (row, col), value in np.ndenumerate(PIXELS):
        expected = LO + value / 255 * (HI - LO)
        assert terrain.height(*centre(row, col)) == pytest.approx(expected, abs=1e-9)
    # The bright top-left pixel is at high y (north) and low x (west).
    assert terrain.height(0.5 * MPP, 2.5 * MPP) == pytest.approx(HI)
    assert terrain.height(3.5 * MPP, 0.5 * MPP) == pytest.approx(LO)


def test_bilinear_between_centres_and_edge_outside(png8: Path) -> None:
    terrain = load_terrain(config(png8))
    h = lambda r, c: LO + PIXELS[r, c] / 255 * (HI - LO)  # noqa: E731
    (x0, y0), (x1, y1) = centre(1, 1), centre(0, 2)
    mid = terrain.height((x0 + x1) / 2, (y0 + y1) / 2)
    assert mid == pytest.approx((h(1, 1) + h(1, 2) + h(0, 1) + h(0, 2)) / 4)
    quarter = terrain.height(x0 + 0.25 * MPP, y0)
    assert quarter == pytest.approx(0.75 * h(1, 1) + 0.25 * h(1, 2))
    # Outside the image: the nearest edge value, not deep water.
    assert terrain.height(-100.0, 2.5 * MPP) == pytest.approx(h(0, 0))
    assert terrain.height(1e4, -1e4) == pytest.approx(h(2, 3))
    xs, ys = np.meshgrid(np.linspace(-5, 25, 7), np.linspace(-5, 20, 6))
    assert terrain.height(xs, ys).shape == (6, 7)  # vectorised, shape preserved
    assert np.all(terrain.depth(xs, ys) >= 0.0)
    assert terrain.depth(*centre(2, 3)) == pytest.approx(35.0)


def test_16bit_png_and_rgba_with_equal_channels(tmp_path: Path) -> None:
    values = np.array([[65535, 0], [32768, 1000]], dtype=np.uint16)
    Image.fromarray(values).save(tmp_path / "t16.png")
    terrain = load_terrain(config(tmp_path / "t16.png"), base_dir=None)
    assert terrain.height(*centre(0, 0, rows=2)) == pytest.approx(HI)
    assert terrain.height(*centre(1, 0, rows=2)) == pytest.approx(LO + 32768 / 65535 * 95)
    rgba = np.stack([PIXELS, PIXELS, PIXELS, np.full_like(PIXELS, 255)], axis=-1)
    Image.fromarray(rgba, mode="RGBA").save(tmp_path / "rgba.png")
    colour = load_terrain(TerrainConfig(elevation_image="rgba.png"), base_dir=tmp_path)
    assert np.array_equal(
        colour.elevation_m, load_terrain(config(tmp_path / "rgba.png")).elevation_m
    )


def test_colour_png_with_unequal_channels_is_refused(tmp_path: Path) -> None:
    rgb = np.stack([PIXELS, PIXELS, PIXELS], axis=-1)
    rgb[1, 2, 1] = 7
    Image.fromarray(rgb, mode="RGB").save(tmp_path / "colour.png")
    with pytest.raises(TerrainError, match=r"unequal channels \(first at row 1, column 2"):
        load_terrain(config(tmp_path / "colour.png"))


def test_tiff_float_metres_and_integer_scaling(tmp_path: Path) -> None:
    metres = np.array([[12.5, -3.25], [-40.0, 0.0]], dtype=np.float32)
    tifffile.imwrite(tmp_path / "m.tif", metres)
    terrain = load_terrain(config(tmp_path / "m.tif"))
    assert terrain.height(*centre(0, 0, rows=2)) == pytest.approx(12.5)  # taken as-is
    assert terrain.height(*centre(1, 0, rows=2)) == pytest.approx(-40.0)
    tifffile.imwrite(tmp_path / "u16.tif", np.array([[65535, 0], [0, 0]], dtype=np.uint16))
    assert load_terrain(config(tmp_path / "u16.tif")).height(2.5, 7.5) == pytest.approx(HI)
    tifffile.imwrite(tmp_path / "multi.tif", np.zeros((2, 2, 3), dtype=np.uint8))
    with pytest.raises(TerrainError, match="single band"):
        load_terrain(config(tmp_path / "multi.tif"))
    tifffile.imwrite(tmp_path / "nan.tif", np.array([[np.nan, 1], [1, 1]], dtype=np.float32))
    with pytest.raises(TerrainError, match="non-finite"):
        load_terrain(config(tmp_path / "nan.tif"))


def test_precise_errors(tmp_path: Path) -> None:
    where = r"\(a relative path is taken from the scenario file's folder, .* images: bay.png\)$"
    with pytest.raises(TerrainError, match=r"elevation_image: file not found: .*nope.png " + where):
        load_terrain(config(tmp_path / "nope.png"))
    (tmp_path / "junk.png").write_bytes(b"definitely not an image")
    with pytest.raises(TerrainError, match="not a PNG or TIFF"):
        load_terrain(config(tmp_path / "junk.png"))
    Image.fromarray(np.zeros((64, 64), dtype=np.uint8) + 7).save(tmp_path / "whole.png")
    (tmp_path / "cut.png").write_bytes((tmp_path / "whole.png").read_bytes()[:60])
    with pytest.raises(TerrainError, match=r"cut.png: cannot decode PNG"):
        load_terrain(config(tmp_path / "cut.png"))
    with pytest.raises(ValidationError, match=r"max_elevation_m .* must be greater than"):
        TerrainConfig(elevation_image="a.png", min_elevation_m=10, max_elevation_m=10)
    with pytest.raises(ValidationError, match="metres_per_pixel"):
        TerrainConfig(elevation_image="a.png", metres_per_pixel=0)
    with pytest.raises(ValidationError, match="terrainHeightMin"):
        TerrainConfig.model_validate({"elevation_image": "a.png", "terrainHeightMin": 1})
    with pytest.raises(ValidationError, match="finite"):
        TerrainConfig(elevation_image="a.png", max_elevation_m=float("inf"))


def test_mesh_counts_winding_and_raycast(png8: Path) -> None:
    terrain = load_terrain(config(png8))
    vertices, triangles = terrain.mesh(MPP)
    assert vertices.shape == ((4 + 2) * (3 + 2), 3) and triangles.shape == (2 * 5 * 4, 3)
    assert triangles.dtype == np.int32 and vertices.dtype == np.float64
    assert np.allclose(vertices[:, 2], terrain.height(vertices[:, 0], vertices[:, 1]))
    corners = vertices[:, :2].min(axis=0), vertices[:, :2].max(axis=0)
    assert np.allclose(corners, [(0, 0), terrain.size_m])
    a, b, c = (vertices[triangles[:, i]] for i in range(3))
    assert np.all(np.cross(b - a, c - a)[:, 2] > 0)  # counter-clockwise: normals up
    coarse_v, coarse_t = terrain.mesh(12.0)
    assert len(coarse_t) == 2 * (len(np.unique(coarse_v[:, 0])) - 1) * 3  # 4 x 3 cells
    scene = terrain.raycasting_scene(MPP)
    x, y = centre(1, 2)
    rays = np.array([[x, y, 100.0, 0.0, 0.0, -1.0]], dtype=np.float32)
    hit = scene.cast_rays(rays)["t_hit"].numpy()[0]
    assert 100.0 - hit == pytest.approx(terrain.height(x, y), abs=1e-3)


def lake() -> Terrain:
    """100 x 80 m at 1 m: land at +3 m, a round lake 20 m deep in the middle, shallow rim."""
    xs, ys = np.meshgrid(np.arange(100) + 0.5, np.arange(80) + 0.5)
    r = np.hypot(xs - 60, ys - 40)
    return Terrain(np.clip(0.5 * r - 15.0, -20.0, 3.0), 1.0, name="lake")


def test_open_water_search_and_start_checks() -> None:
    terrain = lake()
    x, y = terrain.find_open_water(0.5, clearance_m=0.5, footprint_m=4.0)
    assert np.hypot(x - 60, y - 40) < 21 and terrain.depth(x, y) > 1.0
    terrain.check_start(x, y, draft_m=0.5, footprint_m=4.0)
    for near in [(0.0, 0.0), (99.0, 79.0), (60.0, 40.0)]:
        p = terrain.find_open_water(0.3, near=near, footprint_m=2.5)
        terrain.check_start(*p, draft_m=0.3, footprint_m=2.5)  # what it finds is accepted
    with pytest.raises(
        TerrainError, match=r"start pose \(5.0, 5.0\) is on land: ground elevation 3.0 m"
    ):
        terrain.check_start(5.0, 5.0, draft_m=0.06, footprint_m=1.0)
    with pytest.raises(TerrainError, match=r"water depth 0\.\d+ m .* too shallow for draft 0.06 m"):
        terrain.check_start(60.0 + 29.5, 40.0, draft_m=0.06, footprint_m=1.0)
    with pytest.raises(TerrainError, match="outside the terrain"):
        terrain.check_start(-1.0, 5.0, draft_m=0.06, footprint_m=1.0)
    depth = float(terrain.depth(x, y))  # deep water, but a hull started under its bed:
    with pytest.raises(TerrainError, match=r"its keel at z -\d+\.\d+ m is not 0.5 m above"):
        terrain.check_start(x, y, draft_m=0.5, footprint_m=4.0, z_m=-depth)
    terrain.check_start(x, y, draft_m=0.5, footprint_m=4.0, z_m=-2.0)  # under water, clear
    terrain.check_start(60.0 + 29.5, 40.0, draft_m=0.06, footprint_m=1.0, z_m=5.0)  # a drop
    with pytest.raises(TerrainError, match="no open water deeper than") as deep:
        terrain.find_open_water(30.0)
    assert "metres_per_pixel" not in str(deep.value)  # a map far larger than a hull
    river = np.full((16, 10), -35.0)
    river[:, :2] = 5.0  # a bank
    tiny = Terrain(river, 0.005)  # a 10 km river's scale typed in km
    with pytest.raises(TerrainError) as small:
        tiny.find_open_water(0.06, footprint_m=1.08)
    assert "(0.05 x 0.08 m, 0.005 m a pixel)" in str(small.value)
    assert "is metres_per_pixel right?" in str(small.value)


def test_auto_resolution_keeps_the_triangle_budget() -> None:
    terrain = Terrain(np.zeros((900, 700)), 2.0)
    assert terrain.resolution_m > 2.0
    assert len(terrain.mesh()[1]) <= MAX_MESH_TRIANGLES
    assert len(terrain.mesh(terrain.resolution_m * 0.97)[1]) > MAX_MESH_TRIANGLES
    assert Terrain(np.zeros((20, 30)), 5.0).resolution_m == 5.0  # small: full resolution


@pytest.fixture(scope="module")
def river() -> Terrain:
    if not REAL_IMAGE.is_file():
        pytest.skip(f"{REAL_IMAGE} is not available")
    start = time.perf_counter()
    terrain = load_terrain(TerrainConfig(elevation_image=str(REAL_IMAGE)))
    print(f"\nload {REAL_IMAGE.name}: {time.perf_counter() - start:.3f} s")
    return terrain


def test_real_image_mapping_and_orientation(river: Terrain) -> None:
    assert river.elevation_m.shape == (3243, 2056) and river.size_m == (10280.0, 16215.0)
    assert abs(35 / 95 * 255 - 94.0) < 0.06  # the README's water line
    band = np.asarray(Image.open(REAL_IMAGE))[..., 0]
    row, col = np.argwhere(band == 94)[0]
    assert river.height(*centre(row, col, rows=band.shape[0])) == pytest.approx(0.0196, abs=1e-3)
    w, h = river.size_m
    xs, ys = np.meshgrid(np.linspace(0, w, 120), np.linspace(0, h, 180))
    z = river.height(xs, ys)
    fx, fy = xs / w, ys / h  # fractions of the extent, from the bottom-left corner
    assert z[(fx <= 0.2) & (fy <= 0.2)].min() < -5  # the river runs from bottom left ...
    assert z[(fx >= 0.75) & (fy >= 0.85)].min() < -5  # ... to top right
    assert z[(fx >= 0.75) & (fy <= 0.2)].min() > 0  # and the bottom-right is land


def test_real_image_start_checks_and_mesh(river: Terrain) -> None:
    start = time.perf_counter()
    x, y = river.find_open_water(0.06, footprint_m=3.0)
    found_s = time.perf_counter() - start
    assert river.depth(x, y) > 2.0
    assert np.hypot(x - river.size_m[0] / 2, y - river.size_m[1] / 2) < 100
    river.check_start(x, y, draft_m=0.06, footprint_m=3.0)
    z = river.elevation_m
    iy, ix = np.argwhere(z > 5.0)[len(np.argwhere(z > 5.0)) // 2]
    with pytest.raises(TerrainError, match=r"is on land: ground elevation \d+\.\d m"):
        river.check_start((ix + 0.5) * 5, (iy + 0.5) * 5, draft_m=0.06, footprint_m=1.0)
    iy, ix = np.argwhere((z < -0.1) & (z > -0.4))[0]
    with pytest.raises(TerrainError, match=r"too shallow for draft 0\.06 m"):
        river.check_start((ix + 0.5) * 5, (iy + 0.5) * 5, draft_m=0.06, footprint_m=1.0)
    start = time.perf_counter()
    vertices, triangles = river.mesh()
    mesh_s = time.perf_counter() - start
    assert len(triangles) <= MAX_MESH_TRIANGLES and len(triangles) > 0.95 * MAX_MESH_TRIANGLES
    assert len(vertices) == (triangles.max() + 1)
    print(f"\nopen-water search {found_s:.3f} s, mesh {len(triangles)} triangles {mesh_s:.3f} s")


def test_a_refused_start_names_the_nearest_start_that_is_not() -> None:
    """A trial user read the image's pixels to find water; the refusal now says where."""
    terrain = lake()
    for x, y in [(5.0, 5.0), (60.0 + 29.5, 40.0)]:  # on land; in the shallow rim
        with pytest.raises(TerrainError, match=r"nearest start deep enough is \(") as info:
            terrain.check_start(x, y, draft_m=0.5, footprint_m=2.0)
        fx, fy, away = map(float, re.findall(r"is \(([-\d.]+), ([-\d.]+)\), (\d+) m away",
                                             str(info.value))[0])  # fmt: skip
        terrain.check_start(fx, fy, draft_m=0.5, footprint_m=2.0)  # accepted as told
        assert abs(np.hypot(fx - x, fy - y) - away) < 1.0
