"""Physics with current, wind, added mass, collisions and buoys, against analytic results."""

from __future__ import annotations

import math
from typing import Any

import dartpy as dart
import numpy as np
import pytest

from catabot.config.environment import WindConfig, WindZone
from catabot.config.vessel import VesselModel, load_vessel_model
from catabot.world import rotations
from catabot.world.environment import CurrentField, WindField
from services.physics.added_mass import rigid_body_matrix
from services.physics.control import TwistController
from services.physics.fleet import GROUP
from services.physics.wind import wind_gains, wind_wrench
from services.physics.world import PhysicsWorld

DT, RHO = 0.01, 1025.0


def run(world: PhysicsWorld, seconds: float) -> None:
    for _ in range(round(seconds / DT)):
        world.step()


def edited(model: VesselModel, **changes: Any) -> VesselModel:
    return VesselModel.model_validate(model.model_dump() | changes)


def damping_root(linear: float, quadratic: float, force: float) -> float:
    """Speed x >= 0 with linear * x + quadratic * x^2 = force."""
    return (-linear + math.sqrt(linear * linear + 4 * quadratic * force)) / (2 * quadratic)


def world_velocity(world: PhysicsWorld) -> np.ndarray:
    s = world.state_arrays()
    return np.einsum("nij,nj->ni", rotations.matrices(s.orientation), s.linear_velocity)


@pytest.fixture(scope="module")
def catabot() -> VesselModel:
    return load_vessel_model("catabot")


@pytest.fixture(scope="module")
def monohull() -> VesselModel:
    return load_vessel_model("monohull")


# --- added mass -----------------------------------------------------------------------


