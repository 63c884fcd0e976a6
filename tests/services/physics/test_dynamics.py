"""Physics core against analytic results: Archimedes, the damping law, turning, determinism."""

from __future__ import annotations

import json
import math
from pathlib import Path

import dartpy as dart
import numpy as np
import pytest

from catabot.config.vessel import VesselModel, VesselModelError, load_vessel_model
from catabot.world import rotations
from services.physics.diverged import PhysicsDiverged
from services.physics.hydro import (
    Columns,
    buoyancy_wrench,
    hull_columns,
)
from services.physics.world import PhysicsWorld

DT = 0.01
RHO = 1025.0


def run(world: PhysicsWorld, seconds: float) -> None:
    for _ in range(round(seconds / DT)):
        world.step()


@pytest.fixture(scope="module")
def catabot() -> VesselModel:
    return load_vessel_model("catabot")


def test_dart_free_joint_convention() -> None:
    """The convention world.py relies on: world-frame velocities and forces in a FreeJoint."""
    world = dart.simulation.World()
    world.setGravity([0.0, 0.0, 0.0])
    skel = dart.dynamics.Skeleton("probe")
    _, body = skel.createFreeJointAndBodyNodePair()
    world.addSkeleton(skel)
    skel.setPositions([0.0, 0.0, math.pi / 2, 1.0, 2.0, 3.0])  # yawed 90 degrees
    skel.setVelocities([0.1, 0.2, 0.3, 1.0, 0.0, 0.0])
    assert np.allclose(body.getLinearVelocity(), [1.0, 0.0, 0.0])  # world frame, not body
    assert np.allclose(body.getAngularVelocity(), [0.1, 0.2, 0.3])
    assert np.allclose(body.getWorldTransform().translation(), [1.0, 2.0, 3.0])


def test_reported_state_matches_dart_body(catabot: VesselModel) -> None:
    """Pose and body-frame twist read from generalized vectors agree with DART's own frames."""
    world = PhysicsWorld([("cb", catabot, (1.0, 2.0, 0.05, 2.0))], dt_s=DT)
    world.set_thrust("cb", [1.0, -0.5])
    run(world, 1.5)
    state = world.states()["cb"]
    body = world._skeletons[0].getBodyNode(0)
    transform = body.getWorldTransform()
    rot = rotations.matrices(state.orientation[None])[0]
    assert np.allclose(rot, transform.rotation(), atol=1e-12)
    assert np.allclose(state.position, transform.translation(), atol=1e-12)
    spatial = body.getSpatialVelocity()  # body frame [angular, linear]
    assert np.allclose(state.angular_velocity, spatial[:3], atol=1e-12)
    assert np.allclose(state.linear_velocity, spatial[3:], atol=1e-12)
    assert abs(state.angular_velocity[2]) > 0.05 and world.time_s == pytest.approx(1.5)


def test_settles_at_archimedes_draft(catabot: VesselModel) -> None:
    world = PhysicsWorld([("cb", catabot, (0.0, 0.0, 0.04, 0.3))], dt_s=DT, water_density=RHO)
    run(world, 8.0)
    state = world.states()["cb"]
    waterplane = sum(h.length_m * h.beam_m for h in catabot.hulls)
    expected = catabot.mass_kg / (RHO * waterplane)
    bottom = min(h.center_m[2] - h.vertical_extent_m / 2 for h in catabot.hulls)
    draft = -(state.position[2] + bottom)
    assert draft == pytest.approx(expected, rel=0.02)
    assert np.abs(state.linear_velocity).max() < 1e-3
    assert np.abs(state.orientation[:2]).max() < 1e-3  # level: no roll or pitch left


def test_cylinder_columns_match_circular_segment() -> None:
    """WAM-V hulls: column buoyancy at the exact equilibrium draft carries the weight (< 1%)."""
    wamv = load_vessel_model("wamv")
    rho = 997.77
    r, length = wamv.hulls[0].beam_m / 2, wamv.hulls[0].length_m
    area = wamv.mass_kg / rho / 2 / length

    def segment(d: float) -> float:
        return r * r * math.acos((r - d) / r) - (r - d) * math.sqrt(2 * r * d - d * d)

    lo, hi = 0.0, 2 * r
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if segment(mid) < area else (lo, mid)
    draft = lo
    cols = _columns_of(wamv)
    keel = wamv.hulls[0].center_m[2] - r
    pos = np.array([[0.0, 0.0, -(keel + draft)]])
    wrench = buoyancy_wrench(cols, np.eye(3)[None], pos, density=rho, gravity=9.81)
    assert wrench[0, 2] == pytest.approx(wamv.mass_kg * 9.81, rel=0.01)


