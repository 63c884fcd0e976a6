"""navigate.py's obstacle avoidance on synthetic scans: the grid's filters, the arcs, and the
planner closing the loop around obstacles (a kinematic boat, scans made from circles)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from guidance import yaw_of
from planning import (
    GridSpec,
    Planner,
    cell_centres,
    choose,
    clearance,
    occupancy,
    reflectivity,
    rollout,
    window,
    world_offsets,
)

from catabot.world.rotations import matrix as quaternion_matrix

SPEC = GridSpec()
PLAN = Planner()


def hull_points(cx: float, cy: float, radius: float, n: int = 200) -> np.ndarray:
    """Returns off a round hull: a ring of points at two heights above the water."""
    a = np.linspace(0, math.tau, n, endpoint=False)
    ring = np.stack([cx + radius * np.cos(a), cy + radius * np.sin(a), np.full(n, 0.4)], 1)
    return np.concatenate([ring, ring + np.array([0.0, 0.0, 0.3])])


def yaw_quaternion(yaw: float) -> np.ndarray:
    return np.array([0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)])


def test_occupancy_keeps_hulls_and_drops_sea_rain_and_self() -> None:
    rng = np.random.default_rng(0)
    sea = np.column_stack([rng.uniform(-30, 30, (2000, 2)), rng.normal(0, 0.03, 2000)])
    own = np.column_stack([rng.uniform(-0.9, 0.9, (100, 2)), np.full(100, 0.5)])
    boat = hull_points(10.0, -5.0, 1.0)
    r, a = 1.6 + rng.exponential(6.0, 800), rng.uniform(0, math.tau, 800)  # raindrops, dense
    rain = np.column_stack([r * np.cos(a), r * np.sin(a), rng.uniform(0.2, 3.0, 800)])
    points = np.concatenate([sea, own, boat, rain])
    power = np.concatenate([np.full(2100 + len(boat), 0.29), rng.uniform(0.0, 0.15, 800)])
    grid = occupancy(points, power, SPEC)
    centres = cell_centres(grid, SPEC)
    assert len(centres) >= 12  # the hull's rim, every cell of it
    assert np.all(np.abs(np.hypot(centres[:, 0] - 10.0, centres[:, 1] + 5.0) - 1.0) < 0.75)
    assert occupancy(rain, np.full(800, 0.29), SPEC).sum() > 20  # as bright as hulls: kept
    assert not occupancy(np.concatenate([sea, own]), np.full(2100, 1.0), SPEC).any()
    far = hull_points(60.0, 0.0, 1.0)  # outside the 40 m grid
    assert not occupancy(far, np.ones(len(far)), SPEC).any()
    lone = occupancy(np.array([[5.0, 5.0, 0.5]]), np.ones(1), SPEC)  # one return: no hull
    assert not lone.any()


def test_reflectivity_undoes_the_spreading() -> None:
    points = np.array([[3.0, 4.0, 0.0], [0.0, 0.0, 10.0]])
    assert reflectivity(points, np.array([0.01, 0.002])).tolist() == pytest.approx([0.25, 0.2])


def test_points_go_through_mount_and_attitude_into_enu_offsets() -> None:
    ahead = np.array([[10.0, 0.0, 0.0]])
    east = world_offsets(ahead, np.array([0, 0, 1.0]), np.zeros(3), yaw_quaternion(0.0))
    assert east == pytest.approx(np.array([[10.0, 0.0, 1.0]]))
    north = world_offsets(ahead, np.array([0.5, 0, 1.0]), np.zeros(3), yaw_quaternion(math.pi / 2))
    assert north == pytest.approx(np.array([[0.0, 10.5, 1.0]]))
    looking_left = world_offsets(
        ahead, np.zeros(3), np.array([0, 0, math.pi / 2]), yaw_quaternion(0)
    )
    assert looking_left == pytest.approx(np.array([[0.0, 10.0, 0.0]]))
    pitched = np.array([0.0, math.sin(0.1), 0.0, math.cos(0.1)])  # bow down 0.2 rad
    down = world_offsets(ahead, np.zeros(3), np.zeros(3), pitched)
    assert down[0, 2] == pytest.approx(-10 * math.sin(0.2))
    assert yaw_of(yaw_quaternion(2.5)) == pytest.approx(2.5)
    r = quaternion_matrix(np.array([0.1, -0.2, 0.3, 0.9]))
    assert r @ r.T == pytest.approx(np.eye(3))


def test_window_respects_acceleration_and_the_top_speed() -> None:
    cands = window(1.0, 0.0, 0.5, 1.1, PLAN)
    assert cands[:, 0].min() == pytest.approx(0.8) and cands[:, 0].max() == pytest.approx(1.1)
    assert np.abs(cands[:, 1]).max() == pytest.approx(0.4)
    assert window(1.5, 0.0, 0.1, 0.2, PLAN)[:, 0].max() == pytest.approx(0.2)  # near the goal


def test_rollout_arcs_match_integrating_the_motion() -> None:
    cands = np.array([[1.0, 0.0], [1.2, 0.3], [0.8, -0.4]])
    paths = rollout(cands, 0.7, PLAN)
    dt, steps = 0.001, round(PLAN.horizon_s / 0.001)
    for (u, r), path in zip(cands, paths, strict=True):
        heading = 0.7 + r * dt * np.arange(steps)
        xy = np.cumsum(np.stack([u * np.cos(heading), u * np.sin(heading)], 1) * dt, axis=0)
        assert path[-1] == pytest.approx(xy[-1], abs=0.01)


def test_clearance_grows_the_obstacles_with_time() -> None:
    straight = rollout(np.array([[1.0, 0.0], [1.0, 0.5]]), 0.0, PLAN)
    still = np.zeros((1, 2))
    room = clearance(straight, np.array([[5.0, 0.0]]), still, PLAN)
    assert room[0] < 0 < room[1]  # the straight path runs through it, the turn misses it
    crossing = clearance(straight, np.array([[5.0, -5.0]]), np.array([[0.0, 1.0]]), PLAN)
    assert (
        crossing[0] < 0
        and crossing[0] < clearance(straight, np.array([[5.0, -5.0]]), still, PLAN)[0]
    )
    none = np.empty((0, 2))
    assert clearance(straight, none, none, PLAN).tolist() == [10.0, 10.0]


def test_choose_goes_for_the_goal_in_open_water_and_around_a_wall() -> None:
    none = np.empty((0, 2))
    surge, rate = choose(1.5, 0.0, 0.0, np.array([50.0, 0.0]), none, none, 0.1, PLAN)
    assert surge == pytest.approx(1.5) and abs(rate) < 0.06
    _, rate = choose(1.0, 0.0, 0.0, np.array([0.0, 50.0]), none, none, 0.5, PLAN)
    assert rate > 0.3  # goal to the left: turn left
    wall = np.stack([np.full(13, 7.0), np.linspace(-3, 3, 13)], 1)
    surge, rate = choose(1.0, 0.0, 0.0, np.array([50.0, 0.0]), wall, 0 * wall, 0.5, PLAN)
    path = rollout(np.array([[surge, rate]]), 0.0, PLAN)
    assert clearance(path, wall, 0 * wall, PLAN)[0] >= 0 and abs(rate) > 0.1
    boxed = np.stack([np.full(41, 4.0), np.linspace(-10, 10, 41)], 1)
    surge, rate = choose(1.0, 0.0, 0.0, np.array([50.0, 0.0]), boxed, 0 * boxed, 0.5, PLAN)
    assert surge == pytest.approx(0.8) and abs(rate) > 0.1  # no way through: slow, turn away
