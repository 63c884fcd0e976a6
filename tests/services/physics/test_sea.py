"""The sea physics samples (services/physics/sea.py, surface.py): every method stays within
its bound of the exact surface, the cheapest one that can is chosen, calm water is untouched."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catabot.config.vessel import VesselModel, load_vessel_model
from catabot.config.waves import WaveConfig
from catabot.world import rotations
from catabot.world.waves import WaveField
from services.physics.hydro import ColumnSurface, build_columns, water_height
from services.physics.sea import SeaSampler
from services.physics.surface import TOLERANCE_M, choose_order

MEDIUM = WaveConfig(preset="medium")
CHOP = WaveConfig(significant_height_m=0.3, peak_period_s=4.0, direction_rad=1.2)
SHORT = WaveConfig(significant_height_m=0.1, peak_period_s=1.2)


def fleet(*names: str) -> list[VesselModel]:
    return [load_vessel_model(n) for n in names]


def columns_at(
    models: list[VesselModel], seed: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Body-frame column bottoms, their world points, the origins and the rotations for
    random poses: far from the origin, yawed any way, rolled and pitched up to ~0.3 rad."""
    cols = build_columns(models)
    rng = np.random.default_rng(seed)
    n = len(models)
    rotvec = rng.normal(0.0, 0.15, (n, 3))
    rotvec[:, 2] = rng.uniform(-math.pi, math.pi, n)
    pos = np.column_stack([rng.uniform(-3000, 3000, (n, 2)), rng.uniform(-1.0, 0.5, n)])
    rot = rotations.matrices(rotations.from_rotvec(rotvec))
    world = np.matmul(rot, cols.bottom_m) + pos[:, :, None]
    return cols.bottom_m.transpose(0, 2, 1), world, pos, rot


@pytest.mark.parametrize(
    ("sea", "models", "method"),
    [
        (MEDIUM, ("catabot", "monohull", "buoy"), "vessel expansions"),
        (WaveConfig(preset="heavy"), ("wamv", "monohull"), "vessel expansions"),
        (CHOP, ("catabot", "monohull", "wamv"), "hull patches"),
        (SHORT, ("wamv", "catabot"), "exact sum"),
    ],
)
def test_heights_at_the_columns_are_within_the_tolerance_of_the_exact_surface(
    sea: WaveConfig, models: tuple[str, ...], method: str
) -> None:
    waves = WaveField(sea, 3)
    vessels = fleet(*models) * 20
    bottom, world, pos, rot = columns_at(vessels, seed=len(models))
    sampler = SeaSampler(vessels, bottom, build_columns(vessels).area_m2)
    sampler.use(waves)
    assert sampler.method.startswith(method)
    real = build_columns(vessels).area_m2 > 0  # padding columns carry no buoyancy
    for t in (0.0, 1234.56, 86_400.0):
        got = sampler.sample(pos, t, rot).surface(world[:, 0], world[:, 1], t)
        exact = waves.height(world[:, 0], world[:, 1], t)
        assert got.shape == exact.shape
        assert np.isfinite(got).all()  # padding columns too: 0 x NaN would be a NaN force
        assert np.abs(got - exact)[real].max() <= TOLERANCE_M + 1e-6  # + float32 rounding


@pytest.mark.parametrize(
    ("sea", "models"), [(MEDIUM, ("catabot", "monohull")), (CHOP, ("wamv", "monohull", "buoy"))]
)
def test_the_velocity_is_the_orbital_velocity_averaged_over_each_waterplane(
    sea: WaveConfig, models: tuple[str, ...]
) -> None:
    """What damping and added mass see (hull_average.py): the surface's orbital velocity
    at every column, weighted by its area, within the heading table's step; origins above
    the surface, where no decay applies. In the chop a hull's average is far from its
    origin's value: that difference drove a free monohull downwave at 0.77 m/s."""
    waves, vessels = WaveField(sea, 5), fleet(*models) * 10
    cols = build_columns(vessels)
    rng = np.random.default_rng(9)
    yaw = rng.uniform(-math.pi, math.pi, len(vessels))
    rot = rotations.matrices(rotations.from_rotvec(np.column_stack([0 * yaw, 0 * yaw, yaw])))
    pos = np.column_stack([rng.uniform(-3000, 3000, (len(vessels), 2)), np.full(len(yaw), 9.0)])
    sampler = SeaSampler(vessels, cols.bottom_m.transpose(0, 2, 1), cols.area_m2)
    sampler.use(waves)
    got = sampler.sample(pos, 77.7, rot).velocity_w
    world = np.matmul(rot, cols.bottom_m) + pos[:, :, None]
    at_columns = waves.velocity(world[:, 0], world[:, 1], world[:, 2], 77.7)  # (N, C, 3)
    weights = cols.area_m2 / cols.area_m2.sum(axis=1, keepdims=True)
    exact = np.einsum("nc,nck->nk", weights, at_columns)
    origin = waves.velocity(pos[:, 0], pos[:, 1], pos[:, 2], 77.7)
    assert got is not None
    scale = np.abs(exact).max()
    assert np.abs(got - exact).max() <= 0.005 * scale
    assert np.abs(origin - exact).max() > (0.1 if sea is CHOP else 0.001) * scale