def test_steady_surge_speed_matches_damping_law(catabot: VesselModel) -> None:
    world = PhysicsWorld([("cb", catabot, (0.0, 0.0, 0.0, 0.0))], dt_s=DT, water_density=RHO)
    world.set_thrust("cb", [1.0, 1.0])
    run(world, 20.0)
    thrust = sum(t.max_forward_n for t in catabot.thrusters)
    x_u, x_uu = catabot.damping.linear[0], catabot.damping.quadratic[0]
    expected = (-x_u + math.sqrt(x_u * x_u + 4 * x_uu * thrust)) / (2 * x_uu)
    state = world.states()["cb"]
    assert state.linear_velocity[0] == pytest.approx(expected, rel=0.01)
    assert np.allclose(world.thruster_forces("cb"), [36.0, 36.0])


def test_more_starboard_thrust_turns_left(catabot: VesselModel) -> None:
    starboard = [t.position_m[1] < 0 for t in catabot.thrusters]
    world = PhysicsWorld([("cb", catabot, (0.0, 0.0, 0.0, 0.0))], dt_s=DT, water_density=RHO)
    world.set_thrust("cb", [1.0 if s else 0.2 for s in starboard])
    run(world, 3.0)
    state = world.states()["cb"]
    assert state.angular_velocity[2] > 0.1  # counter-clockwise seen from above (FLU/ENU)
    yaw = 2 * math.atan2(state.orientation[2], state.orientation[3])
    assert yaw > 0.1


def test_thrust_command_errors(catabot: VesselModel) -> None:
    world = PhysicsWorld([("cb", catabot, (0.0, 0.0, 0.0, 0.0))], dt_s=DT)
    with pytest.raises(ValueError, match="expected 2 values"):
        world.set_thrust("cb", [1.0])
    with pytest.raises(ValueError, match="value 1 is not finite"):
        world.set_thrust("cb", [0.5, math.nan])
    with pytest.raises(ValueError, match="not finite"):
        world.set_thrust("cb", [math.inf, 0.0])
    with pytest.raises(ValueError, match="unknown vessel id 'nope'"):
        world.set_thrust("nope", [0.0, 0.0])
    world.set_thrust("cb", [5.0, -5.0])  # clamped, not an error
    world.step()
    assert world.thruster_forces("cb")[0] > 0 > world.thruster_forces("cb")[1]


def _bad_model(tmp_path: Path, catabot: VesselModel, edit: dict[str, object]) -> Path:
    data = json.loads(catabot.model_dump_json())
    for key, value in edit.items():
        target = data
        *parents, last = key.split(".")
        for p in parents:
            target = target[int(p)] if p.isdigit() else target[p]
        if value is None:
            del target[last]
        else:
            target[last] = value
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        ({"mass_kg": None}, r"mass_kg: required field missing"),
        ({"mass_kg": -5.0}, r"mass_kg: must be > 0 \(got -5.0\)"),
        ({"hulls.0.length_m": -1}, r"hulls\.0\.length_m: must be > 0 \(got -1\)"),
        (
            {"hulls.1.shape": "sphere"},
            r"hulls\.1\.shape: must be one of 'box' or 'cylinder' \(got 'sphere'\)",
        ),
        ({"hulls.0.height_m": None}, r"hulls\.0\.height_m: required when shape is 'box'"),
        ({"hulls.0.colour": "red"}, r"hulls\.0\.colour: unknown field \(allowed: shape, "),
        ({"inertia_kgm2": [1.0, 1.0, 5.0]}, r"inertia_kgm2: principal moments"),
        ({"damping.linear": [1, 2, 3]}, r"damping\.linear: must be a list of 6 numbers \[X_u"),
        ({"cog_m": [0.0, "x", 0.1]}, r"cog_m\.1: "),
        ({"thrusters.0.max_reverse_n": -3}, r"thrusters\.0\.max_reverse_n: must be >= 0"),
        (
            {"thrusters.1.position_m": [-0.9, -0.4, 0.0]},
            r"thrusters\.1\.position_m: z = 0 m: a thruster pushes only under water",
        ),
        (  # a trial's 1 GN ended the run at 0.08 s blaming buoyancy
            {"thrusters.1.max_forward_n": 1e6},
            r"thrusters\.1\.max_forward_n: the thrusters together give 1\.00004e\+06 N, 1\.85e\+03 "
            r"times the boat's weight \(539\.6 N for mass_kg 55\), over 100: the thrust \(N\) or "
            r"mass_kg in another unit\?",
        ),
        ({"thrusters.0.max_reverse_n": 6e4}, r"thrusters\.0\.max_reverse_n: the thrusters tog"),
    ],
)
def test_bad_vessel_model_names_the_field(
    tmp_path: Path, catabot: VesselModel, edit: dict[str, object], message: str
) -> None:
    path = _bad_model(tmp_path, catabot, edit)
    with pytest.raises(VesselModelError, match=message) as info:
        load_vessel_model("bad.json", base_dir=tmp_path)
    assert str(info.value).startswith("vessel model 'bad.json': ")
    assert path.exists()


