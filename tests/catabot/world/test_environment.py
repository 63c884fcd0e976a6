"""Wind and current fields against exact results: zones, gust statistics, bilinear maps."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image
from pydantic import ValidationError

from catabot.config.environment import (
    CurrentConfig,
    CurrentMapConfig,
    CurrentMapError,
    WindConfig,
    WindZone,
)
from catabot.config.geometry import Polygon
from catabot.world.environment import CurrentField, WindField

L_SHAPE = [(0.0, 0.0), (10.0, 0.0), (10.0, 4.0), (4.0, 4.0), (4.0, 10.0), (0.0, 10.0)]


def circle(**kw: Any) -> WindZone:
    return WindZone(**{"shape": "circle", "center_m": (0.0, 0.0), "radius_m": 5.0} | kw)


# --- configuration ------------------------------------------------------------------


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"shape": "circle", "speed_mps": 1, "radius_m": 2}, "needs center_m and radius_m"),
        ({"shape": "polygon", "speed_mps": 1, "vertices_m": [(0, 0), (1, 1)]}, "at least 3"),
        ({"shape": "polygon", "speed_mps": 1, "vertices_m": [(0, 0), (1, 1), (2, 2)]}, "no area"),
        (
            {"shape": "polygon", "speed_mps": 1, "vertices_m": [(0, 0), (3, 3), (3, 0), (0, 2)]},
            "edges 0 and 2 cross",
        ),
        (  # a bow tie: its halves' areas cancel, and it said "enclose no area"
            {
                "shape": "polygon",
                "speed_mps": 1,
                "vertices_m": [(20, 20), (80, 80), (80, 20), (20, 80)],
            },
            "edges 0 and 2 cross",
        ),
        (
            {"shape": "polygon", "speed_mps": 1, "vertices_m": L_SHAPE, "radius_m": 1},
            "only for shape 'circle'",
        ),
        ({"shape": "circle", "speed_mps": -1, "center_m": (0, 0), "radius_m": 1}, "speed_mps"),
        ({"shape": "circle", "speed_mps": 1, "center_m": (0, 0), "radius_m": 0}, "radius_m"),
        ({"shape": "circle", "speed_mps": math.nan, "center_m": (0, 0), "radius_m": 1}, "finite"),
        ({"shape": "ellipse", "speed_mps": 1}, "shape"),
        ({"shape": "circle", "speed_mps": 1, "center": (0, 0), "radius_m": 1}, "center"),
    ],
)
def test_bad_zone_is_refused_with_a_precise_message(data: dict[str, Any], message: str) -> None:
    with pytest.raises(ValidationError, match=message):
        WindZone.model_validate(data)


def test_wind_and_current_configs_are_strict_and_frozen() -> None:
    with pytest.raises(ValidationError, match="gust_time_constant_s"):
        WindConfig(gust_time_constant_s=0.0)
    with pytest.raises(ValidationError, match="Extra inputs"):
        CurrentConfig.model_validate({"velocity": [1, 0]})
    with pytest.raises(ValidationError, match="spacing_m"):
        CurrentMapConfig(path="a.npy", spacing_m=-1.0)
    config = WindConfig(speed_mps=2.0, toward_rad=math.pi / 2)
    assert config.mean_velocity_mps == pytest.approx((0.0, 2.0))
    with pytest.raises(ValidationError):
        config.speed_mps = 3.0  # type: ignore[misc]


# --- zones ----------------------------------------------------------------------------


def test_point_in_concave_polygon_vectorised() -> None:
    poly = Polygon(L_SHAPE)
    x = np.array([1.0, 8.0, 8.0, 2.0, 5.0, -1.0, 11.0, 3.9])
    y = np.array([1.0, 2.0, 8.0, 8.0, 5.0, 5.0, 1.0, 9.9])
    assert poly.contains(x, y).tolist() == [True, True, False, True, False, False, False, True]
    grid = poly.contains(np.full((3, 4), 1.0), np.full((3, 4), 1.0))
    assert grid.shape == (3, 4) and grid.all()


def test_zone_replaces_global_wind_and_last_zone_wins() -> None:
    config = WindConfig(
        speed_mps=3.0,
        toward_rad=0.0,
        zones=[
            circle(speed_mps=5.0, toward_rad=math.pi / 2),
            WindZone(shape="polygon", vertices_m=L_SHAPE, speed_mps=7.0, toward_rad=math.pi),
        ],
    )
    wind = WindField(config, seed=1)
    x = np.array([-3.0, 2.0, 8.0, 50.0])  # circle only, both (L wins), L only, neither
    y = np.array([0.0, 2.0, 2.0, 50.0])
    assert wind.source_at(x, y).tolist() == [1, 2, 2, 0]
    expected = [(0.0, 5.0), (-7.0, 0.0), (-7.0, 0.0), (3.0, 0.0)]
    assert np.allclose(wind.velocity_at(x, y), expected, atol=1e-12)


# --- gusts ----------------------------------------------------------------------------


def _gust_series(seed: int, steps: int, dt: float, std: float = 1.5) -> np.ndarray:
    wind = WindField(WindConfig(speed_mps=10.0, gust_std_mps=std), seed=seed)
    out = np.empty(steps)
    origin = np.zeros(1)
    for k in range(steps):
        out[k] = wind.velocity_at(origin, origin)[0, 0] - 10.0
        wind.advance(dt)
    return out


def test_gust_statistics_match_gauss_markov() -> None:
    """Std within 10 %, autocorrelation exp(-lag / tau) with tau = 2 s (VRX's default)."""
    dt, tau, std = 0.1, 2.0, 1.5
    g = _gust_series(seed=11, steps=100_000, dt=dt, std=std)  # 10 000 s = 5 000 tau
    assert abs(g.mean()) < 0.1 * std
    assert g.std() == pytest.approx(std, rel=0.10)
    centred = g - g.mean()
    lags = np.arange(1, 61)  # up to 3 tau
    acf = np.array([np.dot(centred[:-k], centred[k:]) / np.dot(centred, centred) for k in lags])
    fitted_tau = -1.0 / np.polyfit(lags * dt, np.log(acf), 1)[0]
    assert fitted_tau == pytest.approx(tau, rel=0.10)
    assert acf[round(tau / dt) - 1] == pytest.approx(math.exp(-1.0), abs=0.05)


def test_gusts_are_deterministic_per_seed() -> None:
    a, b = _gust_series(3, 500, 0.01), _gust_series(3, 500, 0.01)
    assert a.tobytes() == b.tobytes()
    assert not np.array_equal(a, _gust_series(4, 500, 0.01))
    assert np.all(_gust_series(3, 50, 0.01, std=0.0) == 0.0)


def test_gusty_speed_never_negative() -> None:
    wind = WindField(WindConfig(speed_mps=0.5, gust_std_mps=2.0), seed=0)
    speeds = []
    for _ in range(2000):
        speeds.append(np.hypot(*wind.velocity_at(np.zeros(1), np.zeros(1))[0]))
        wind.advance(0.05)
    assert min(speeds) == 0.0 and max(speeds) > 2.0


# --- current --------------------------------------------------------------------------


def _grid() -> np.ndarray:
    rng = np.random.default_rng(5)
    return rng.uniform(-1.0, 1.0, size=(4, 5, 2))  # rows (y) 4, cols (x) 5


def test_current_map_exact_at_nodes_and_bilinear_between() -> None:
    grid, origin, h = _grid(), (10.0, -20.0), 2.5
    uniform = np.array([0.1, -0.2])
    field = CurrentField((0.1, -0.2), grid=grid, origin_m=origin, spacing_m=h)
    j, i = np.meshgrid(np.arange(4), np.arange(5), indexing="ij")
    at_nodes = field.velocity_at(origin[0] + i * h, origin[1] + j * h)
    assert np.array_equal(at_nodes, grid + uniform)  # exact at the nodes
    tx, ty = 0.3, 0.8  # inside cell (row 1, col 2)
    v = field.velocity_at(
        np.array([origin[0] + (2 + tx) * h]), np.array([origin[1] + (1 + ty) * h])
    )
    south = (1 - tx) * grid[1, 2] + tx * grid[1, 3]
    north = (1 - tx) * grid[2, 2] + tx * grid[2, 3]
    assert np.allclose(v[0], (1 - ty) * south + ty * north + uniform, rtol=0, atol=1e-14)


def test_current_map_outside_edge_or_zero() -> None:
    grid = _grid()
    edge = CurrentField(grid=grid, spacing_m=1.0)
    zero = CurrentField((0.5, 0.0), grid=grid, spacing_m=1.0, outside="zero")
    x, y = np.array([-3.0, 10.0, 2.0]), np.array([0.0, 3.0, 1.0])
    assert np.allclose(edge.velocity_at(x, y)[:2], [grid[0, 0], grid[3, 4]])
    assert np.allclose(zero.velocity_at(x, y)[:2], [(0.5, 0.0), (0.5, 0.0)])
    assert np.allclose(zero.velocity_at(x, y)[2], grid[1, 2] + (0.5, 0.0))


def test_current_map_from_npy_and_from_image(tmp_path: Path) -> None:
    grid = _grid()
    np.save(tmp_path / "map.npy", grid)
    config = CurrentConfig(map=CurrentMapConfig(path="map.npy", spacing_m=1.0))
    field = CurrentField.from_config(config, base_dir=tmp_path)
    assert np.array_equal(field.grid, grid)
    pixels = np.full((3, 2, 3), 128, dtype=np.uint8)
    pixels[0, 1] = (255, 1, 0)  # top-right pixel = north-east node: u = +scale, v = -scale
    Image.fromarray(pixels, "RGB").save(tmp_path / "map.png")
    image = CurrentMapConfig(path=str(tmp_path / "map.png"), spacing_m=2.0, scale_mps=0.8)
    field = CurrentField.from_config(CurrentConfig(map=image))
    assert np.allclose(
        field.velocity_at(np.array([2.0, 0.0]), np.array([4.0, 0.0])),
        [
            (0.8, -0.8),
            (0.0, 0.0),
        ],
    )


@pytest.mark.parametrize(
    ("name", "content", "scale", "message"),
    [
        ("m.npy", np.zeros((3, 3)), None, r"shape must be \(rows, cols, 2\)"),
        ("m.npy", np.zeros((1, 3, 2)), None, "at least 2 x 2"),
        ("m.npy", np.full((2, 2, 2), np.nan), None, "row 0, col 0, comp 0 not finite"),
        ("m.npy", np.zeros((2, 2, 2)), 1.0, "scale_mps is only for images"),
        ("m.png", None, 1.0, "cannot read image"),
        ("m.csv", None, None, "unknown file type '.csv'"),
        ("missing.npy", None, None, "cannot read"),
    ],
)
def test_bad_current_map_is_refused(
    tmp_path: Path, name: str, content: np.ndarray | None, scale: float | None, message: str
) -> None:
    if content is not None:
        np.save(tmp_path / name, content)
    config = CurrentMapConfig(path=name, spacing_m=1.0, scale_mps=scale)
    with pytest.raises(CurrentMapError, match=message):
        CurrentField.from_config(CurrentConfig(map=config), base_dir=tmp_path)


def test_grey_image_is_refused(tmp_path: Path) -> None:
    Image.fromarray(np.zeros((2, 2), dtype=np.uint8), "L").save(tmp_path / "g.png")
    config = CurrentMapConfig(path=str(tmp_path / "g.png"), spacing_m=1.0, scale_mps=1.0)
    with pytest.raises(CurrentMapError, match=r"^water\.current\.map: current map .* mode 'L'"):
        CurrentField.from_config(CurrentConfig(map=config))  # named as the field, as others


@pytest.mark.parametrize(
    ("name", "message"),
    [("t.png", "cannot read image"), ("t.npy", r"not a \.npy file \(NumPy's np\.save format\)")],
)
def test_a_text_file_is_refused_as_not_a_map(tmp_path: Path, name: str, message: str) -> None:
    """It was told to give scale_mps (.png), or NumPy's advice to allow pickles (.npy)."""
    (tmp_path / name).write_text("not a map")
    config = CurrentMapConfig(path=name, spacing_m=1.0)
    with pytest.raises(CurrentMapError, match=message):
        CurrentField.from_config(CurrentConfig(map=config), base_dir=tmp_path)


def test_an_image_without_its_scale_is_refused(tmp_path: Path) -> None:
    Image.fromarray(np.zeros((2, 2, 3), dtype=np.uint8), "RGB").save(tmp_path / "m.png")
    config = CurrentMapConfig(path="m.png", spacing_m=1.0)
    with pytest.raises(CurrentMapError, match="an image needs scale_mps"):
        CurrentField.from_config(CurrentConfig(map=config), base_dir=tmp_path)
