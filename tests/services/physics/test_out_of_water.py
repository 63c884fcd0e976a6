"""A hull out of the water feels no water: a dropped boat falls freely until it touches the
surface, a propeller in the air pushes nothing, and damping and added mass come back as the
hull enters the water (services/physics/forces.py `wetness`, hydro.py `ThrustLoad`)."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.config.vessel import VesselModel, load_vessel_model
from catabot.config.waves import WaveConfig
from catabot.world import rotations
from catabot.world.waves import WaveField
from services.physics.added_mass import AddedMass
from services.physics.wet import scaled_added_mass
from services.physics.world import PhysicsWorld

DT, G = 0.01, 9.81


@pytest.fixture(scope="module")
def catabot() -> VesselModel:
    return load_vessel_model("catabot")


def test_a_dropped_boat_falls_freely_until_it_meets_the_water(catabot: VesselModel) -> None:
    """From 10 m: the semi-implicit Euler fall of g exactly (it fell at 1.2 m/s, its weight
    over the water's heave damping, with the heave added mass in the air)."""
    world = PhysicsWorld([("a", catabot, (0.0, 0.0, 10.0, 0.0))], dt_s=DT)
    z = []
    for _ in range(100):
        world.step()
        z.append(world.states()["a"].position[2])
    n = np.arange(1, 101)
    np.testing.assert_allclose(z, 10.0 - G * DT * DT * n * (n + 1) / 2, atol=1e-9)
    assert z[-1] == pytest.approx(10.0 - G / 2, abs=0.06)  # the continuous fall, within a step
    for _ in range(500):  # then it enters the water and floats again
        world.step()
    s = world.states()["a"]
    assert abs(s.position[2]) < 0.05 and np.abs(s.linear_velocity).max() < 0.2


def test_a_propeller_in_the_air_pushes_nothing(catabot: VesselModel) -> None:
    """Full thrust 20 m up: no surge, no pitch (the boat flew forward and pitched 71 degrees
    before reaching the water); under water the same command drives it."""
    world = PhysicsWorld([("a", catabot, (0.0, 0.0, 20.0, 0.0))], dt_s=DT)
    world.set_thrust("a", [1.0, 1.0])
    for _ in range(100):
        world.step()
    s = world.states()["a"]
    assert np.abs(s.linear_velocity[:2]).max() < 1e-9 and np.abs(s.angular_velocity).max() < 1e-9
    afloat = PhysicsWorld([("a", catabot, (0.0, 0.0, 0.0, 0.0))], dt_s=DT)
    afloat.set_thrust("a", [1.0, 1.0])
    for _ in range(100):
        afloat.step()
    assert afloat.states()["a"].linear_velocity[0] > 0.5


def test_a_capsized_boat_whose_propellers_are_in_the_air_does_not_drive(
    catabot: VesselModel,
) -> None:
    world = PhysicsWorld([("a", catabot, (0.0, 0.0, 0.0, 0.0))], dt_s=DT)
    world.place(np.array([0]), np.array([[np.pi, 0.0, 0.0, 0.0, 0.0, 0.2]]), np.zeros((1, 6)))
    world.set_thrust("a", [1.0, 1.0])
    for _ in range(500):
        world.step()
    s = world.states()["a"]
    assert abs(s.position[0]) < 0.05, s.position  # upright, it would have gone ~8 m
    rot = rotations.matrices(np.asarray([s.orientation]))[0]
    assert (s.position + rot @ catabot.thrusters[0].position_m)[2] > 0.0  # in the air indeed


@pytest.mark.parametrize(
    ("sea", "method"),
    [
        (WaveConfig(preset="medium"), "vessel expansions"),
        (
            WaveConfig(significant_height_m=0.3, peak_period_s=4.0, direction_rad=1.2),
            "hull patches",
        ),
    ],
)
def test_in_waves_the_propellers_meet_the_surface_above_them(
    catabot: VesselModel, sea: WaveConfig, method: str
) -> None:
    """Every method of sampling the sea (sea.py) answers for the thrusters too (the exact
    sum at their points: the harbour's chop, on hull patches, crashed physics at tick 0)."""
    vessels = [(n, load_vessel_model(n), (20.0 * i, 0.0, 0.0, 0.0))
               for i, n in enumerate(("catabot", "monohull", "wamv"))]  # fmt: skip
    world = PhysicsWorld(vessels, dt_s=DT, waves=WaveField(sea, seed=1))
    assert world._sea.method.startswith(method)
    world.set_thrusts(np.arange(3), np.ones((3, 2)))
    for _ in range(300):
        world.step()
    assert (world.state_arrays().linear_velocity[:, 0] > 0.5).all()


def test_the_added_mass_of_a_hull_partly_out_of_the_water_is_its_share() -> None:
    """The compiled 6 x 6 solve against NumPy's inverse; a wet row keeps its own tables."""
    models = [load_vessel_model(n) for n in ("catabot", "monohull", "catabot")]
    am = AddedMass(models, G)
    wet = np.array([1.0, 0.3, 0.0])
    inverse, diag, coriolis = scaled_added_mass(am.m_rb, am.inverse, am.diag, am.coriolis_diag, wet)
    scaled = am.diag * wet[:, None]
    expected = np.linalg.inv(am.m_rb + np.einsum("ni,ij->nij", scaled, np.eye(6)))
    np.testing.assert_allclose(inverse, expected, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(diag, scaled)
    np.testing.assert_array_equal(coriolis, am.coriolis_diag * wet[:, None])
    np.testing.assert_array_equal(inverse[0], am.inverse[0])
    with pytest.raises(ValueError, match="one wetness per row"):
        scaled_added_mass(am.m_rb, am.inverse, am.diag, am.coriolis_diag, np.ones(2))
