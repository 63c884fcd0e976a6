"""The gridded wave surface: its frame, cell sizes and the proven interpolation bounds."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.config.waves import WaveConfig
from catabot.world.waves import WaveField
from services.sensors import wave_kernel as wk
from services.sensors.wave_grid import EPS_M, Scratch, WaveGrid, grid_spec
from services.sensors.wave_pass import warm_up

MEDIUM = WaveField(WaveConfig(preset="medium"), 1)
SEAS = {
    "medium": MEDIUM,
    "harbour": WaveField(
        WaveConfig(significant_height_m=0.3, peak_period_s=4.0, direction_rad=1.2), 3
    ),
    "heavy": WaveField(WaveConfig(preset="heavy", direction_rad=2.5), 7),
    "long-crested": WaveField(WaveConfig(preset="medium", spreading=None, direction_rad=0.7), 2),
}


def _grid(waves: WaveField, anchor: tuple[float, float], time_s: float) -> WaveGrid:
    spec = grid_spec(waves)
    assert spec is not None
    box = (np.array([-60.0, -45.0]), np.array([70.0, 50.0]))
    return WaveGrid(spec, waves, time_s, np.array(anchor), box, Scratch())


def _interpolate(grid: WaveGrid, uv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear height and gradient at grid-frame points (2, n), through the kernel's own
    cell lookup and interpolation."""
    warm_up()  # the kernel's helpers, compiled
    f0 = (uv - [[grid.u0], [grid.v0]]) / [[grid.hu], [grid.hv]]
    cells, row = (grid.nu - 1, grid.nv - 1), 3 * grid.nv
    height, grad = np.empty(f0.shape[1]), np.empty((2, f0.shape[1]))
    for k, (fu, fv) in enumerate(f0.T):
        ray = (fu, fv, 0.0, 0.0, 0.0, -1.0, -1.0)  # z = 0 at t = 0: f = -g
        cell = wk._cell_of(cells, ray, 0.0)
        height[k] = -wk._gap(grid.flat, row, cell, ray, 0.0)[0]
        grad[:, k] = wk._gradient(grid.flat, row, cell, ray, 0.0)
    return height, grad


def test_calm_water_has_no_grid() -> None:
    assert grid_spec(WaveField(WaveConfig(), 0)) is None


def test_cells_split_the_bound_between_the_principal_axes() -> None:
    spec = grid_spec(MEDIUM)
    assert spec is not None
    a, k = MEDIUM.amplitudes_m, MEDIUM.wavenumbers_radpm
    assert spec.eps == pytest.approx(EPS_M)
    assert spec.eps == pytest.approx(
        spec.hu**2 / 8 * np.sum(a * spec.k_u**2) + spec.hv**2 / 8 * np.sum(a * spec.k_v**2)
    )
    assert np.allclose(spec.k_u**2 + spec.k_v**2, k**2)  # a rotation of the wave vectors
    assert np.sum(a * spec.k_u * spec.k_v) == pytest.approx(0.0, abs=1e-12)  # principal axes
    assert spec.hv > 2.0 * spec.hu  # a narrow spread: long cells across the waves
    square = np.sqrt(8.0 * EPS_M / np.sum(a * k**2))  # square cells for the same bound
    assert spec.hu * spec.hv > 1.5 * square**2
    assert np.allclose(
        np.linalg.eigvalsh(spec.curvature),
        np.sort([np.sum(a * spec.k_u**2), np.sum(a * spec.k_v**2)]),
    )


@pytest.mark.parametrize("sea", SEAS)
@pytest.mark.parametrize(
    ("anchor", "time_s"), [((3.0, -2.0), 4.5), ((-41_250.0, 73_900.5), 86_400.25)]
)
def test_interpolated_surface_is_within_its_bounds(
    sea: str, anchor: tuple[float, float], time_s: float
) -> None:
    """Far from the origin and late in a run too: phases are reduced in float64 first."""
    waves = SEAS[sea]
    grid = _grid(waves, anchor, time_s)
    spec = grid.spec
    uv = np.random.default_rng(4).uniform([-59.0, -44.0], [69.0, 49.0], (20_000, 2)).T
    height, grad = _interpolate(grid, uv)
    xy = np.asarray(anchor)[:, None] + spec.rot.T @ uv
    true = waves.height(xy[0], xy[1], time_s)
    assert np.abs(height - true).max() <= spec.eps + 1e-5
    assert np.abs(height - true).max() > 0.2 * spec.eps  # the bound is not slack by orders
    n = waves.normal(xy[0], xy[1], time_s)
    true_grad = spec.rot @ np.stack([-n[:, 0] / n[:, 2], -n[:, 1] / n[:, 2]])  # grid frame
    for axis in range(2):
        assert np.abs(grad[axis] - true_grad[axis]).max() <= spec.grad_err[axis] + 1e-5


def test_extremes_rises_and_block_maxima_hold_the_interpolant() -> None:
    grid = _grid(MEDIUM, (10.0, 20.0), 3.0)
    nodes = grid.flat.reshape(grid.nu, grid.nv, 3)[:, :, 0]
    assert grid.zmin == nodes.min() and grid.zmax == nodes.max()
    assert grid.rise[0] == pytest.approx(np.abs(np.diff(nodes, axis=0)).max())
    assert grid.rise[1] == pytest.approx(np.abs(np.diff(nodes, axis=1)).max())
    top, shape, b = grid.blocks
    assert top.shape == shape == ((grid.nu - 2) // b + 1, (grid.nv - 2) // b + 1)
    for i, j in [(0, 0), (3, 5), (shape[0] - 1, shape[1] - 1)]:
        held = nodes[i * b : i * b + b + 1, j * b : j * b + b + 1]
        assert top[i, j] == held.max()
