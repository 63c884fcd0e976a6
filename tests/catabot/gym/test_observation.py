"""Observations from a frame: the goal in the body frame, sensors converted and pooled."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catabot.bus.messages import BodyStates, GpsFix
from catabot.gym.episode import Goal
from catabot.gym.link import Frame
from catabot.gym.observation import Observer, observation_space, pooled
from catabot.gym.options import env_options
from catabot.world.geo import EnuFrame

ORIGIN = EnuFrame(43.7, -72.3, 0.0)


def frame(x: float, y: float, yaw: float, u: float = 0.0, sensors: dict | None = None) -> Frame:
    pos = np.array([[x, y, 0.0]])
    quat = np.array([[0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)]])
    vel = np.array([[u, 0.1, 0.0]])
    rate = np.array([[0.0, 0.0, 0.05]])
    zero = np.zeros((1, 3))
    bodies = BodyStates(9, 10**8, ("ego",), pos, quat, vel, rate, zero, zero)
    return Frame(10, 10**8, bodies, sensors or {})


def test_state_puts_the_goal_in_the_body_frame() -> None:
    obs = Observer(env_options(), 0, {}, ORIGIN)
    obs.goal = Goal(10.0, 10.0, math.pi / 2)
    facing_north = obs.state(frame(10.0, 0.0, math.pi / 2, u=1.5))
    ahead, left, dist, s_b, c_b, s_h, c_h, u, v, r = facing_north.tolist()
    assert (ahead, left, dist) == pytest.approx((10.0, 0.0, 10.0), abs=1e-5)
    assert (s_b, c_b, s_h, c_h) == pytest.approx((0.0, 1.0, 0.0, 1.0), abs=1e-6)
    assert (u, v, r) == pytest.approx((1.5, 0.1, 0.05))
    facing_east = obs.state(frame(10.0, 0.0, 0.0))
    assert facing_east[:2] == pytest.approx((0.0, 10.0), abs=1e-5)  # the goal to port
    assert facing_east[3:5] == pytest.approx((1.0, 0.0), abs=1e-6)  # 90 degrees to the left


def test_gps_is_metres_from_the_goal() -> None:
    obs = Observer(env_options(sensors=["gps"]), 0, {"gps": "gps"}, ORIGIN)
    obs.goal = Goal(100.0, 50.0, 0.0)
    lat, lon, alt = ORIGIN.to_geodetic(130.0, 20.0, 0.0)
    fix = GpsFix(5, 5 * 10**7, float(lat), float(lon), float(alt), 0.5, 1.0)
    out = obs(frame(0, 0, 0, sensors={"gps": fix}))
    assert out["gps"] == pytest.approx([30.0, -30.0, 0.5], abs=1e-3)
    assert out["gps"].dtype == np.float32
    assert observation_space(obs.options)["gps"].contains(out["gps"])


def test_lidar_is_the_nearest_range_of_each_block() -> None:
    image = np.full((16, 256), np.inf, np.float32)
    image[3, 130] = 7.5  # one return between coarse columns
    image[15, 0:4] = [80.0, 60.0, np.nan, 90.0]
    out = pooled(image, (16, 64), 50.0)
    assert out.shape == (16, 64) and out.dtype == np.float32
    assert out[3, 32] == 7.5 and out[3, 31] == 50.0 and out[3, 33] == 50.0
    assert out[15, 0] == 50.0  # beyond the range read as the range
    assert np.count_nonzero(out < 50.0) == 1
    uneven = pooled(np.arange(30, dtype=np.float32).reshape(5, 6), (2, 4), 100.0)
    assert uneven.shape == (2, 4) and uneven[0, 0] == 0.0 and uneven[1, 3] == 16.0
