"""Vessels that start off rest (pose z, roll, pitch; a body-frame velocity) against analytic
results: a heave free decay at the natural period, a boat under way that stays under way."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import parse_scenario
from catabot.config.vessel import load_vessel_model
from catabot.world import rotations
from catabot.world.waves import WaveField
from catabot.world.world import World
from services.physics.setup import build_world
from services.physics.wind import wind_gains

DT = 0.01


def _world(vessel: dict[str, Any]) -> World:
    return World.resolve(parse_scenario({"vessels": [{"id": "a", **vessel}]}))


def test_the_physics_start_is_the_worlds_start_state() -> None:
    pose = {
        "x_m": 3.0,
        "y_m": -2.0,
        "z_m": 0.5,
        "roll_rad": 0.1,
        "pitch_rad": -0.05,
        "yaw_rad": 2.0,
    }
    velocity = {"surge_mps": 1.0, "sway_mps": 0.2, "heave_mps": -0.1, "yaw_rate_radps": 0.3}
    world = _world({"pose": pose, "velocity": velocity})
    start, physics = world.start_states(), build_world(world)
    got = physics.state_arrays()
    assert np.allclose(got.position, start.position, atol=1e-12)
    assert np.allclose(got.orientation, start.orientation, atol=1e-12)
    assert np.allclose(got.linear_velocity, [[1.0, 0.2, -0.1]], atol=1e-12)
    assert np.allclose(got.angular_velocity, [[0.0, 0.0, 0.3]], atol=1e-12)
    rot = rotations.matrices(got.orientation)[0]
    roll = math.atan2(rot[2, 1], rot[2, 2])  # of Rz Ry Rx
    assert roll == pytest.approx(0.1, abs=1e-12)


def test_a_level_start_at_rest_is_the_one_before_these_fields() -> None:
    world = _world({"pose": {"x_m": 1.0, "y_m": 2.0, "yaw_rad": 0.7}})
    start = world.start_states()
    assert start.orientation.tolist() == [[0.0, 0.0, math.sin(0.35), math.cos(0.35)]]
    assert not start.linear_velocity.any() and start.position[0, 2] == 0.0


def test_heave_free_decay_from_above_equilibrium_has_the_natural_period() -> None:
    """z0 = z_eq + 4 cm in calm water: T = 2 pi sqrt((m + a33) / (rho g A_wp)), damped by
    the model's linear heave damping c (zeta = c / (2 sqrt(k (m + a33)))), and it decays."""
    model = load_vessel_model("catabot")
    rho, g = 1025.0, 9.81
    waterplane = sum(h.length_m * h.beam_m for h in model.hulls)
    bottom = min(h.center_m[2] - h.vertical_extent_m / 2 for h in model.hulls)
    z_eq = -bottom - model.mass_kg / (rho * waterplane)  # the bottoms at the draft
    physics = build_world(_world({"pose": {"z_m": z_eq + 0.04}}))
    z = np.empty(400)
    for k in range(z.size):
        physics.step()
        z[k] = physics.state_arrays().position[0, 2]
    mass = model.mass_kg + model.added_mass[2]
    k_heave = rho * g * waterplane
    natural = 2 * math.pi * math.sqrt(mass / k_heave)
    zeta = model.damping.linear[2] / (2 * math.sqrt(k_heave * mass))
    x = z - z_eq
    sign = np.flatnonzero(np.sign(x[:-1]) != np.sign(x[1:]))[:4]  # the first 4 crossings
    crossings = (sign + x[sign] / (x[sign] - x[sign + 1])) * DT
    damped = 2 * np.diff(crossings).mean()
    assert damped == pytest.approx(natural / math.sqrt(1 - zeta**2), rel=0.03)
    assert damped * math.sqrt(1 - zeta**2) == pytest.approx(natural, rel=0.03)
    peaks = [np.abs(x[a:b]).max() for a, b in itertools.pairwise(sign)]
    assert peaks[0] > peaks[1] > peaks[2]  # decays, by about exp(-pi zeta / sqrt(1 - zeta^2))
    assert peaks[1] / peaks[0] == pytest.approx(
        math.exp(-math.pi * zeta / math.sqrt(1 - zeta**2)), rel=0.15
    )
    assert abs(x[-50:]).max() < 0.002  # settled at the hydrostatic equilibrium


