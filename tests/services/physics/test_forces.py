"""The force model on the awake bodies only (services/physics/forces.py): the same wrench,
bit for bit, as on every body; nothing for sleeping ones; a woken body's forces at once."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.config.environment import WindConfig
from catabot.config.vessel import VesselModel, load_vessel_model
from catabot.world import rotations
from catabot.world.environment import CurrentField, WindField
from services.physics.forces import BodyMotion, Fluid, ForceTables, body_wrench
from services.physics.hydro import ThrusterBank, build_columns
from services.physics.loads import EnvironmentLoads
from services.physics.sea import SeaSampler
from services.physics.wet import ThrustLoad
from services.physics.world import PhysicsWorld

FLUID = Fluid(1025.0, 9.81)
BUOYS = [(f"b{i}", (10.0 + 3.0 * i, 20.0)) for i in range(8)]  # one skeleton of buoys


@pytest.fixture(scope="module")
def models() -> list[VesselModel]:
    """Vessels with and without added mass, then moored buoys."""
    names = ["catabot", "monohull", "wamv", "catabot", "buoy", "buoy", "buoy"]
    return [load_vessel_model(n) for n in names]


def tables_of(models: list[VesselModel]) -> ForceTables:
    anchors = np.full((len(models), 2), np.nan)
    anchors[4:] = [(5.0, 5.0), (6.0, -2.0), (-3.0, 1.0)]
    grid = np.random.default_rng(1).uniform(-0.3, 0.3, (20, 20, 2))
    loads = EnvironmentLoads(
        models,
        gravity=FLUID.gravity,
        current=CurrentField((0.2, 0.1), grid=grid, spacing_m=5.0),
        wind=WindField(WindConfig(speed_mps=6.0), seed=1),
        anchors=anchors,
    )
    linear = np.array([m.damping.linear for m in models], dtype=np.float64)
    quadratic = np.array([m.damping.quadratic for m in models], dtype=np.float64)
    weight = np.array([m.mass_kg for m in models]) * FLUID.gravity
    return ForceTables(build_columns(models), linear, quadratic, loads, weight)


def motion_of(n: int) -> BodyMotion:
    rng = np.random.default_rng(7)
    quat = rotations.from_rotvec(rng.normal(0.0, 0.1, (n, 3)))
    pos = np.column_stack([rng.uniform(-20.0, 20.0, (n, 2)), rng.normal(0.0, 0.05, n)])
    return BodyMotion(rotations.matrices(quat), pos, rng.normal(0.0, 0.5, (n, 6)))


def test_the_awake_rows_get_the_same_wrench_bit_for_bit(models: list[VesselModel]) -> None:
    tables, motion = tables_of(models), motion_of(len(models))
    sea = SeaSampler(models, tables.columns.bottom_m.transpose(0, 2, 1), tables.columns.area_m2)
    bank = ThrusterBank([m.thrusters for m in models], 0.01)
    bank.force_n[...] = np.random.default_rng(3).normal(0.0, 50.0, bank.force_n.shape)
    thrust = ThrustLoad(bank.force_n, bank.unit_wrench, bank.position_m)
    full, _ = body_wrench(tables, motion, sea, thrust, fluid=FLUID, time_s=1.0)
    for rows in (np.array([0, 2, 5]), np.array([1, 3, 4, 6]), np.array([6])):
        part, _ = body_wrench(
            tables.take(rows), motion.take(rows), sea, thrust.take(rows), fluid=FLUID, time_s=1.0
        )
        for name, wrench in part.items():
            np.testing.assert_array_equal(wrench, full[name][rows], err_msg=name)
    assert np.abs(full["wind, moorings and added mass"][4:, :2]).max() > 1.0  # moorings act


def world_of() -> PhysicsWorld:
    """A catamaran at rest facing the first of eight buoys 22 m away."""
    catabot = load_vessel_model("catabot")
    start = (0.0, 0.0, 0.0, float(np.arctan2(20.0, 10.0)))
    return PhysicsWorld([("a", catabot, start)], dt_s=0.01, buoys=BUOYS)


def run(world: PhysicsWorld, steps: int) -> None:
    for _ in range(steps):
        world.step()


def test_sleeping_bodies_carry_no_loads() -> None:
    world = world_of()
    run(world, 300)
    assert world.asleep[1:].all()
    world.set_thrust("a", [0.5, 0.5])
    world.step()
    loads = world._last_loads  # what a divergence report names
    for name, wrench in loads.items():
        assert np.all(wrench[1:] == 0.0), name
        assert wrench.shape == (9, 6)
    assert np.abs(loads["thrust"][0]).max() > 1.0  # the boat pushes (its thrust lags)


def test_a_woken_buoy_feels_its_buoyancy_in_its_first_step() -> None:
    """Waking comes before the forces of a step: a buoy woken without them would fall
    freely for that step (-0.098 m/s)."""
    world = world_of()
    run(world, 300)
    assert world.asleep[1:].all()
    world.set_thrust("a", [1.0, 1.0])
    for _ in range(4000):
        world.step()
        if not world.asleep[1:].all():
            break
    assert not world.asleep[1]  # woken by the boat coming near, in this very step
    heave = world.buoy_state_arrays().linear_velocity[:, 2]
    assert np.abs(heave).max() < 1e-3
