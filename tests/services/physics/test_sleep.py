"""Resting buoys (services/physics/sleep.py): they sleep only where nothing can move them,
and wake before anything reaches them."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.config.environment import WindConfig
from catabot.config.vessel import VesselModel, load_vessel_model
from catabot.config.waves import WaveConfig
from catabot.world.environment import WindField
from catabot.world.waves import WaveField
from services.physics.sleep import REST_STEPS
from services.physics.world import PhysicsWorld

DT = 0.01
RHO = 1025.0
BUOYS = [(f"b{i}", (10.0 + 3.0 * i, 20.0)) for i in range(8)]  # one skeleton of buoys


@pytest.fixture(scope="module")
def catabot() -> VesselModel:
    return load_vessel_model("catabot")


def world_of(catabot: VesselModel, **kwargs: object) -> PhysicsWorld:
    return PhysicsWorld(
        [("a", catabot, (0.0, 0.0, 0.0, 0.0))], dt_s=DT, water_density=RHO, buoys=BUOYS, **kwargs
    )  # type: ignore[arg-type]


def run(world: PhysicsWorld, seconds: float) -> None:
    for _ in range(round(seconds / DT)):
        world.step()


def test_buoys_on_calm_water_fall_asleep_at_their_equilibrium(catabot: VesselModel) -> None:
    world = world_of(catabot)
    run(world, 0.5)
    assert not world.asleep.any()  # still for REST_STEPS steps (1 s) first
    run(world, 4.5)
    asleep = world.asleep
    assert not asleep[0] and asleep[1:].all()  # the vessel never sleeps
    assert world._world.getNumSkeletons() == 1  # the buoys' skeleton left DART's world
    before = world.buoy_state_arrays()
    run(world, 1.0)
    after = world.buoy_state_arrays()
    np.testing.assert_array_equal(after.position, before.position)  # held exactly
    assert np.all(after.linear_velocity == 0.0)
    buoy = load_vessel_model("buoy")
    hull = buoy.hulls[0]
    draft = buoy.mass_kg / (RHO * hull.length_m * hull.beam_m)
    bottom = hull.center_m[2] - hull.height_m / 2  # type: ignore[operator]
    np.testing.assert_allclose(-(after.position[:, 2] + bottom), draft, rtol=0.02)


def test_a_vessel_wakes_a_buoy_before_it_reaches_it_and_pushes_it(catabot: VesselModel) -> None:
    world = world_of(catabot)
    run(world, 3.0)
    assert world.asleep[1:].all()
    anchor = np.array(BUOYS[0][1])
    world.set_thrust("a", [1.0, 1.0])  # heading +x along y = 0: turn toward the first buoy
    world.place(
        np.array([0]),
        np.array([[0.0, 0.0, np.arctan2(20.0, 10.0), 0.0, 0.0, 0.0]]),
        np.zeros((1, 6)),
    )
    woke_at = None
    for _ in range(round(40.0 / DT)):
        world.step()
        gap = np.hypot(*(world.state_arrays().position[0, :2] - anchor))
        if woke_at is None and not world.asleep[1]:
            woke_at = gap
        if gap < 1.0:
            break
    assert woke_at is not None and woke_at > 2.0  # awake well before any contact
    assert world._world.getNumSkeletons() == 2  # back in DART's world to be hit
    run(world, 3.0)
    moved = np.hypot(*(world.buoy_state_arrays().position[0, :2] - anchor))
    assert moved > 0.05  # a real collision with a mobile buoy, not a wall


def test_nothing_sleeps_in_waves_or_gusts(catabot: VesselModel) -> None:
    waves = WaveField(WaveConfig(preset="medium"), 1)
    gusty = WindField(WindConfig(speed_mps=5.0, gust_std_mps=1.0), seed=1)
    for world in (world_of(catabot, waves=waves), world_of(catabot, wind=gusty)):
        run(world, 3.0)
        assert not world.asleep.any()


def test_a_steady_wind_lets_them_sleep_and_a_change_wakes_them(catabot: VesselModel) -> None:
    world = world_of(catabot, wind=WindField(WindConfig(speed_mps=5.0), seed=1))
    run(world, 45.0)  # pushed against their moorings, creeping to a stop
    assert world.asleep[1:].all()
    world.wake()  # what a run-time setting does (services/physics/settings.py)
    assert not world.asleep.any()
    world.step()
    assert not world.asleep.any()  # and they count still steps from zero again
    assert REST_STEPS > 1
