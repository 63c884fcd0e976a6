"""The compiled force laws (services/physics/kernels.py): the column law of buoyancy against
a plain NumPy statement of it, NaN carried through (so physics still names a diverging body),
and one compiled type per kernel whatever a run passes (a second compilation would cost
seconds inside a step)."""

from __future__ import annotations

from typing import Any

import numba
import numpy as np
import pytest

from catabot.config.vessel import load_vessel_model
from catabot.config.waves import WaveConfig
from catabot.world import rotations
from catabot.world.waves import WaveField
from services.physics import kernels, wave_pull, wet
from services.physics.control import TwistControllerBank
from services.physics.hydro import Columns, build_columns, buoyancy_wrench
from services.physics.world import PhysicsWorld

MODELS = [load_vessel_model(n) for n in ("catabot", "wamv", "monohull", "buoy")]


def poses(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Random rotations (some capsized) and positions around the waterline."""
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    pos = rng.uniform(-1.0, 1.0, (n, 3)) * [50.0, 50.0, 1.0]
    return rotations.matrices(q), pos


def reference(cols: Columns, rot: np.ndarray, pos: np.ndarray, rho_g: float) -> np.ndarray:
    """The law as hydro.buoyancy_wrench states it, on calm water, one array pass per step."""
    world = np.matmul(rot, cols.bottom_m) + pos[:, :, None]
    rise = cols.height_m * rot[:, 2, 2:3]
    frac = np.clip(-(np.minimum(rise, 0.0) + world[:, 2]) / np.maximum(np.abs(rise), 1e-12), 0, 1)
    force = cols.volume_m3 * frac * rho_g
    along = frac * cols.height_m / 2
    along = np.where(rot[:, 2, 2:3] < 0.0, cols.height_m - along, along)
    moment = np.einsum("nkc,nc->nk", cols.bottom_m, force)
    moment[:, 2] += (force * along).sum(axis=1)
    up = rot[:, 2, :]
    return np.concatenate([force.sum(axis=1)[:, None] * up, np.cross(moment, up)], axis=1)


def test_buoyancy_follows_the_column_law_upright_tilted_and_capsized() -> None:
    models = MODELS * 10
    cols = build_columns(models)
    rot, pos = poses(len(models), seed=4)
    rot[:4] = np.eye(3)  # upright ones too
    got = buoyancy_wrench(cols, rot, pos, density=1025.0, gravity=9.81)
    want = reference(cols, rot, pos, 1025.0 * 9.81)
    assert np.abs(got[:, :3]).max() > 1e3  # some hulls are in the water
    assert got == pytest.approx(want, rel=1e-12, abs=1e-9)


def test_a_nan_pose_gives_a_nan_wrench_not_a_quiet_zero() -> None:
    cols = build_columns(MODELS[:2])
    rot, pos = np.stack([np.eye(3)] * 2), np.zeros((2, 3))
    pos[1, 2] = np.nan
    wrench = buoyancy_wrench(cols, rot, pos, density=1025.0, gravity=9.81)
    assert np.isfinite(wrench[0]).all() and np.isnan(wrench[1, 2])
    tables = (np.eye(6)[None], np.eye(6)[None], np.ones((1, 6)), np.ones((1, 6)), np.ones((1, 1)),
              np.zeros((1, 3)))  # fmt: skip
    nu = np.full((1, 6), np.nan)
    tau = kernels.added_mass(tables, np.array([[0.0, 0.0, 1.0]]), nu, np.zeros((1, 3)),
                             np.zeros((1, 6)), 9.81)  # fmt: skip
    assert np.isnan(tau).all()


@pytest.mark.parametrize("waves", [None, WaveConfig(preset="medium")])
def test_a_stepping_world_reaches_each_kernel_as_the_one_type_warm_up_compiled(
    waves: WaveConfig | None,
) -> None:
    kernels.warm_up()
    wet.warm_up()
    wave_pull.warm_up()
    starts = [(f"v{i}", m, (12.0 * i, 0.0, 0.0, 0.3 * i)) for i, m in enumerate(MODELS[:3])]
    world = PhysicsWorld(
        starts, dt_s=0.01, waves=WaveField(waves, 2) if waves else None, buoys=[("b", (0, 30))]
    )
    bank = TwistControllerBank([m for _, m, _ in starts], dt_s=0.01)
    rows = np.array([1, 2])
    for _ in range(5):
        target = np.array([[1.5, 0.1], [2.0, -0.2]])
        world.set_thrusts(rows, bank.command(rows, target, world.surge_and_yaw_rate(rows)))
        world.step()
    world.surge_and_yaw_rate(rows.astype(np.int32))  # a caller's narrower rows: no new type
    used = [k for k in compiled_kernels() if k.signatures]
    assert len(used) >= 12  # every kernel a step calls, wet.py's included
    for kernel in used:
        assert len(kernel.signatures) == 1, kernel  # e.g. a strided positions view: seconds


def compiled_kernels() -> list[Any]:
    """Every compiled kernel of the physics step (kernels.py, wet.py, wave_pull.py), found,
    not listed,
    so a new one is checked too."""
    found = (getattr(module, name) for module in (kernels, wet, wave_pull) for name in dir(module))
    return [f for f in found if isinstance(f, numba.core.registry.CPUDispatcher)]


def test_surge_and_yaw_rate_are_the_body_frame_states_components() -> None:
    starts = [(f"v{i}", m, (12.0 * i, 0.0, 0.0, 0.7 * i)) for i, m in enumerate(MODELS[:3])]
    world = PhysicsWorld(starts, dt_s=0.01)
    world.set_thrusts(np.arange(3), np.array([[1.0, 0.2], [0.6, -0.4], [1.0, 0.2]]))
    for _ in range(200):
        world.step()
    state, rows = world.state_arrays(), np.array([2, 0])
    measured = world.surge_and_yaw_rate(rows)
    assert measured[:, 0] == pytest.approx(state.linear_velocity[rows, 0], rel=1e-12)
    assert measured[:, 1] == pytest.approx(state.angular_velocity[rows, 2], rel=1e-12)
    assert np.abs(measured).min() > 1e-3  # moving and turning


def test_thrust_commands_clamped_padded_and_refused_whole() -> None:
    world = PhysicsWorld([("cb", MODELS[0], (0, 0, 0, 0)), ("m", MODELS[2], (20, 0, 0, 0))],
                         dt_s=0.01)  # fmt: skip
    table = world._thrusters.command  # 2 thrusters each: padding only in the commands here
    world.set_thrusts(np.array([1, 0]), np.array([[2.0, -0.5, 9.0], [-3.0, 0.25, np.nan]]))
    assert table.tolist() == [[-1.0, 0.25], [1.0, -0.5]]  # the extra column never read
    with pytest.raises(ValueError, match="row 0 is not finite"):
        world.set_thrusts(np.array([1, 0]), np.array([[0.5, 0.5], [np.inf, 0.0]]))
    assert table.tolist() == [[-1.0, 0.25], [1.0, -0.5]]  # nothing stored


def test_poses_are_the_rotation_rules_bit_for_bit() -> None:
    """The compiled pose read is rotations.from_rotvec and rotations.matrices (one rule)."""
    q = np.random.default_rng(4).normal(size=(50, 6)) * [2.0, 2.0, 2.0, 100.0, 100.0, 1.0]
    q[0, :3], q[1, :3] = 0.0, 1e-8  # the small-angle series
    quat, rot = kernels.poses(q)
    assert np.array_equal(quat, rotations.from_rotvec(q[:, :3]))
    assert np.array_equal(rot, rotations.matrices(quat))
    nan = kernels.poses(np.full((1, 6), np.nan))
    assert np.isnan(nan[0]).all() and np.isnan(nan[1]).all()


def test_frame_turns_match_the_matrix_products() -> None:
    rot, _ = poses(40, 5)
    rng = np.random.default_rng(6)
    wrench, vel = rng.normal(size=(40, 6)) * 1e3, rng.normal(size=(40, 6))
    generalized = kernels.to_generalized(rot, wrench)  # [R M, R F]
    assert generalized[:, :3] == pytest.approx(np.einsum("nij,nj->ni", rot, wrench[:, 3:]))
    assert generalized[:, 3:] == pytest.approx(np.einsum("nij,nj->ni", rot, wrench[:, :3]))
    nu, rot_t = kernels.body_twist(rot, vel), rot.transpose(0, 2, 1)  # [R^T v, R^T w]
    assert np.array_equal(nu[:, :3], np.einsum("nij,nj->ni", rot_t, vel[:, 3:]))
    assert np.array_equal(nu[:, 3:], np.einsum("nij,nj->ni", rot_t, vel[:, :3]))
    forces = np.ascontiguousarray(wrench[:, :3])
    assert np.array_equal(kernels.to_body(rot, forces), np.einsum("nij,nj->ni", rot_t, forces))
