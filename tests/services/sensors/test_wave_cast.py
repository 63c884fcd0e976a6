"""Ray casts against the wave surface through the grid: on the surface, at the first crossing,
the exact march where the grid does not pay, deterministic."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from catabot.bus.messages import CLASS_VESSEL, CLASS_WATER
from catabot.config.waves import WaveConfig
from catabot.world.waves import WaveField
from services.sensors.scene import Body, Scene
from services.sensors.water import wave_hits
from tests.paths import REPO

MEDIUM = WaveField(WaveConfig(preset="medium"), 1)
HARBOUR = WaveField(WaveConfig(significant_height_m=0.3, peak_period_s=4.0, direction_rad=1.2), 3)
HEAVY = WaveField(WaveConfig(preset="heavy", direction_rad=2.5), 7)
ON_SURFACE_M = 0.0075  # the grid's bound (7 mm) and rounding, well under 1 cm
TOLERANCE_M = 0.01  # no crossing of the sea before a hit dips deeper (the grid's bound: 7 mm)


def _scene(waves: WaveField, time_s: float, bodies: list[Body] | None = None) -> Scene:
    scene = Scene(terrain=None, waves=waves, bodies=bodies or [])
    scene.update({}, time_s)
    return scene


def _fan(n: int, seed: int, steepest_deg: float = 25.0) -> np.ndarray:
    """Downward unit rays, many grazing: elevations -0.05..-steepest degrees, any azimuth."""
    rng = np.random.default_rng(seed)
    el = -np.radians(np.exp(rng.uniform(np.log(0.05), np.log(steepest_deg), n)))
    az = rng.uniform(0.0, 2.0 * np.pi, n)
    return np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)


def _off_surface(
    waves: WaveField, o: np.ndarray, d: np.ndarray, rng_: np.ndarray, t: float
) -> np.ndarray:
    p = o + rng_[:, None].astype(np.float64) * d
    return p[:, 2] - waves.height(p[:, 0], p[:, 1], t)


@pytest.mark.parametrize("waves", [MEDIUM, HARBOUR, HEAVY], ids=["medium", "harbour", "heavy"])
@pytest.mark.parametrize(
    ("origin", "time_s"), [((5.0, -3.0, 1.8), 12.5), ((-38_400.0, 91_200.0, 2.5), 250_000.25)]
)
def test_hits_lie_on_the_surface_with_its_normal(
    waves: WaveField, origin: tuple[float, float, float], time_s: float
) -> None:
    scene = _scene(waves, time_s)
    d = _fan(20_000, 1)
    o = np.array(origin)
    hits = scene.cast(o, d, 150.0)
    water = np.flatnonzero(hits.cls == CLASS_WATER)
    assert water.size > 10_000  # the shallowest ~40% reach the sea beyond 150 m
    assert scene._water.last_plan.startswith("grid")
    err = _off_surface(waves, o, d[water], hits.range[water], time_s)
    assert np.abs(err).max() <= ON_SURFACE_M
    p = o + hits.range[water, None].astype(np.float64) * d[water]
    normal = waves.normal(p[:, 0], p[:, 1], time_s)
    spec = scene._water.spec
    assert spec is not None  # normals move no more than the gradients they come from
    bound = np.hypot(*spec.grad_err) + 1e-5
    assert np.linalg.norm(hits.normal[water] - normal, axis=1).max() <= bound


@pytest.mark.parametrize("waves", [MEDIUM, HARBOUR], ids=["medium", "harbour"])
def test_the_hit_is_the_first_crossing_of_grazing_rays(waves: WaveField) -> None:
    """Dense exact sampling (2 cm steps) of grazing rays: no crossing deeper than TOLERANCE_M
    before the hit, and no ray that dips that deep left without a hit."""
    time_s, o = 7.25, np.array([12.0, 4.0, 1.2])
    d = _fan(8000, 2, steepest_deg=4.0)
    scene = _scene(waves, time_s)
    hits = scene.cast(o, d, 120.0)
    assert scene._water.last_plan.startswith("grid")
    for i in range(0, d.shape[0], 4):
        end = min(float(hits.range[i]), 120.0)
        s = np.arange(0.0, end - 0.03, 0.02)
        f = _off_surface(waves, o, np.broadcast_to(d[i], (s.size, 3)), s, time_s)
        assert f.size == 0 or f.min() > -TOLERANCE_M, (i, float(f.min()))


def test_own_origins_and_origins_under_the_surface() -> None:
    time_s = 3.0
    scene = _scene(MEDIUM, time_s)
    rng = np.random.default_rng(3)
    n = 6000
    xy = rng.uniform(-40.0, 40.0, (n, 2))
    z = MEDIUM.height(xy[:, 0], xy[:, 1], time_s) + rng.uniform(-0.5, 2.0, n)
    o = np.column_stack([xy, z])
    d = _fan(n, 4)
    hits = scene.cast(o, d, 100.0)
    under = o[:, 2] < MEDIUM.height(o[:, 0], o[:, 1], time_s) - 0.01
    assert under.sum() > 500 and np.all(hits.range[under] == 0.0)  # as on the exact march
    water = np.flatnonzero((hits.cls == CLASS_WATER) & (hits.range > 0.0))
    assert water.size > 3000
    err = _off_surface(MEDIUM, o[water], d[water], hits.range[water], time_s)
    assert np.abs(err).max() <= ON_SURFACE_M


def test_nearer_bodies_win_and_rays_stop_at_their_range() -> None:
    boat = Body("boat", CLASS_VESSEL, 2, (-2.0, -1.0, -1.0), (2.0, 1.0, 1.5))
    scene = _scene(MEDIUM, 2.0, [boat])
    scene.update({"boat": ((15.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))}, 2.0)
    d = _fan(8000, 5)
    hits = scene.cast(np.array([0.0, 0.0, 2.0]), d, 60.0)
    assert np.sum(hits.cls == CLASS_VESSEL) > 10
    assert np.all(hits.range[hits.cls == CLASS_WATER] <= 60.0)
    assert np.all(np.isinf(hits.range[hits.cls == 0]))


def test_few_rays_take_the_exact_march_unchanged() -> None:
    """A radar-sized cast: a grid does not pay; the bytes are the exact march's."""
    scene = _scene(MEDIUM, 5.0)
    o, d = np.array([1.0, 2.0, 3.0]), _fan(60, 6)
    hits = scene.cast(o, d, 250.0)
    assert scene._water.last_plan == "exact"
    rows, t, normal = wave_hits(MEDIUM, np.broadcast_to(o, d.shape), d, np.full(60, 250.0), 5.0)
    assert np.array_equal(hits.range[rows], t.astype(np.float32))
    assert np.array_equal(hits.normal[rows], normal.astype(np.float32))


