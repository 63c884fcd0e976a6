"""The env's observation: a Dict space of float32 arrays, built from one lockstep frame.

- `state` (10,): the goal in the body frame (x forward, y left; m), its distance (m), the
  bearing error (sin, cos), the heading error to the goal's heading (sin, cos; what station
  keeping holds), and the body-frame surge, sway (m/s) and yaw rate (rad/s).
- `gps` (3,): the fix as east, north offsets from the goal (m; converted from latitude and
  longitude about the scenario's origin) and its horizontal sigma (m).
- `imu` (10,): orientation (x, y, z, w), angular velocity (rad/s), specific force (m/s^2).
- `lidar` (rows, columns): ranges (m) from `LidarScan.range_image`, min-pooled to the shape
  (the nearest return in each block: a thin buoy between coarse columns still shows),
  no return or farther than `lidar_range_m` reads as `lidar_range_m`.
The state is exact (the simulator's truth); the sensors carry their modelled noise.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import gymnasium as gym
import numpy as np

from catabot.bus.messages import GpsFix, ImuSample, LidarScan, Message
from catabot.gym.episode import Goal
from catabot.gym.link import Frame
from catabot.gym.options import EnvOptions
from catabot.world import rotations
from catabot.world.geo import EnuFrame

STATE_SIZE, GPS_SIZE, IMU_SIZE = 10, 3, 10
Obs = dict[str, np.ndarray]


def observation_space(options: EnvOptions) -> gym.spaces.Dict:
    inf = np.float32(np.inf)
    parts: dict[str, gym.spaces.Space[Any]] = {
        "state": gym.spaces.Box(-inf, inf, (STATE_SIZE,), np.float32)
    }
    if "gps" in options.sensors:
        parts["gps"] = gym.spaces.Box(-inf, inf, (GPS_SIZE,), np.float32)
    if "imu" in options.sensors:
        parts["imu"] = gym.spaces.Box(-inf, inf, (IMU_SIZE,), np.float32)
    if "lidar" in options.sensors:
        top = np.float32(options.lidar_range_m)
        parts["lidar"] = gym.spaces.Box(np.float32(0.0), top, options.lidar_shape, np.float32)
    return gym.spaces.Dict(parts)


class Observer:
    """Turns frames of one episode into observations (the goal and sensor names fixed)."""

    def __init__(
        self, options: EnvOptions, row: int, names: Mapping[str, str], origin: EnuFrame
    ) -> None:
        self.options, self.row, self.origin = options, row, origin
        self.names = dict(names)  # sensor kind -> the ego's sensor name
        self.goal = Goal(0.0, 0.0, 0.0)

    def __call__(self, frame: Frame) -> Obs:
        obs = {"state": self.state(frame)}
        for kind in self.options.sensors:
            sample = frame.sensors.get(self.names[kind])
            obs[kind] = _READERS[kind](self, sample)
        return obs

    def state(self, frame: Frame) -> np.ndarray:
        b, i, g = frame.bodies, self.row, self.goal
        x, y = float(b.position[i, 0]), float(b.position[i, 1])
        yaw = float(rotations.yaw_of_quaternions(b.orientation[i : i + 1])[0])
        dx, dy = g.x_m - x, g.y_m - y
        c, s = math.cos(yaw), math.sin(yaw)
        ahead, left = c * dx + s * dy, -s * dx + c * dy
        bearing = math.atan2(left, ahead)
        heading = yaw - g.yaw_rad
        u, v, _ = b.linear_velocity[i].tolist()
        r = float(b.angular_velocity[i, 2])
        values = (ahead, left, math.hypot(dx, dy), math.sin(bearing), math.cos(bearing),
                  math.sin(heading), math.cos(heading), u, v, r)  # fmt: skip
        return np.array(values, dtype=np.float32)

    def gps(self, sample: Message | None) -> np.ndarray:
        if not isinstance(sample, GpsFix):
            return np.zeros(GPS_SIZE, np.float32)
        east, north, _ = self.origin.to_enu(sample.latitude, sample.longitude, sample.altitude)
        values = (float(east) - self.goal.x_m, float(north) - self.goal.y_m,
                  sample.horizontal_sigma)  # fmt: skip
        return np.array(values, dtype=np.float32)

    def imu(self, sample: Message | None) -> np.ndarray:
        if not isinstance(sample, ImuSample):
            return np.zeros(IMU_SIZE, np.float32)
        values = (*sample.orientation, *sample.angular_velocity, *sample.linear_acceleration)
        return np.array(values, dtype=np.float32)

    def lidar(self, sample: Message | None) -> np.ndarray:
        top = self.options.lidar_range_m
        if not isinstance(sample, LidarScan):
            return np.full(self.options.lidar_shape, top, np.float32)
        return pooled(sample.range_image, self.options.lidar_shape, top)


def pooled(image: np.ndarray, shape: tuple[int, int], top: float) -> np.ndarray:
    """The nearest range in each block of a (channels, columns) range image, as `shape`.
    Blocks are whole when the sizes divide; otherwise each output cell takes the block of
    input rows/columns that falls in it (at least one)."""
    ranges = np.nan_to_num(np.asarray(image, np.float32), nan=top, posinf=top)
    ranges = np.minimum(ranges, np.float32(top))
    rows, cols = shape
    ranges = _pool_axis(ranges, rows, axis=0)
    return np.ascontiguousarray(_pool_axis(ranges, cols, axis=1), dtype=np.float32)


def _pool_axis(a: np.ndarray, n: int, *, axis: int) -> np.ndarray:
    size = a.shape[axis]
    if size % n == 0:
        moved = np.moveaxis(a, axis, 0)
        blocks = moved.reshape(n, size // n, *moved.shape[1:]).min(axis=1)
        return np.moveaxis(blocks, 0, axis)
    edges = np.minimum((np.arange(n) * size) // n, size - 1)
    return np.minimum.reduceat(a, edges, axis=axis)


_READERS = {"gps": Observer.gps, "imu": Observer.imu, "lidar": Observer.lidar}