def test_a_boat_started_at_top_speed_under_full_thrust_stays_there(tmp_path: Path) -> None:
    """Top speed u solves X_u u + (X_uu + k_x) u^2 = thrust (still air); thrusters without
    lag so the thrust matches from the first step. Heading 0.5 rad: it goes that way."""
    data = load_vessel_model("catabot").model_dump(mode="json")
    for t in data["thrusters"]:
        t["time_constant_s"] = 0.0
    (tmp_path / "fast.json").write_text(json.dumps(data))
    model = load_vessel_model(str(tmp_path / "fast.json"))
    linear, quadratic = model.damping.linear[0], model.damping.quadratic[0]
    quadratic += wind_gains([model], 1.225)[0, 0]
    thrust = sum(t.max_forward_n for t in model.thrusters)
    top = (-linear + math.sqrt(linear**2 + 4 * quadratic * thrust)) / (2 * quadratic)
    vessel = {"model": str(tmp_path / "fast.json"), "pose": {"yaw_rad": 0.5},
              "velocity": {"surge_mps": top}}  # fmt: skip
    physics = build_world(_world(vessel))
    physics.set_thrust("a", [1.0, 1.0])
    speeds = []
    for _ in range(500):
        physics.step()
        speeds.append(physics.state_arrays().linear_velocity[0, 0])
    assert np.allclose(speeds, top, rtol=2e-3)
    x, y, _ = physics.state_arrays().position[0]
    assert math.hypot(x, y) == pytest.approx(top * 5.0, rel=5e-3)
    assert math.atan2(y, x) == pytest.approx(0.5, abs=5e-3)


@pytest.mark.parametrize(
    ("vessel", "message"),
    [
        ({"pose": {"z_m": 500.0}}, "vessels.0.pose.z_m: must be <= 100"),
        ({"pose": {"pitch_rad": 2.0}}, "vessels.0.pose.pitch_rad: must be <= 1.5708"),
        ({"velocity": {"surge_mps": math.nan}}, "vessels.0.velocity.surge_mps: must be a finite"),
        ({"velocity": {"yaw_rate_radps": 9.0}}, "velocity.yaw_rate_radps: must be <= 6.28"),
        ({"velocity": {"surge": 1.0}}, "velocity.surge: unknown field (allowed: surge_mps"),
    ],
)  # fmt: skip
def test_bad_start_states_are_named(vessel: dict[str, Any], message: str) -> None:
    with pytest.raises(ScenarioError) as info:
        parse_scenario({"vessels": [{"id": "a", **vessel}]})
    assert message in str(info.value)


def test_in_waves_every_body_starts_on_the_surface_moving_with_it() -> None:
    """z_m is above the surface at the body's point: set at the calm level, a catamaran in a
    trough fell freely (a_z -9.81 m/s^2 for its first ticks), one under a crest was thrown
    up. On the surface and with the water's velocity, its first accelerations are small."""
    data = {
        "seed": 4,
        "water": {"waves": {"preset": "medium"}},
        "vessels": [{"id": f"v{i}", "pose": {"x_m": 7.0 * i, "y_m": 3.0 * i}} for i in range(4)],
        "buoys": [{"id": "b", "x_m": 40.0, "y_m": -5.0}],
    }
    world = World.resolve(parse_scenario(data))
    sea = WaveField(world.scenario.water.waves, world.scenario.seed)
    start, physics = world.start_states(), build_world(world)
    x, y, z = start.position.T
    assert np.allclose(z, sea.height(x, y), atol=1e-12) and np.ptp(z) > 0.05  # not all at 0
    placed = np.concatenate([physics.state_arrays().position, physics.buoy_state_arrays().position])
    assert np.allclose(placed, start.position, atol=1e-12)
    for _ in range(5):
        physics.step()
        heave = physics.state_arrays().linear_acceleration[:, 2]
        assert np.all(np.abs(heave) < 3.0), heave  # a fraction of g, not a fall


def test_in_waves_every_body_starts_on_the_slope_under_it() -> None:
    """Started level across a sloping sea, a WAM-V (4.9 m hulls, 0.09 m draft) pitched at up
    to 12 rad/s^2 in its first tick; on the slope, with the roll and pitch given taken as
    relative to it, its first ticks are calm."""
    poses = [{"x_m": 12.0 * i, "y_m": 3.0 * i} for i in range(6)]
    poses[5] |= {"roll_rad": 0.1, "yaw_rad": 1.0}  # a roll given: from the slope, not level
    vessels = [{"id": f"v{i}", "model": "wamv", "pose": p} for i, p in enumerate(poses)]
    data = {"seed": 4, "water": {"waves": {"preset": "medium"}}, "vessels": vessels}
    world = World.resolve(parse_scenario(data))
    start, physics = world.start_states(), build_world(world)
    x, y, _ = start.position.T
    normal = world.waves.normal(x, y)
    turned = rotations.matrices(start.orientation)
    assert np.allclose(turned[:5, :, 2], normal[:5], atol=1e-12)  # body z along the normal
    level = rotations.matrices(np.array([rotations.from_rpy(0.1, 0.0, 1.0)]))[0]
    assert np.dot(turned[5, :, 2], normal[5]) == pytest.approx(level[2, 2], abs=1e-12)
    for _ in range(3):
        physics.step()
        spin = physics.state_arrays().angular_acceleration
        assert np.abs(spin[:5]).max() < 1.0, spin  # 9.8 rad/s^2 started level
