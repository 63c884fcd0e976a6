"""PhysicsWorld: every vessel as a DART free rigid body, driven by vectorised hydro forces.

DART conventions this relies on (checked against dartpy 6.20, see tests): a FreeJoint's
generalized positions are [rotation vector (3), translation (3)] of the body frame in the world;
its generalized velocities are [angular velocity (3), linear velocity of the body-frame origin
(3)] both expressed in the WORLD frame (not the body frame), and its generalized forces are the
matching [torque about the body origin, force at the body origin], world frame. State is read
and forces are written through these generalized vectors, which is much cheaper than querying
body transforms one by one; bodies are trees of a few shared skeletons (fleet.py), so a
step makes a handful of such calls, not three per vessel.

The body node's frame is the vessel's body frame (FLU, origin at the waterline reference
point); the centre of gravity is set as the body's local centre of mass, so reported positions
and velocities are those of the body origin, as the message contract expects.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import dartpy as dart
import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import VesselModel
from catabot.world.environment import CurrentField, WindField
from catabot.world.terrain import Terrain
from catabot.world.waves import WaveField
from services.physics import kernels, wave_pull, wet
from services.physics.diverged import check_finite, check_state
from services.physics.fleet import Fleet, buoy_bodies
from services.physics.forces import AwakeTables, BodyMotion, Fluid, ForceTables, body_wrench, spread
from services.physics.grounding import Grounding
from services.physics.hydro import Array, ThrusterBank, build_columns
from services.physics.loads import EnvironmentLoads
from services.physics.sea import SeaSampler
from services.physics.setup_check import check_setup
from services.physics.sleep import Sleep, plan_radii
from services.physics.wet import ThrustLoad

StartPose = tuple[float, float, float, float]  # x, y, z (m, map ENU), yaw (rad)


@dataclass(frozen=True)
class VesselKinematics:
    """One vessel's state: pose in `map` (ENU), twist and acceleration in the body frame (FLU).

    Accelerations are the body origin's kinematic acceleration (zero when floating at rest; an
    accelerometer there would read it minus the gravity vector), from the change of world
    velocity over the last step, rotated into the current body frame.
    """

    position: Array  # (3,) m
    orientation: Array  # (4,) quaternion x, y, z, w
    linear_velocity: Array  # (3,) m/s
    angular_velocity: Array  # (3,) rad/s
    linear_acceleration: Array  # (3,) m/s^2
    angular_acceleration: Array  # (3,) rad/s^2


@dataclass(frozen=True)
class KinematicsArrays:
    """The same state for every vessel at once, rows in `PhysicsWorld.vessel_ids` order."""

    position: Array  # (N, 3)
    orientation: Array  # (N, 4)
    linear_velocity: Array  # (N, 3)
    angular_velocity: Array  # (N, 3)
    linear_acceleration: Array  # (N, 3)
    angular_acceleration: Array  # (N, 3)


class PhysicsWorld:
    """Vessels and buoys: column buoyancy, Fossen damping, thrusters, environment loads, DART.

    current / wind: fields that carry their own state (the wind's seeded gusts advance once
    per step), so the world needs no seed. buoys: (id, (x, y)) moored at (x, y), see loads.py.
    """

    def __init__(
        self,
        vessels: Sequence[tuple[str, VesselModel, StartPose]],
        *,
        dt_s: float,
        water_density: float = 1025.0,
        gravity: float = 9.81,
        waves: WaveField | None = None,
        terrain: Terrain | None = None,
        current: CurrentField | None = None,
        wind: WindField | None = None,
        buoys: Sequence[tuple[str, tuple[float, float]]] = (),
        buoy_model: VesselModel | None = None,
    ) -> None:
        self._n_vessels = len(vessels)  # buoys are extra bodies, rows after the vessels
        vessels = [*vessels, *buoy_bodies(buoys, buoy_model)]
        check_setup(vessels, dt_s, water_density, gravity)
        self._ids = [vid for vid, _, _ in vessels]
        self._index = {vid: i for i, vid in enumerate(self._ids[: self._n_vessels])}
        models = [model for _, model, _ in vessels]
        self._dt, self._rho, self._g = float(dt_s), float(water_density), float(gravity)
        self._steps = 0
        self._world = dart.simulation.World()
        self._world.setGravity([0.0, 0.0, -self._g])
        self._world.setTimeStep(self._dt)
        # bodies as trees of a few skeletons (fleet.py), buoys in skeletons of their own
        self._fleet = Fleet(vessels, first_buoy=self._n_vessels)
        self._fleet.add_to(self._world)
        self._skeletons = self._fleet.views  # per-body, skeleton-like access
        columns = build_columns(models)
        self._thrusters = ThrusterBank([m.thrusters for m in models], self._dt)
        anchors = np.full((len(models), 2), np.nan)  # buoys are moored where they start
        anchors[self._n_vessels :] = np.reshape([xy for _, xy in buoys], (-1, 2))
        self._loads = EnvironmentLoads(
            models, gravity=self._g, current=current, wind=wind, anchors=anchors
        )
        linear = np.array([m.damping.linear for m in models], dtype=np.float64)
        quadratic = np.array([m.damping.quadratic for m in models], dtype=np.float64)
        weight = np.array([m.mass_kg for m in models]) * self._g
        lift = np.array([m.damping.lift_uv for m in models], dtype=np.float64).reshape(-1, 2)
        tables = ForceTables(columns, linear, quadratic, self._loads, weight,
                             lift if lift.any() else None,
                             wave_pull.PullTable.of(models, columns))  # fmt: skip
        self._tables = AwakeTables(tables)
        self._sea = SeaSampler(models, columns.bottom_m.transpose(0, 2, 1), columns.area_m2)
        self._sea.use(waves)  # eta at the columns, orbital velocity at the origins (sea.py)
        # Bottom contact with the terrain (grounding.py); buoyancy knows nothing about it.
        self._ground = (
            Grounding(terrain, models, self._dt, self._skeletons) if terrain is not None else None
        )
        self._sleep = Sleep(self._fleet, plan_radii(models), self._n_vessels, dt_s=self._dt)
        self._read_state()
        self._acc_w = np.zeros((len(models), 6))
        self._last_loads: dict[str, Array] = {}  # this step's loads by kind, for `diverged`
        self._wet: Array | None = None  # each hull's wetness this step (wet.py)
        kernels.warm_up()  # the compiled force laws load now, not inside the first step
        wet.warm_up()
        wave_pull.warm_up()

    # --- public API -----------------------------------------------------------------

    @property
    def time_s(self) -> float:
        """Simulated time: whole steps times dt, so it does not drift with rounding."""
        return self._steps * self._dt

    @property
    def loads(self) -> EnvironmentLoads:
        """The wind and current loads (run-time settings change them)."""
        return self._loads

    def set_waves(self, waves: WaveField) -> None:
        """A run-time change of the sea (`catabot set waves`), from the next step on."""
        self._sea.use(waves)
        self._sleep.wake_all()

    def wake(self) -> None:
        """Every resting buoy moves again (the environment changed: sleep.py)."""
        self._sleep.wake_all()

    @property
    def sea_method(self) -> str:
        return self._sea.method

    @property
    def asleep(self) -> NDArray[np.bool_]:
        """Which bodies rest this step (rows of vessels then buoys; sleep.py)."""
        return self._sleep.rows_asleep()

    @property
    def vessel_ids(self) -> list[str]:
        return self._ids[: self._n_vessels]

    @property
    def buoy_ids(self) -> list[str]:
        """Moored buoys, rows of `buoy_state_arrays()`."""
        return self._ids[self._n_vessels :]

    def set_thrust(self, vessel_id: str, command: Sequence[float]) -> None:
        """Set a vessel's normalised thruster commands (-1 full reverse .. +1 full forward).

        Raises ValueError for an unknown vessel, a wrong number of values or a non-finite one;
        finite values outside [-1, 1] are clamped. Takes effect from the next `step()`.
        """
        index = self._index.get(vessel_id)
        if index is None:
            raise ValueError(f"unknown vessel id {vessel_id!r} (known: {', '.join(self._ids)})")
        values = np.asarray(command, dtype=np.float64).ravel()
        expected = self._thrusters.count[index]
        if values.size != expected:
            raise ValueError(
                f"thrust command for vessel {vessel_id!r}: expected {expected} values "
                f"(one per thruster), got {values.size}"
            )
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise ValueError(
                f"thrust command for vessel {vessel_id!r}: value {int(bad[0])} is not finite "
                f"({values[bad[0]]})"
            )
        self._thrusters.set_command(index, np.clip(values, -1.0, 1.0))

    def set_thrusts(self, rows: NDArray[np.intp], commands: Array) -> None:
        """Commands for many vessels at once (a controller's output): rows index `vessel_ids`,
        commands (len(rows), >= thrusters) normalised, padding columns ignored; non-finite
        rows are refused (logged by the caller's ValueError), the others clamped to [-1, 1]."""
        commands, rows = np.asarray(commands, dtype=np.float64), np.asarray(rows)
        if commands.ndim != 2 or len(commands) != len(rows) or _outside(rows, self._n_vessels):
            raise ValueError(f"thrust commands of shape {commands.shape} for rows {rows}")
        self._thrusters.set_commands(rows, commands)

    def place(self, rows: NDArray[np.intp], pose: Array, velocity_w: Array) -> None:
        """Start bodies `rows` off rest: `pose` (k, 6) rotation vector and position in `map`,
        `velocity_w` (k, 6) angular and linear velocity in `map` (services/physics/setup.py)."""
        self._sleep.wake_all()
        self._fleet.place(rows, pose, velocity_w)
        self._read_state()

    def step(self) -> None:
        """Advance every vessel by dt: compute all forces vectorised, apply, step DART.
        `PhysicsDiverged` names the body and the load when a state stops being finite."""
        self._sleep.wake_near(self._pos, self._vel_w)  # first: one woken now gets its forces
        self._thrusters.advance()
        generalized = kernels.to_generalized(self._rot, self._body_wrench())
        if self._ground is not None:
            contact = self._ground.generalized_forces(
                self._rot, self._pos, self._vel_w, generalized, wet=self._wet
            )
            generalized += contact
            self._last_loads["terrain contact"] = contact[:, [3, 4, 5, 0, 1, 2]]  # as [F, M]
        check_finite(self._ids, self._last_loads, generalized, self.time_s)
        self._fleet.set_forces(generalized)
        vel_before = self._vel_w
        self._world.step()
        self._steps += 1
        self._loads.advance(self._dt)  # gusts: one draw per step, whatever else happens
        self._read_state()
        self._acc_w = (self._vel_w - vel_before) / self._dt
        check_state(self._ids, self._pos, self._vel_w, self._last_loads, self.time_s)
        self._sleep.settle(self._pos, self._vel_w, steady=self._steady())

    def state_arrays(self) -> KinematicsArrays:
        """Every vessel's state as stacked arrays (copies), rows in `vessel_ids` order."""
        return self._kinematics(slice(0, self._n_vessels))

    def buoy_state_arrays(self) -> KinematicsArrays:
        """Every buoy's state as stacked arrays (copies), rows in `buoy_ids` order."""
        return self._kinematics(slice(self._n_vessels, None))

    def _kinematics(self, rows: slice) -> KinematicsArrays:
        # The four world-frame vectors of each body as rows: v_b^T = v_w^T R, one matmul.
        world = np.concatenate((self._vel_w[rows], self._acc_w[rows]), axis=1).reshape(-1, 4, 3)
        body = np.matmul(world, self._rot[rows])  # (N, 4, 3): w, v, dw/dt, dv/dt
        return KinematicsArrays(
            position=self._pos[rows].copy(),
            orientation=self._quat[rows].copy(),
            linear_velocity=body[:, 1],
            angular_velocity=body[:, 0],
            linear_acceleration=body[:, 3],
            angular_acceleration=body[:, 2],
        )

    def surge_and_yaw_rate(self, rows: NDArray[np.intp]) -> Array:
        """(len(rows), 2): body-frame surge speed u and yaw rate r, what the velocity
        controllers measure (two dot products, not the whole body-frame state)."""
        rows = np.ascontiguousarray(rows, dtype=np.intp)  # the one type the kernel is built for
        return kernels.surge_and_yaw_rate(self._rot, self._vel_w, rows)

    def states(self) -> dict[str, VesselKinematics]:
        """Every vessel's state keyed by vessel id."""
        a = self.state_arrays()
        return {
            vid: VesselKinematics(
                a.position[i],
                a.orientation[i],
                a.linear_velocity[i],
                a.angular_velocity[i],
                a.linear_acceleration[i],
                a.angular_acceleration[i],
            )
            for i, vid in enumerate(self.vessel_ids)
        }

    @property
    def grounding(self) -> Grounding | None:
        """Terrain contact (last step's penetration and force per vessel), None without terrain."""
        return self._ground

    def thruster_forces(self, vessel_id: str) -> Array:
        """Delivered (lagged) force of each thruster of a vessel, newtons."""
        index = self._index[vessel_id]
        return self._thrusters.force_n[index, : self._thrusters.count[index]].copy()

    # --- internals ------------------------------------------------------------------

    def _read_state(self) -> None:
        """Cache pose and world-frame velocity of all vessels from the generalized vectors."""
        q = self._fleet.positions()
        self._vel_w = self._fleet.velocities()
        self._pos = np.ascontiguousarray(q[:, 3:])  # one layout for the compiled kernels
        self._quat, self._rot = kernels.poses(q)

    def _body_wrench(self) -> Array:
        """Every load on the awake bodies (forces.py), body frame; zero rows for the rest."""
        rows, tables = self._tables.of(self._sleep)
        motion = BodyMotion(self._rot, self._pos, self._vel_w)
        bank = self._thrusters
        thrust = ThrustLoad(bank.force_n, bank.unit_wrench, bank.position_m)
        if rows is not None:
            motion, thrust = motion.take(rows), thrust.take(rows)
        fluid = Fluid(self._rho, self._g)
        loads, share = body_wrench(
            tables, motion, self._sea, thrust, fluid=fluid, time_s=self.time_s
        )
        self._wet = None
        if share is not None:  # sleeping bodies rest afloat
            self._wet = np.ones(len(self._ids))
            self._wet[slice(None) if rows is None else rows] = share
        if rows is not None:
            loads = spread(loads, rows, len(self._ids))
        total = loads.pop("total")
        self._last_loads = loads
        return total

    def _steady(self) -> bool:
        """Loads that do not change in time: no waves and no gusts (sleep.py)."""
        wind = self._loads.wind
        return self._sea.calm and (wind is None or not np.any(wind.gust_std))


def _outside(rows: NDArray[np.intp], n: int) -> bool:
    """A row that is not a vessel's (the min and max of a few rows: no temporaries)."""
    return bool(rows.size) and (int(rows.min()) < 0 or int(rows.max()) >= n)
