"""The compiled ray search on the bilinear wave surface: the first root of the interpolant,
checked against a NumPy reference of the same surface sampled densely along each ray."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from services.sensors import wave_kernel as wk
from services.sensors.wave_bounds import bounds
from services.sensors.wave_grid import WaveGrid
from services.sensors.wave_pass import CastRays, cast_on_grid, warm_up
from tests.services.sensors.wave_helpers import ORIGIN, Near, cast, fan, wave_grid


@pytest.fixture(autouse=True)
def _compiled() -> None:
    """The module's helpers are called straight from here: compiled first, as in a cast."""
    warm_up()


def _interpolant(grid: WaveGrid, xy: np.ndarray) -> np.ndarray:
    """The bilinear surface at world points (n, 2), in NumPy: the reference."""
    uv = (xy - ORIGIN[:2]) @ grid.spec.rot.T
    f = (uv - [grid.u0, grid.v0]) / [grid.hu, grid.hv]
    i, j = np.floor(f).astype(int).T
    w = f - np.stack([i, j], axis=1)
    h = grid.flat.reshape(grid.nu, grid.nv, 3)[:, :, 0].astype(np.float64)
    return (
        h[i, j] * (1 - w[:, 0]) * (1 - w[:, 1])
        + h[i + 1, j] * w[:, 0] * (1 - w[:, 1])
        + h[i, j + 1] * (1 - w[:, 0]) * w[:, 1]
        + h[i + 1, j + 1] * w[:, 0] * w[:, 1]
    )


def _gap(grid: WaveGrid, d: np.ndarray, t: np.ndarray) -> np.ndarray:
    p = ORIGIN + t[:, None] * d
    return p[:, 2] - _interpolant(grid, p[:, :2])


@pytest.mark.parametrize(
    ("elevations", "hits"), [((0.3, 4.0), 180), ((4.0, 40.0), 400)], ids=["grazing", "steep"]
)
def test_hits_are_the_first_roots_of_the_interpolant(
    elevations: tuple[float, float], hits: int
) -> None:
    grid = wave_grid()
    d = fan(400, 1, elevations)
    near, far = cast(grid, d, 60.0)
    assert far.size == 0
    hit = np.flatnonzero(np.isfinite(near.rng))
    assert hit.size >= hits  # the shallowest grazing rays reach the sea beyond 60 m
    assert np.abs(_gap(grid, d[hit], near.rng[hit])).max() < 1e-6  # on the interpolant
    for r in range(d.shape[0]):  # never under it before (1 cm steps)
        end = min(float(near.rng[r]), 60.0)
        t = np.arange(0.0, end - 1e-3, 0.01)
        assert t.size == 0 or _gap(grid, np.broadcast_to(d[r], (t.size, 3)), t).min() > -1e-9


def test_normals_are_unit_and_upward() -> None:
    near, _ = cast(wave_grid(), fan(500, 2, (1.0, 60.0)), 60.0)
    hit = np.isfinite(near.rng)
    assert np.allclose(np.linalg.norm(near.normal[hit], axis=1), 1.0, atol=1e-6)
    assert (near.normal[hit, 2] > 0.9).all()


def test_a_steep_ray_gets_the_same_root_from_newton_and_from_the_walk() -> None:
    grid = wave_grid()
    cells, row = (grid.nu - 1, grid.nv - 1), 3 * grid.nv
    frame = np.concatenate(
        [ORIGIN[:2], grid.spec.rot.ravel(), [grid.u0, grid.v0, 1 / grid.hu, 1 / grid.hv]]
    )
    top = grid.zmax + grid.spec.eps
    for d in fan(200, 3, (8.0, 80.0)):
        ray = wk._in_cells(frame, ORIGIN, d)
        assert -ray[5] > abs(ray[2]) * grid.rise[0] + abs(ray[3]) * grid.rise[1]
        span = ((top - ORIGIN[2]) / d[2], (grid.zmin - 0.1 - ORIGIN[2]) / d[2])
        walked = wk._walk(grid.flat, row, cells, ray, *span)[0]
        for z in (0.0, -0.8, 0.9):  # where Newton starts changes nothing
            assert wk._steep(grid.flat, row, cells, ray, span, z)[0] == pytest.approx(walked)


def test_rays_leaving_the_grid_are_left_to_the_exact_march() -> None:
    d = fan(300, 4, (0.05, 0.2))  # reaching the water hundreds of metres out
    near, far = cast(wave_grid(), d, 1000.0)
    assert far.size > 250 and np.isinf(near.rng[far]).all()


@pytest.mark.parametrize(
    ("c", "b", "a", "length"),
    [(1.0, -2.0, 0.0, 1.0), (1.0, -3.0, 2.0, 5.0), (1.0, 1.0, -2.0, 5.0), (1.0, -1.0, 1.0, 5.0)],
)
def test_first_root_is_the_least_in_the_interval(
    c: float, b: float, a: float, length: float
) -> None:
    roots = np.roots([a, b, c]) if a else np.array([-c / b])
    real = roots[np.isreal(roots)].real
    inside = real[(real >= 0.0) & (real <= length)]
    want = inside.min() if inside.size else np.inf
    assert wk._first_root(c, b, a, length) == pytest.approx(want)


def test_casts_use_the_kernels_warm_up_compiled() -> None:
    """A second compilation would cost seconds inside a tick: shared and own origins, read-only
    views included, reach the kernels as the one type warm_up compiles them for."""
    warm_up()
    grid, d = wave_grid(), fan(50, 6, (1.0, 30.0))
    cast(grid, d, 60.0)  # a shared origin, a read-only broadcast view
    own = np.broadcast_to(ORIGIN + np.array([0.5, 0.0, 0.0]), d.shape)
    rays = CastRays.of(own.copy(), d, np.full(50, 60.0), grid.spec.rot)
    cast_on_grid(grid, rays, Near(50), (10.0, 60.0), normals=True)
    helpers = bounds()
    kernels: list[Any] = [wk.chunks(), helpers.band_ends, helpers.block_tops]
    for kernel in (*kernels, helpers.surface_bounds):
        assert len(kernel.signatures) == 1, kernel


def test_calls_with_nearer_hits_keep_them() -> None:
    grid = wave_grid()
    d = fan(100, 5, (5.0, 30.0))
    near = Near(d.shape[0])
    near.rng[:] = 0.5  # something nearer than the water on every ray
    o = np.broadcast_to(ORIGIN, d.shape)
    rays = CastRays.of(o, d, near.rng.copy(), grid.spec.rot)
    cast_on_grid(grid, rays, near, (10.0, 60.0), normals=True)
    assert (near.rng == 0.5).all() and (near.cls == 0).all()