def test_rays_leaving_the_grid_are_marched_exactly() -> None:
    """A camera-like fan with rays reaching 1 km: the far ones go exact, all on the surface."""
    scene = _scene(MEDIUM, 9.0)
    rng = np.random.default_rng(7)
    el = -np.radians(np.concatenate([rng.uniform(0.05, 0.2, 300), rng.uniform(1.0, 30.0, 30_000)]))
    az = rng.uniform(-0.6, 0.6, el.size)
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
    o = np.array([0.0, 0.0, 1.5])
    hits = scene.cast(o, d, 1000.0)
    plan = scene._water.last_plan
    assert plan.startswith("grid") and not plan.endswith(", 0 rays exact")
    water = np.flatnonzero(hits.cls == CLASS_WATER)
    assert water.size > 30_000
    err = _off_surface(MEDIUM, o, d[water], hits.range[water], 9.0)
    assert np.abs(err).max() <= ON_SURFACE_M


def test_a_surface_outside_the_guessed_band_is_planned_again() -> None:
    d, o = _fan(10_000, 8), np.array([0.0, 0.0, 2.0])
    usual = _scene(MEDIUM, 4.0).cast(o, d, 100.0)
    scene = _scene(MEDIUM, 4.0)
    scene._water.guess = 0.2  # far below the realised crests (~1 m)
    hits = scene.cast(o, d, 100.0)
    assert np.array_equal(hits.cls, usual.cls)
    water = np.flatnonzero(hits.cls == CLASS_WATER)
    assert np.abs(_off_surface(MEDIUM, o, d[water], hits.range[water], 4.0)).max() <= ON_SURFACE_M


def test_casts_are_deterministic() -> None:
    d = _fan(20_000, 9)
    o = np.array([3.0, 1.0, 1.7])
    first = _scene(MEDIUM, 6.5).cast(o, d, 200.0)
    scene = _scene(MEDIUM, 6.5)
    for _ in range(2):
        again = scene.cast(o, d, 200.0)
        for a, b in zip(
            (first.range, first.normal, first.cls),
            (again.range, again.normal, again.cls),
            strict=True,
        ):
            assert a.tobytes() == b.tobytes()


def test_a_cast_without_normals_has_the_same_hits_and_the_calm_normal() -> None:
    """A LiDAR ignores normals: sparing the wave surface's changes no range and no class."""
    d, o = _fan(6000, 10), np.array([1.0, -1.0, 1.8])
    full = _scene(MEDIUM, 5.5).cast(o, d, 120.0)
    bare = _scene(MEDIUM, 5.5).cast(o, d, 120.0, normals=False)
    assert np.array_equal(full.range, bare.range) and np.array_equal(full.cls, bare.cls)
    gridded = (bare.cls == CLASS_WATER) & (bare.normal[:, 2] == 1.0)
    assert gridded.sum() > 3000 and not np.array_equal(full.normal, bare.normal)
    assert np.all(bare.normal[gridded, :2] == 0.0)


def test_only_a_sea_with_waves_loads_the_compiler() -> None:
    """numba (≈110 MB resident) is loaded by the first wavy sea, not by calm-water casts."""
    code = (
        "import sys, numpy as np\n"
        "from catabot.config.waves import WaveConfig\n"
        "from catabot.world.waves import WaveField\n"
        "from services.sensors.scene import Scene\n"
        "d = np.array([[0.3, 0.0, -1.0]]); o = np.array([0.0, 0.0, 2.0])\n"
        "for config in (WaveConfig(), WaveConfig(preset='medium')):\n"
        "    scene = Scene(terrain=None, waves=WaveField(config, 1), bodies=[])\n"
        "    scene.update({}, 1.0)\n"
        "    scene.cast(o, d, 50.0)\n"
        "    print('numba' in sys.modules)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=True
    )
    assert out.stdout.split() == ["False", "True"]