def test_first_step_acceleration_is_that_of_rigid_plus_added_mass(catabot: VesselModel) -> None:
    """Under water without gravity (no weight, no buoyancy), only thrust acts: DART must
    give (M_RB + M_A)^-1 tau."""
    thrusters = [t.model_copy(update={"time_constant_s": 0.0}) for t in catabot.thrusters]
    model = edited(catabot, thrusters=thrusters, added_mass=(150.0, 20.0, 80.0, 10.0, 30.0, 40.0))
    world = PhysicsWorld([("a", model, (0.0, 0.0, -5.0, 0.0))], dt_s=DT, gravity=0.0)
    world.set_thrust("a", [1.0, 0.4])
    world.step()
    f = [36.0, 14.4]
    tau = np.zeros(6)
    for t, force in zip(model.thrusters, f, strict=True):
        tau[:3] += (force, 0.0, 0.0)
        tau[3:] += np.cross(t.position_m, (force, 0.0, 0.0))
    expected = np.linalg.solve(rigid_body_matrix(model) + np.diag(model.added_mass), tau)
    s = world.state_arrays()  # reported in the end-of-step frame; the start frame is identity
    rot = rotations.matrices(s.orientation)[0]
    got = np.concatenate([rot @ s.linear_acceleration[0], rot @ s.angular_acceleration[0]])
    assert np.allclose(got, expected, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("ratio", [1.0, 5.0])
def test_heave_period_with_large_added_mass(catabot: VesselModel, ratio: float) -> None:
    """A33 = ratio * m: no blow-up, and T = 2 pi sqrt((m + A33) / (rho g A_wp)) within 2 %."""
    a33 = ratio * catabot.mass_kg
    linear = list(catabot.damping.linear)
    linear[2] = 0.0  # undamped heave, so the period is the natural one
    added = (2.75, 21.0, a33, 12.8, 23.9, 6.4)
    damping = catabot.damping.model_dump() | {"linear": linear}
    model = edited(catabot, added_mass=added, damping=damping)
    world = PhysicsWorld([("a", model, (0.0, 0.0, 0.0, 0.0))], dt_s=DT, water_density=RHO)
    z = np.empty(1500)
    for k in range(z.size):
        world.step()
        z[k] = world.state_arrays().position[0, 2]
    centre = 0.5 * (z.max() + z.min())
    up = np.flatnonzero((z[:-1] < centre) & (z[1:] >= centre))
    crossings = (up + (centre - z[up]) / (z[up + 1] - z[up])) * DT
    waterplane = sum(h.length_m * h.beam_m for h in model.hulls)
    expected = 2 * math.pi * math.sqrt((model.mass_kg + a33) / (RHO * 9.81 * waterplane))
    assert np.diff(crossings).mean() == pytest.approx(expected, rel=0.02)
    first, last = np.ptp(z[:300]), np.ptp(z[-300:])
    assert last == pytest.approx(first, rel=0.02)  # neither grows nor decays


def test_top_speed_with_added_mass_matches_damping_law(monohull: VesselModel) -> None:
    world = PhysicsWorld([("m", monohull, (0.0, 0.0, 0.0, 0.0))], dt_s=DT, water_density=RHO)
    world.set_thrust("m", [1.0, 1.0])
    run(world, 15.0)
    thrust = sum(t.max_forward_n for t in monohull.thrusters)
    expected = damping_root(monohull.damping.linear[0], monohull.damping.quadratic[0], thrust)
    assert world.state_arrays().linear_velocity[0, 0] == pytest.approx(expected, rel=0.01)


# --- current --------------------------------------------------------------------------


def test_vessel_without_thrust_drifts_with_the_current(catabot: VesselModel) -> None:
    current = CurrentField((0.3, -0.2))
    world = PhysicsWorld([("a", catabot, (0.0, 0.0, 0.0, 0.7))], dt_s=DT, current=current)
    run(world, 30.0)
    assert np.allclose(world_velocity(world)[0, :2], (0.3, -0.2), rtol=0.02, atol=0.0)


# --- wind -----------------------------------------------------------------------------


def test_terminal_drift_under_steady_wind_head_and_beam(catabot: VesselModel) -> None:
    """k (W - u)^2 = X_u u + X_uu u^2 (head wind) and the same in sway (beam wind)."""
    wind = WindField(WindConfig(speed_mps=10.0, toward_rad=0.0), seed=0)
    vessels = [
        ("head", catabot, (0.0, 0.0, 0.0, 0.0)),
        ("beam", catabot, (0.0, 30.0, 0.0, -math.pi / 2)),  # heads south: wind on starboard
    ]
    world = PhysicsWorld(vessels, dt_s=DT, wind=wind)
    run(world, 40.0)
    k_x, k_y, _ = wind_gains([catabot], 1.225)[0]
    lin, quad = catabot.damping.linear, catabot.damping.quadratic

    def terminal(k: float, a: float, b: float) -> float:  # k (W - s)^2 = a s + b s^2
        return damping_root(a + 2 * k * 10.0, b - k, k * 100.0)

    velocity = world.state_arrays().linear_velocity
    assert velocity[0, 0] == pytest.approx(terminal(k_x, lin[0], quad[0]), rel=0.02)
    assert velocity[1, 1] == pytest.approx(terminal(k_y, lin[1], quad[1]), rel=0.02)


@pytest.mark.parametrize("speed", [0.0, 1e-6])
def test_still_air_drags_a_moving_boat(catabot: VesselModel, speed: float) -> None:
    """Top speed solves X_u u + (X_uu + k_x) u^2 = thrust in still air, and a wind of 1e-6 m/s
    changes nothing: air drag does not switch on with the wind (it used to)."""
    wind = WindField(WindConfig(speed_mps=speed), seed=0)
    world = PhysicsWorld([("a", catabot, (0.0, 0.0, 0.0, 0.0))], dt_s=DT, wind=wind)
    world.set_thrust("a", [1.0, 1.0])
    run(world, 30.0)
    k_x = wind_gains([catabot], 1.225)[0, 0]
    thrust = sum(t.max_forward_n for t in catabot.thrusters)
    linear, quadratic = catabot.damping.linear[0], catabot.damping.quadratic[0]
    expected = damping_root(linear, quadratic + k_x, thrust)
    assert expected < damping_root(linear, quadratic, thrust)
    assert world.state_arrays().linear_velocity[0, 0] == pytest.approx(expected, rel=5e-4)


def test_wind_law_is_vrx_for_the_wamv() -> None:
    """X = 0.5 u|u|, Y = 0.5 v|v|, N = -2 * 0.33 u v on the apparent wind (VRX's plugin)."""
    gains = wind_gains([load_vessel_model("wamv")], 1.225)
    rot = rotations.matrices(np.array([[0.0, 0.0, math.sin(0.3), math.cos(0.3)]]))  # yaw 0.6 rad
    wind = np.array([[4.0, -3.0]])
    nu = np.array([[1.0, 0.5, 0.0, 0.0, 0.0, 0.2]])
    u, v = rot[0, :2, :2].T @ wind[0] - nu[0, :2]
    expected = [0.5 * u * abs(u), 0.5 * v * abs(v), 0, 0, 0, -2 * 0.33 * u * v]
    assert np.allclose(wind_wrench(gains, rot, wind, nu)[0], expected, rtol=1e-4)


def test_quartering_wind_turns_the_bow_downwind(catabot: VesselModel) -> None:
    gains = wind_gains([catabot], 1.225)
    wind_from_port_bow = np.array([[-5.0, -5.0]])  # blows aft and to starboard
    wrench = wind_wrench(gains, np.eye(3)[None], wind_from_port_bow, np.zeros((1, 6)))
    assert wrench[0, 5] < 0  # bow to starboard, away from the wind


def test_only_vessels_inside_a_zone_feel_its_wind(catabot: VesselModel) -> None:
    zones = [
        WindZone(shape="circle", center_m=(0.0, 0.0), radius_m=10.0, speed_mps=12.0),
        WindZone(
            shape="polygon",
            vertices_m=[(40.0, -10.0), (60.0, -10.0), (60.0, 10.0), (50.0, 0.0), (40.0, 10.0)],
            speed_mps=12.0,
            toward_rad=math.pi / 2,
        ),
    ]
    wind = WindField(WindConfig(zones=zones), seed=0)  # calm outside the zones
    starts = {"circle": (0.0, 0.0), "polygon": (50.0, -5.0), "notch": (50.0, 5.0), "out": (25, 0)}
    vessels = [(name, catabot, (x, y, 0.0, 0.0)) for name, (x, y) in starts.items()]
    world = PhysicsWorld(vessels, dt_s=DT, wind=wind)
    run(world, 5.0)
    v = world_velocity(world)
    assert v[0, 0] > 0.3 and abs(v[0, 1]) < 1e-6  # pushed east in the circle
    assert v[1, 1] > 0.2 and abs(v[1, 0]) < 1e-6  # pushed north in the polygon
    assert np.abs(v[2:]).max() < 1e-6  # in the polygon's notch, and outside: calm


def test_gusty_wind_runs_are_identical_per_seed(catabot: VesselModel) -> None:
    def simulate(seed: int) -> bytes:
        wind = WindField(WindConfig(speed_mps=8.0, gust_std_mps=2.0, toward_rad=1.0), seed=seed)
        world = PhysicsWorld([("a", catabot, (0.0, 0.0, 0.0, 0.0))], dt_s=DT, wind=wind)
        run(world, 2.0)
        s = world.state_arrays()
        return s.position.tobytes() + s.linear_velocity.tobytes()

    assert simulate(5) == simulate(5) != simulate(6)


# --- turning and control --------------------------------------------------------------


def test_turn_on_the_spot_matches_yaw_damping_law(catabot: VesselModel) -> None:
    """Equal and opposite thrust: N = N_r r + N_rr r|r| in steady state."""
    world = PhysicsWorld([("a", catabot, (0.0, 0.0, 0.0, 0.0))], dt_s=DT)
    world.set_thrust("a", [-1.0, 28.0 / 36.0])  # port 28 N astern, starboard 28 N ahead
    run(world, 20.0)
    moment = 2 * 0.40 * 28.0
    expected = damping_root(catabot.damping.linear[5], catabot.damping.quadratic[5], moment)
    assert world.state_arrays().angular_velocity[0, 2] == pytest.approx(expected, rel=0.01)


def test_turn_at_speed_matches_manoeuvring_steady_state(catabot: VesselModel) -> None:
    """Surge, sway, yaw balance: centripetal and Munk terms of M_RB + M_A, the hull's lift."""
    world = PhysicsWorld([("a", catabot, (0.0, 0.0, 0.0, 0.0))], dt_s=DT)
    world.set_thrust("a", [0.3, 1.0])
    run(world, 30.0)
    s = world.state_arrays()
    u, v, r = s.linear_velocity[0, 0], s.linear_velocity[0, 1], s.angular_velocity[0, 2]
    m, a, (lift_y, lift_n) = catabot.mass_kg, catabot.added_mass, catabot.damping.lift_uv
    lin, quad = catabot.damping.linear, catabot.damping.quadratic

    def damping(i: int, x: float) -> float:
        return lin[i] * x + quad[i] * x * abs(x)

    thrust, moment = 36.0 * 1.3, 0.40 * 36.0 * 0.7
    assert damping(0, u) - (m + a[1]) * v * r == pytest.approx(thrust, rel=0.02)
    sway = damping(1, v) - lift_y * abs(u) * v + (m + a[0]) * u * r
    assert sway == pytest.approx(0.0, abs=0.02 * thrust) and lift_n != 0.0  # it has a lift
    assert damping(5, r) + (a[1] - a[0] - lift_n) * u * v == pytest.approx(moment, rel=0.02)


@pytest.mark.parametrize(
    ("name", "surge", "yaw_rate"),
    [
        ("catabot", 1.2, 0.1),
        ("catabot", 0.6, -0.2),
        ("monohull", 5.0, math.radians(15)),
    ],  # feasible for the thrusters,
)
def test_twist_controller_reaches_its_set_point(name: str, surge: float, yaw_rate: float) -> None:
    model = load_vessel_model(name)
    world = PhysicsWorld([("a", model, (0.0, 0.0, 0.0, 0.0))], dt_s=DT)
    control = TwistController(model, dt_s=DT)
    for _ in range(round(40.0 / DT)):
        s = world.state_arrays()
        measured = (s.linear_velocity[0, 0], s.angular_velocity[0, 2])
        command = control.command((surge, yaw_rate), measured)
        assert np.all(np.abs(command) <= 1.0)
        world.set_thrust("a", command)
        world.step()
    s = world.state_arrays()
    assert s.linear_velocity[0, 0] == pytest.approx(surge, rel=0.02)
    assert s.angular_velocity[0, 2] == pytest.approx(yaw_rate, rel=0.05)


def test_twist_controller_output_is_clamped_and_turn_has_priority(catabot: VesselModel) -> None:
    control = TwistController(catabot, dt_s=DT)
    command = control.command((50.0, 3.0), (0.0, 0.0))  # far beyond what it can do
    assert np.all(np.abs(command) <= 1.0)
    assert command[1] == 1.0 and command[0] < 0.0  # full yaw moment kept, surge shed
    assert np.all(control.integral == 0.0)  # saturated: the integrator did not wind up


# --- collisions and buoys -------------------------------------------------------------


@pytest.mark.parametrize("idle", [0, GROUP], ids=["same-skeleton", "other-skeleton"])
def test_vessels_driven_head_on_do_not_pass_through(catabot: VesselModel, idle: int) -> None:
    """Contacts within one fleet skeleton and between two (idle vessels in between)."""
    parked = [(f"p{i}", catabot, (100.0 + 10 * i, 50.0, 0.0, 0.0)) for i in range(idle)]
    vessels = [
        ("a", catabot, (0.0, 0.0, 0.0, 0.0)),
        *parked,
        ("b", catabot, (6.0, 0.0, 0.0, math.pi)),
    ]
    world = PhysicsWorld(vessels, dt_s=DT)
    gap = []
    for _ in range(round(8.0 / DT)):
        world.set_thrust("a", [1.0, 1.0])
        world.set_thrust("b", [1.0, 1.0])
        world.step()
        x = world.state_arrays().position[:, 0]
        gap.append(x[-1] - x[0])
    length = catabot.hulls[0].length_m
    assert min(gap) > length - 0.05  # bows meet, hulls do not overlap
    assert gap[-1] < length + 0.05  # and they are pressed together, not far apart


def test_buoy_floats_moored_and_stops_a_vessel(catabot: VesselModel) -> None:
    buoy = load_vessel_model("buoy")
    world = PhysicsWorld(
        [("a", catabot, (-4.0, 0.0, 0.0, 0.0))],
        dt_s=DT,
        water_density=RHO,
        buoys=[("b0", (0.0, 0.0)), ("b1", (20.0, 5.0))],
        current=CurrentField((0.2, 0.0)),
    )
    assert world.vessel_ids == ["a"] and world.buoy_ids == ["b0", "b1"]
    with pytest.raises(ValueError, match="unknown vessel id 'b0'"):
        world.set_thrust("b0", [])
    world.set_thrust("a", [0.6, 0.6])
    run(world, 12.0)
    vessel, buoys = world.state_arrays(), world.buoy_state_arrays()
    draft = buoy.mass_kg / (RHO * buoy.hulls[0].length_m * buoy.hulls[0].beam_m)
    bottom = buoy.hulls[0].center_m[2] - buoy.hulls[0].height_m / 2  # type: ignore[operator]
    assert -(buoys.position[1, 2] + bottom) == pytest.approx(draft, rel=0.02)
    assert np.hypot(*(buoys.position[1, :2] - (20.0, 5.0))) < 1.5  # held (test_loads.py)
    half = (catabot.hulls[0].length_m + buoy.hulls[0].length_m) / 2
    assert vessel.position[0, 0] < buoys.position[0, 0] - half + 0.1  # blocked by buoy b0


def test_fleet_trees_behave_like_separate_skeletons(catabot: VesselModel) -> None:
    """One multi-tree skeleton: row i is body i, and per-tree dynamics match a lone skeleton."""
    monohull = load_vessel_model("monohull")
    vessels = [
        (f"v{i}", (catabot, monohull)[i % 2], (12.0 * i, -4.0 * i, 0.0, 0.3 * i))
        for i in range(GROUP + 3)  # more than one skeleton's worth
    ]
    world = PhysicsWorld(vessels, dt_s=DT)
    for i in range(1, len(vessels), 3):
        world.set_thrust(f"v{i}", [1.0, 0.2])
    run(world, 1.0)
    s = world.state_arrays()
    for i, (name, model, _) in enumerate(vessels):
        view = world._skeletons[i]
        body = view.getBodyNode(0)
        assert body.getName() == view.getName() == name
        assert np.allclose(body.getWorldTransform().translation(), s.position[i], atol=1e-12)
        alone = dart.dynamics.Skeleton(name)
        _, lone = alone.createFreeJointAndBodyNodePair()
        lone.setMass(model.mass_kg)
        lone.setMomentOfInertia(*model.inertia_kgm2, 0.0, 0.0, 0.0)
        lone.setLocalCOM(np.asarray(model.cog_m))
        alone.setGravity([0.0, 0.0, -9.81])
        alone.setPositions(view.getPositions())
        alone.setVelocities(view.getVelocities())
        assert np.allclose(view.getMassMatrix(), alone.getMassMatrix(), rtol=1e-12)
        assert np.allclose(
            view.getCoriolisAndGravityForces(), alone.getCoriolisAndGravityForces(), rtol=1e-12
        )
