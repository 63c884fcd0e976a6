"""Grounding on synthetic terrain: a vessel at full thrust stops on a beach or a bank, without
sinking into it, tunnelling, NaN or energy growth; friction sticks and slips; deep water is
untouched by the terrain."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from catabot.config.vessel import VesselModel, load_vessel_model
from catabot.world.terrain import Terrain
from services.physics.world import PhysicsWorld

DT = 0.01
Field = Callable[[np.ndarray, np.ndarray], np.ndarray]


def terrain_of(f: Field, size: tuple[int, int] = (200, 60)) -> Terrain:
    """A 1 m-per-pixel terrain from a world formula z = f(x, y)."""
    xs, ys = np.meshgrid(np.arange(size[0]) + 0.5, np.arange(size[1]) + 0.5)
    return Terrain(f(xs, ys), 1.0, name="synthetic")


def beach(slope: float) -> Terrain:
    """3 m deep up to x = 60 m, then rising at `slope` to a 5 m high shore."""
    return terrain_of(lambda x, y: np.clip(-3.0 + slope * (x - 60.0), -3.0, 5.0))


def keel_below_ground(world: PhysicsWorld, terrain: Terrain, model: VesselModel) -> float:
    """Deepest point of the hull bottoms' corners below the terrain, vertical metres."""
    state = world.states()["v"]
    x, y, z, w = state.orientation
    rot = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    corners = []
    for hull in model.hulls:
        cx, cy, cz = hull.center_m
        for sx in (-1, 1):
            for sy in (-1, 1):
                corners.append(
                    (
                        cx + sx * hull.length_m / 2,
                        cy + sy * hull.beam_m / 2,
                        cz - hull.vertical_extent_m / 2,
                    )
                )
    points = state.position + np.asarray(corners) @ rot.T
    return float(np.max(terrain.height(points[:, 0], points[:, 1]) - points[:, 2]))


def drive(
    world: PhysicsWorld, terrain: Terrain, model: VesselModel, seconds: float
) -> dict[str, float]:
    """Run at the current commands; track the worst keel depth and the kinetic energy."""
    worst, energy = 0.0, []
    for _ in range(round(seconds / DT)):
        world.step()
        state = world.state_arrays()
        assert np.isfinite(state.position).all() and np.isfinite(state.linear_velocity).all()
        worst = max(worst, keel_below_ground(world, terrain, model))
        energy.append(0.5 * model.mass_kg * float(np.sum(state.linear_velocity**2)))
    speed = float(np.linalg.norm(world.states()["v"].linear_velocity))
    return {"worst": worst, "speed": speed, "max_energy": max(energy)}


@pytest.fixture(scope="module")
def catabot() -> VesselModel:
    return load_vessel_model("catabot")


def test_full_thrust_up_a_beach_stops_on_the_surface(catabot: VesselModel) -> None:
    terrain = beach(0.1)
    world = PhysicsWorld([("v", catabot, (50.0, 30.0, 0.0, 0.0))], dt_s=DT, terrain=terrain)
    world.set_thrust("v", [1.0, 1.0])
    cruise = drive(world, terrain, catabot, 12.0)  # reaches top speed before the shore
    assert world.grounding is not None and world.grounding.penetration_m[0] == 0.0
    after = drive(world, terrain, catabot, 18.0)
    state = world.states()["v"]
    assert after["speed"] < 1e-3  # stopped, held by friction and the slope: no creeping
    assert 80.0 < state.position[0] < 100.0  # on the beach, not through it
    assert after["worst"] < 0.03  # keel at most a few cm into the ground, ever
    assert after["max_energy"] <= cruise["max_energy"] * 1.001  # contact adds no energy
    thrust = sum(t.max_forward_n for t in catabot.thrusters)
    assert world.grounding.force_n[0, 0] == pytest.approx(-thrust, abs=1.0)  # holds the thrust


@pytest.mark.parametrize("model_name", ["wamv", "monohull"])
def test_ramming_a_steep_bank_stops_without_tunnelling(model_name: str) -> None:
    """Slope 3 (15 m rise per 5 m pixel): the bow hits a near-wall at top speed."""
    model = load_vessel_model(model_name)
    terrain = beach(3.0)
    world = PhysicsWorld([("v", model, (40.0, 30.0, 0.0, 0.0))], dt_s=DT, terrain=terrain)
    world.set_thrust("v", [1.0] * len(model.thrusters))
    result = drive(world, terrain, model, 25.0)  # hits at ~13 s; heave and pitch then decay
    assert result["speed"] < 1e-3
    assert world.states()["v"].position[0] < 62.0  # the bank is at x = 60 m
    assert keel_below_ground(world, terrain, model) < 0.03 * np.sqrt(10)  # 3 cm, normal
    assert result["worst"] < 0.6  # the impact itself: < 0.2 m along the normal


def test_drop_onto_land_settles_without_bounce(catabot: VesselModel) -> None:
    terrain = terrain_of(lambda x, y: np.full_like(x, 1.0), (80, 80))
    world = PhysicsWorld([("v", catabot, (40.0, 40.0, 2.5, 0.4))], dt_s=DT, terrain=terrain)
    heights = []
    for _ in range(400):
        world.step()
        heights.append(world.states()["v"].position[2])
    landed = int(np.argmax(np.asarray(heights) < 1.2))
    assert max(heights[landed:]) < 1.2  # never bounces back up
    rest = 1.0 - min(h.center_m[2] - h.vertical_extent_m / 2 for h in catabot.hulls)
    assert heights[-1] == pytest.approx(rest, abs=0.005)
    assert world.grounding is not None
    assert world.grounding.force_n[0] == pytest.approx([0, 0, catabot.mass_kg * 9.81], abs=1.0)


def test_friction_sticks_below_mu_and_slips_above(catabot: VesselModel) -> None:
    flat = terrain_of(lambda x, y: np.full_like(x, 1.0), (80, 80))
    world = PhysicsWorld([("v", catabot, (40.0, 40.0, 1.07, 0.0))], dt_s=DT, terrain=flat)
    world.set_thrust("v", [1.0, 1.0])  # 72 N < mu m g = 270 N
    assert sum(t.max_forward_n for t in catabot.thrusters) < 0.4 * catabot.mass_kg * 9.81
    drive(world, flat, catabot, 3.0)
    assert abs(world.states()["v"].position[0] - 40.0) < 0.01
    steep = terrain_of(lambda x, y: 40.0 + 0.8 * (x - 40.0), (80, 80))  # tan > mu = 0.5
    world = PhysicsWorld([("v", catabot, (40.0, 40.0, 40.5, 0.0))], dt_s=DT, terrain=steep)
    drive(world, steep, catabot, 2.0)
    assert world.states()["v"].position[0] < 39.0  # slid downhill


def test_deep_water_terrain_changes_nothing(catabot: VesselModel) -> None:
    """Buoyancy knows nothing about the terrain, and far from it contact costs no force."""
    deep = terrain_of(lambda x, y: np.full_like(x, -20.0), (100, 100))
    runs = []
    for terrain in (None, deep):
        world = PhysicsWorld([("v", catabot, (50.0, 50.0, 0.03, 0.2))], dt_s=DT, terrain=terrain)
        world.set_thrust("v", [1.0, 0.3])
        for _ in range(300):
            world.step()
        runs.append(world.state_arrays())
    assert np.array_equal(runs[0].position, runs[1].position)
    assert np.array_equal(runs[0].linear_velocity, runs[1].linear_velocity)
