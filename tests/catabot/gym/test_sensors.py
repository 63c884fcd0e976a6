"""The env with every observation and twist actions, against a real run: GPS, IMU and the
pooled LiDAR range image arrive from the first observation on and agree with the state."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import catabot.gym  # noqa: F401 - registers the envs

pytestmark = pytest.mark.timeout(240)


def test_sensors_and_twist_actions() -> None:
    env = gym.make("CataBot/Navigate-v0", sensors=["gps", "imu", "lidar"], action="twist",
                   max_steps=10)  # fmt: skip
    try:
        assert env.action_space.shape == (2,)
        obs, _ = env.reset(seed=3)
        for _ in range(8):  # ahead at 1 m/s, turning left
            obs, *_ = env.step(np.array([0.5, 0.4], np.float32))
        assert env.observation_space.contains(obs)
        state, gps, imu, lidar = obs["state"], obs["gps"], obs["imu"], obs["lidar"]
        # the GPS fix (0.5 m noise, one tick older) is where the state puts the vessel
        assert np.hypot(*gps[:2]) == pytest.approx(state[2], abs=2.5)
        assert gps[2] == pytest.approx(0.5)  # its horizontal sigma
        assert np.linalg.norm(imu[:4]) == pytest.approx(1.0, abs=1e-3)  # a unit quaternion
        assert imu[9] == pytest.approx(9.81, abs=1.5)  # specific force: +g up, at rest-ish
        assert imu[6] > 0.05  # the yaw rate commanded, seen by the gyro (noise 0.009)
        assert lidar.shape == (16, 64) and lidar.min() < 50.0  # the water below the horizon
        assert state[7] > 0.1  # getting under way (0.8 s in)
    finally:
        env.close()


def test_station_keeping_holds_the_start_pose_in_the_harbour() -> None:
    env = gym.make("CataBot/StationKeep-v0", max_steps=3)
    try:
        obs, info = env.reset(seed=2)
        assert info["distance_m"] < 0.5  # the goal is where it started, a period ago
        assert obs["state"][5:7] == pytest.approx([0.0, 1.0], abs=0.05)  # its start heading
        rewards = [env.step(np.zeros(2, np.float32))[1] for _ in range(3)]
        assert all(np.isfinite(rewards)) and max(rewards) <= 0.1  # holding costs, never pays
    finally:
        env.close()
