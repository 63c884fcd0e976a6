"""navigate.py's moving obstacles: clusters, tracks and velocities on synthetic scans, and the
whole pipeline (grid, tracks, planner) closing the loop around still and crossing boats."""

from __future__ import annotations

import math

import numpy as np
import pytest
from planning import GridSpec, Planner, cell_grid, choose
from tracking import Obstacles, Tracker, Tracks, cell_velocities, centroids, clusters

SPEC = GridSpec()


def test_clusters_group_cells_within_reach() -> None:
    grid = np.zeros((9, 9), bool)
    grid[1, 1:4] = True  # a bar
    grid[2, 4] = True  # touching it diagonally: same object
    grid[6, 6] = grid[6, 7] = True  # another, three cells away
    labels = clusters(grid, reach=1)
    assert labels.max() == 2 and (labels > 0).sum() == 6
    assert labels[1, 1] == labels[2, 4] != labels[6, 6] == labels[6, 7]
    grid[4, 5] = True  # two cells from both
    assert clusters(grid, reach=1).max() == 3 and clusters(grid, reach=2).max() == 1
    assert clusters(np.zeros((4, 4), bool)).max() == 0
    snake = np.zeros((9, 9), bool)  # one long winding object: many propagation passes
    snake[0, :] = snake[:, 8] = snake[8, :] = snake[2:, 0] = True
    assert clusters(snake, reach=1).max() == 1


def test_centroids_are_each_clusters_mean_position() -> None:
    grid = np.zeros((SPEC.size, SPEC.size), bool)
    grid[80, 100:104] = True  # east 10.25 .. 11.75, north 0.25
    labels = clusters(grid)
    assert centroids(labels, cell_grid(SPEC)) == pytest.approx(np.array([[11.0, 0.25]]))


def test_tracks_learn_a_velocity_and_new_objects_start_still() -> None:
    tracker, tracks, dt = Tracker(), Tracks.none(), 0.1
    for k in range(60):
        found = np.array([[10.0 + 1.0 * k * dt, 5.0], [-20.0, -20.0 - 0.5 * k * dt]])
        tracks = tracker.update(tracks, found, dt)
    assert tracks.velocity == pytest.approx(np.array([[1.0, 0.0], [0.0, -0.5]]), abs=0.05)
    assert tracks.seen.tolist() == [60, 60]
    tracks = tracker.update(tracks, np.array([[16.0, 5.0], [30.0, 30.0]]), dt)
    assert tracks.seen.tolist() == [61, 1] and tracks.velocity[1].tolist() == [0.0, 0.0]
    assert len(tracker.update(tracks, np.empty((0, 2)), dt).position) == 0
    jump = tracker.update(Tracks(np.zeros((1, 2)), np.zeros((1, 2)), np.ones(1, np.int64)),
                          np.array([[1.9, 0.0]]), 0.001)  # fmt: skip
    assert np.hypot(*jump.velocity[0]) == pytest.approx(4.0)  # clamped


def test_cells_take_their_objects_velocity_once_it_is_known() -> None:
    labels = np.array([[1, 0, 2], [1, 0, 0]])
    tracks = Tracks(np.zeros((2, 2)), np.array([[1.0, 0.0], [0.0, 2.0]]), np.array([5, 1]))
    assert cell_velocities(labels, tracks, 3).tolist() == [[1.0, 0.0], [0.0, 0.0], [1.0, 0.0]]


def hull_ring(cx: float, cy: float, radius: float, n: int = 80) -> np.ndarray:
    a = np.linspace(0, math.tau, n, endpoint=False)
    ring = np.stack([cx + radius * np.cos(a), cy + radius * np.sin(a), np.full(n, 0.4)], 1)
    return np.concatenate([ring, ring + np.array([0.0, 0.0, 0.3])])


def sail(moving: list[tuple[float, float, float, float, float]], seconds: float = 60.0
         ) -> tuple[float, float, float]:  # fmt: skip
    """A kinematic boat with its velocity controller's lag, steered at 10 Hz by the whole
    pipeline through round obstacles (x, y, radius, vx, vy) seen by a perfect level scan,
    to (45, 0). Returns (time to the goal or inf, nearest gap between hulls, final x)."""
    goal, plan, dt = np.array([45.0, 0.0]), Planner(), 0.1
    position, heading, surge, rate = np.zeros(2), 0.0, 0.0, 0.0
    obstacles, nearest = Obstacles(SPEC, Tracker()), math.inf
    for k in range(round(seconds / dt)):
        now = [(x + vx * k * dt, y + vy * k * dt, r) for x, y, r, vx, vy in moving]
        nearest = min(nearest, *(math.dist(position, (x, y)) - r - plan.hull_m for x, y, r in now))
        if math.dist(position, goal) < 2.0:
            return k * dt, nearest, float(position[0])
        scan = np.concatenate([hull_ring(x - position[0], y - position[1], r) for x, y, r in now])
        cells, velocities = obstacles.update(scan, np.full(len(scan), 0.29), position, dt)
        want = choose(surge, rate, heading, goal - position, cells, velocities, dt, plan)
        surge += (want[0] - surge) * dt / 0.5
        rate += (want[1] - rate) * dt / 0.3
        heading += rate * dt
        position = position + surge * dt * np.array([math.cos(heading), math.sin(heading)])
    return math.inf, nearest, float(position[0])


STILL = [(12.0, 0.5, 2.0, 0.0, 0.0), (25.0, -1.0, 2.5, 0.0, 0.0)]


@pytest.mark.parametrize(
    "traffic",
    [
        [*STILL, (32.0, 12.0, 2.0, 0.0, -0.7)],  # still ones and one crossing from the north
        [(25.0, -22.0, 2.0, 0.0, 1.0), (15.0, 18.0, 2.0, 0.3, -0.8)],  # two crossing
        [(55.0, 0.5, 2.0, -1.0, 0.0)],  # head-on, slightly off the line
    ],
    ids=["still-and-crossing", "two-crossing", "head-on"],
)
def test_the_pipeline_takes_a_boat_through_traffic_to_its_goal(traffic: list) -> None:
    arrived, nearest, _ = sail(traffic)
    assert arrived < 60.0, arrived  # a straight run would take 30 s
    assert nearest > 0.5, nearest  # never within half a metre of a hull
