"""IMU model: specific force and angular rate in the body frame (FLU), with noise and bias.

An accelerometer measures specific force f = a - g: the inertial acceleration of its
mounting point minus gravity, in its own axes, so at rest and level it reads +g on z.
`VesselState.linear_acceleration` is the body origin's inertial acceleration expressed in
body axes, and a sensor at lever arm r (body frame) adds alpha x r + w x (w x r).

Errors, per axis and independent (ImuModel's defaults):
- white noise per sample, sigma 0.009 rad/s and 0.021 m/s^2 (VRX's WAM-V IMU). These are
  per-sample values, as VRX specifies them, so they do not change with the rate;
- bias instability, a first-order Gauss-Markov process with correlation time 300 s and
  stationary sigma 0.0008 rad/s (~165 deg/h) and 0.004 m/s^2 (~0.4 mg), typical of
  the low-cost MEMS units on small ASVs. The bias starts drawn from its stationary
  law, so it also plays the turn-on bias;
- bias random walk (rad/s/sqrt(s), m/s^2/sqrt(s)): off by default, because it grows
  without bound over long runs; turn it on to model rate random walk.
With `noise=False` the IMU is ideal. Orientation is passed through from the state.

A sample describes the interval since the one before, as a real IMU's samples integrate (or
filter and decimate) what happened between them. The state's rates describe the last
physics tick, so an IMU as fast as the tick reads them; a slower one averages over its own
interval T: the angular rate from the turn R_prevᵀ R over T, the acceleration from the
world-frame change of velocity over T, in the axes of the interval's middle. An audit's
10 Hz IMU in a 0.6 m sea read the last tick alone: 0.14 / 0.12 / 0.32 m/s² rms off the
interval's mean on x / y / z, and dead reckoning on it was 0.19 m/s off after 18 s.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np

from catabot.bus.messages import ImuSample, Message, VesselState
from catabot.config.sensors import ImuParams
from catabot.config.waves import GRAVITY
from catabot.world import rotations, seeding
from services.sensors.common import (
    Array,
    SensorError,
    finite_vector,
    non_negative,
    rotation_from_quaternion,
)
from services.sensors.mount import Mount

UP = np.array([0.0, 0.0, 1.0])


class ImuModel:
    """One IMU. Deterministic: the same seed and name give the same samples."""

    message: ClassVar[type[Message]] = ImuSample

    def __init__(self, params: ImuParams, mount: Mount, *, gravity: float = GRAVITY) -> None:
        p = params  # validated: sigmas >= 0, tau > 0, all finite (catabot.config.sensors)
        self.sigma = np.array([p.gyro_sigma, p.accel_sigma])
        self.bias_sigma = np.array([p.gyro_bias_instability, p.accel_bias_instability])
        self.walk = np.array([p.gyro_random_walk, p.accel_random_walk])
        self.bias_tau_s = float(p.bias_tau_s)
        self.lever_arm = np.array(p.lever_arm, dtype=np.float64)
        self.gravity = non_negative(gravity, "gravity (m/s^2)")
        self.noise, self.name = mount.noise, mount.name
        self._rng = seeding.rng(mount.seed, mount.name)
        # rows: gyro, accel; Gauss-Markov part drawn from its stationary law, walk from 0
        self._markov = self.bias_sigma[:, None] * self._rng.standard_normal((2, 3))
        self._walked = np.zeros((2, 3))
        self._last_stamp_ns: int | None = None
        self._averages = 0 < mount.tick_ns < mount.period_ns  # slower than the physics tick
        self._before: VesselState | None = None  # the state at the previous sample

    @property
    def bias(self) -> Array:
        """Current bias, rows gyro (rad/s) and accel (m/s^2); zero when noise is off."""
        return (self._markov + self._walked) if self.noise else np.zeros((2, 3))

    def ideal(self, state: VesselState) -> tuple[Array, Array]:
        """Error-free angular rate (rad/s) and specific force (m/s^2) at the sensor, body axes."""
        rot = rotation_from_quaternion(state.orientation)
        w = _angular(state)
        alpha = finite_vector(state.angular_acceleration, "angular_acceleration (rad/s^2)")
        acc = finite_vector(state.linear_acceleration, "linear_acceleration (m/s^2)")
        return w, acc + self._lever(w, alpha) + self.gravity * (rot.T @ UP)  # f = a - g

    def averaged(self, before: VesselState, state: VesselState, dt: float) -> tuple[Array, Array]:
        """The ideal angular rate and specific force averaged over the `dt` seconds from
        `before` to `state`, body axes of the interval's middle."""
        rot0, rot1 = (rotation_from_quaternion(s.orientation) for s in (before, state))
        turn = rotations.to_rotvec(np.array([rotations.quaternion_of_matrix(rot0.T @ rot1)]))[0]
        w = turn / dt
        mid = rot0 @ rotations.matrices(rotations.from_rotvec(0.5 * turn[None, :]))[0]
        dv = rot1 @ _linear(state) - rot0 @ _linear(before)  # world frame
        alpha = (_angular(state) - _angular(before)) / dt
        return w, mid.T @ (dv / dt) + self._lever(w, alpha) + self.gravity * (mid.T @ UP)

    def _lever(self, w: Array, alpha: Array) -> Array:
        """What the sensor at `lever_arm` feels beyond the origin: alpha x r + w x (w x r)."""
        r = self.lever_arm
        return rotations.cross(alpha, r) + rotations.cross(w, rotations.cross(w, r))

    def sample(
        self, state: VesselState, *, tick: int, stamp_ns: int, dt_s: float | None = None
    ) -> ImuSample:
        """One sample; `dt_s` (time since the last sample) defaults to the stamp difference."""
        dt = self._elapsed(stamp_ns, dt_s)
        before, self._before = self._before, state
        if self._averages and before is not None and dt > 0.0:
            rate, force = self.averaged(before, state, dt)
        else:
            rate, force = self.ideal(state)
        if self.noise:
            draws = self._rng.standard_normal((3, 2, 3))  # fixed count: stream stays aligned
            self._propagate_bias(dt, draws[1], draws[2])
            measured = np.stack([rate, force]) + self.bias + self.sigma[:, None] * draws[0]
            rate, force = measured[0], measured[1]
        return ImuSample(
            tick=tick,
            stamp_ns=stamp_ns,
            orientation=tuple(float(v) for v in state.orientation),
            angular_velocity=tuple(float(v) for v in rate),
            linear_acceleration=tuple(float(v) for v in force),
        )

    def _elapsed(self, stamp_ns: int, dt_s: float | None) -> float:
        """Seconds since the previous sample (0 for the first), refusing time running back."""
        last, self._last_stamp_ns = self._last_stamp_ns, stamp_ns
        if dt_s is not None:
            return non_negative(dt_s, "dt_s (s)")
        if last is None:
            return 0.0
        if stamp_ns < last:
            raise SensorError(f"IMU {self.name!r}: stamp_ns went back from {last} to {stamp_ns}")
        return (stamp_ns - last) * 1e-9

    def _propagate_bias(self, dt: float, markov_draw: Array, walk_draw: Array) -> None:
        """Exact discretisation of the Gauss-Markov bias (any dt) plus the random walk."""
        phi = math.exp(-dt / self.bias_tau_s)
        self._markov = phi * self._markov + (
            self.bias_sigma[:, None] * math.sqrt(1.0 - phi * phi) * markov_draw
        )
        self._walked = self._walked + self.walk[:, None] * math.sqrt(dt) * walk_draw


def _linear(state: VesselState) -> Array:
    return finite_vector(state.linear_velocity, "linear_velocity (m/s)")


def _angular(state: VesselState) -> Array:
    return finite_vector(state.angular_velocity, "angular_velocity (rad/s)")