@pytest.mark.parametrize("sea", [None, WaveConfig(), WaveConfig(preset="calm")])
def test_calm_water_is_zero_height_and_still_water(sea: WaveConfig | None) -> None:
    vessels = fleet("catabot")
    bottom, _, pos, rot = columns_at(vessels, seed=1)
    sampler = SeaSampler(vessels, bottom, build_columns(vessels).area_m2)
    sampler.use(None if sea is None else WaveField(sea, 1))
    sample = sampler.sample(pos, 3.0, rot)
    assert sampler.calm and sampler.method == "calm"
    assert sample.velocity_w is None and sample.surface is water_height


def test_a_change_of_sea_changes_the_method() -> None:
    vessels = fleet("wamv")
    sampler = SeaSampler(vessels, columns_at(vessels, seed=2)[0], build_columns(vessels).area_m2)
    sampler.use(WaveField(MEDIUM, 1))
    assert sampler.method.startswith("vessel expansions")
    sampler.use(WaveField(SHORT, 1))
    assert sampler.method == "exact sum"
    sampler.use(None)
    assert sampler.calm


def test_the_order_is_the_least_whose_remainder_bound_holds() -> None:
    """One long-crested component: the bound a (k r)^(n+1) / (n+1)! is exact enough to
    check by hand, and the chosen order's worst error along the wave stays under it."""
    waves = WaveField(WaveConfig(significant_height_m=1.0, peak_period_s=6.0, spreading=None,
                                 frequency_components=1, direction_components=1), 1)  # fmt: skip
    a, k = float(waves.amplitudes_m[0]), float(waves.wavenumbers_radpm[0])
    r = 2.0
    order = choose_order(waves, r)
    assert order is not None
    bound = [a * (k * r) ** (n + 1) / math.factorial(n + 1) for n in range(order + 1)]
    assert bound[order] <= TOLERANCE_M < bound[order - 1]


@pytest.mark.parametrize("sea", [MEDIUM, WaveConfig(preset="heavy")])
def test_the_compiled_column_heights_are_within_the_tolerance_too(sea: WaveConfig) -> None:
    """What buoyancy reads (kernels.expansion_heights: the columns turned and evaluated in one
    pass) is the same expansion as the array form above, within float32 rounding."""
    waves, vessels = WaveField(sea, 4), fleet("catabot", "monohull", "wamv", "buoy") * 10
    cols = build_columns(vessels)
    rng = np.random.default_rng(11)
    rotvec = rng.normal(0.0, 0.15, (len(vessels), 3))
    rotvec[:, 2] = rng.uniform(-math.pi, math.pi, len(vessels))
    pos = np.column_stack([rng.uniform(-3000, 3000, (len(vessels), 2)), rng.normal(0, 0.3, 40)])
    rot = rotations.matrices(rotations.from_rotvec(rotvec))
    world = np.matmul(rot, cols.bottom_m) + pos[:, :, None]
    sampler = SeaSampler(vessels, cols.bottom_m.transpose(0, 2, 1), cols.area_m2)
    sampler.use(waves)
    surface = sampler.sample(pos, 321.0, rot).surface
    assert isinstance(surface, ColumnSurface)
    got = surface.at_columns(rot, cols.bottom_m)
    real = cols.area_m2 > 0
    exact = waves.height(world[:, 0], world[:, 1], 321.0)
    assert np.abs(got - exact)[real].max() <= TOLERANCE_M + 1e-6
    arrays = surface(world[:, 0], world[:, 1], 321.0)
    assert np.abs(got - arrays)[real].max() <= 1e-5  # float32 rounding of metres of offset