def test_unknown_bundled_name_lists_bundled() -> None:
    bundled = r"unknown bundled name \(bundled: buoy, catabot, monohull, wamv\)"
    with pytest.raises(VesselModelError, match=bundled):
        load_vessel_model("titanic")


def test_missing_file_and_bad_json(tmp_path: Path) -> None:
    with pytest.raises(VesselModelError, match="cannot read"):
        load_vessel_model("nowhere.json", base_dir=tmp_path)
    (tmp_path / "broken.json").write_text("{ not json")
    with pytest.raises(VesselModelError, match=r"broken.json: not valid JSON: .*line 1 column 3"):
        load_vessel_model("broken.json", base_dir=tmp_path)


def test_same_inputs_give_identical_bytes(catabot: VesselModel) -> None:
    wamv = load_vessel_model("wamv")

    def simulate() -> bytes:
        vessels = [
            ("a", catabot, (0.0, 0.0, 0.05, 0.1)),
            ("b", wamv, (20.0, 5.0, 0.0, -1.0)),
            ("c", catabot, (-10.0, 3.0, 0.02, 2.5)),
        ]
        world = PhysicsWorld(vessels, dt_s=DT, water_density=RHO)
        for k in range(200):
            world.set_thrust("a", [0.7, -0.3])
            world.set_thrust("b", [math.sin(k * 0.05), 0.9])
            world.set_thrust("c", [1.0, 1.0])
            world.step()
        arrays = world.state_arrays()
        return (
            b"".join(getattr(arrays, f).tobytes() for f in arrays.__dataclass_fields__)
            + np.float64(world.time_s).tobytes()
        )

    assert simulate() == simulate()


def _columns_of(model: VesselModel) -> Columns:
    parts = [hull_columns(h) for h in model.hulls]
    return Columns(*(np.concatenate(p)[None] for p in zip(*parts, strict=True)))


def test_submerged_box_buoyancy_is_archimedes_at_any_attitude(catabot: VesselModel) -> None:
    """Deep under water, tilted or upside down: total = rho*g*V acting at the volume centre."""
    cols = _columns_of(catabot)
    volume = sum(h.length_m * h.beam_m * h.vertical_extent_m for h in catabot.hulls)
    centre = np.mean([h.center_m for h in catabot.hulls], axis=0)
    for rv in ([0.0, 0.0, 0.0], [0.4, -0.3, 1.0], [math.pi * 0.9, 0.2, 0.0]):
        quat = rotations.from_rotvec(np.array([rv]))
        rot = rotations.matrices(quat)
        wrench = buoyancy_wrench(cols, rot, np.array([[0.0, 0.0, -5.0]]), density=RHO, gravity=9.81)
        up = rot[0, 2, :]
        assert np.allclose(wrench[0, :3], RHO * 9.81 * volume * up, rtol=1e-12)
        assert np.allclose(wrench[0, 3:], np.cross(centre, wrench[0, :3]), atol=1e-9)


def test_roll_gives_restoring_moment(catabot: VesselModel) -> None:
    cols = _columns_of(catabot)
    rot = rotations.matrices(rotations.from_rotvec(np.array([[0.1, 0.0, 0.0]])))  # port side up
    wrench = buoyancy_wrench(cols, rot, np.zeros((1, 3)), density=RHO, gravity=9.81)
    assert wrench[0, 3] < -100.0  # pushes the roll back towards level


def test_thruster_first_order_lag(catabot: VesselModel) -> None:
    """After one time constant the delivered force is (1 - 1/e) of the command, exactly."""
    world = PhysicsWorld([("cb", catabot, (0.0, 0.0, 0.0, 0.0))], dt_s=DT)
    world.set_thrust("cb", [1.0, -1.0])
    run(world, catabot.thrusters[0].time_constant_s)
    gain = 1.0 - math.exp(-1.0)
    assert np.allclose(world.thruster_forces("cb"), [36.0 * gain, -28.0 * gain], rtol=1e-9)


def test_a_state_that_stops_being_finite_is_named_with_its_load(catabot: VesselModel) -> None:
    """A thruster's force made infinite (as a bug or a corrupt model would): the step raises
    naming the body and the load, instead of a NaN spreading to every body and sensor."""
    world = PhysicsWorld([("ego", catabot, (0.0, 0.0, 0.0, 0.0))], dt_s=0.01)
    world.step()
    world._thrusters.max_forward_n[0, 0] = np.inf
    world.set_thrust("ego", [1.0, 1.0])
    with pytest.raises(PhysicsDiverged) as info:
        for _ in range(5):
            world.step()
    assert str(info.value).startswith("body 'ego': a load on it is not finite at t = 0.01 s")
    assert "the largest load on it in that step was thrust" in str(info.value)
