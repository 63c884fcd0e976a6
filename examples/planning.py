"""Obstacle avoidance for navigate.py: a local occupancy grid from LiDAR returns and a
dynamic-window planner over it. Pure NumPy functions, tested on synthetic scans in
tests/examples/test_planning.py.

The grid is ENU-aligned and centred on the vessel (offsets in metres, not map positions), so a
noisy GPS fix moves the goal a little but never the obstacles. Traffic moves: each occupied
cell carries its object's velocity (tracking.py) and is predicted along it, and since an
estimate is only an estimate, a candidate arc must keep `hull + margin + uncertainty * t`
away from every predicted cell at every time t of its horizon.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.world import rotations

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class GridSpec:
    """The local occupancy grid: which returns count and how they are binned."""

    cell_m: float = 0.5
    half_m: float = 40.0  # the grid spans +-half_m east and north of the vessel
    min_z_m: float = 0.15  # returns lower than this above the vessel's waterline are the sea
    max_z_m: float = 4.0  # higher: bridges, birds, nothing a hull meets
    min_reflectivity: float = 0.18  # intensity x range^2: hulls ~0.29, raindrops < 0.15
    min_hits: int = 2  # a stray return alone in its cell is no hull
    self_m: float = 1.6  # nearer returns are the vessel's own hull and mast

    @property
    def size(self) -> int:
        return round(2 * self.half_m / self.cell_m)


@dataclass(frozen=True)
class Planner:
    """The dynamic window: what the vessel can do in one control period, and how arcs score."""

    max_surge_mps: float = 1.5
    max_yaw_rate_radps: float = 0.5
    surge_accel_mps2: float = 0.4
    yaw_accel_radps2: float = 0.8
    horizon_s: float = 6.0
    step_s: float = 0.5
    hull_m: float = 1.1  # the vessel's circumscribed radius
    margin_m: float = 1.5
    uncertainty_mps: float = 0.3  # how fast an obstacle may stray from its predicted track
    clearance_cap_m: float = 10.0  # farther than this, more room earns nothing
    surges: int = 5
    yaw_rates: int = 15
    w_progress: float = 1.0
    w_clearance: float = 0.35
    w_speed: float = 0.1


def world_offsets(points: F64, mount_xyz: F64, mount_rpy: F64, orientation: F64) -> F64:
    """LiDAR returns (N, 3, sensor frame) as ENU offsets from the vessel's origin (N, 3):
    through the mount into the body frame, then levelled and turned by the IMU's attitude."""
    mount = rotations.rpy(*np.degrees(np.asarray(mount_rpy, np.float64)))
    body = np.asarray(points, np.float64) @ mount.T + np.asarray(mount_xyz)
    attitude = rotations.matrix(orientation)
    if attitude is None:
        raise ValueError(f"orientation {list(orientation)} is not a rotation")
    return body @ attitude.T


def reflectivity(points: F64, intensity: F64) -> F64:
    """Range-corrected intensity (N,): the received power times range squared, which undoes
    the 1 / R^2 spreading (paper eq. 4) and leaves the target's reflectivity. A raindrop is a
    weak, tiny reflector: its returns come out well under a hull's (measured on a 10 mm/h
    run: every raindrop under 0.15, every hull 0.28-0.29), whatever their range."""
    return np.asarray(intensity, np.float64) * np.einsum("ij,ij->i", points, points)


def occupancy(offsets: F64, reflectivities: F64, spec: GridSpec) -> NDArray[np.bool_]:
    """Occupied cells (size, size), row = north, column = east, the vessel at the centre.

    A return counts when it is reflective enough (not rain), above the sea and below
    `max_z_m`, beyond the vessel's own hull and inside the grid; a cell is occupied with at
    least `min_hits` returns. No label of the scan is read: a real sensor has none."""
    p = np.asarray(offsets, np.float64)
    keep = np.asarray(reflectivities) >= spec.min_reflectivity
    keep &= (p[:, 2] > spec.min_z_m) & (p[:, 2] < spec.max_z_m)
    keep &= np.hypot(p[:, 0], p[:, 1]) > spec.self_m
    keep &= (np.abs(p[:, 0]) < spec.half_m) & (np.abs(p[:, 1]) < spec.half_m)
    n = spec.size
    col = np.clip(((p[keep, 0] + spec.half_m) / spec.cell_m).astype(np.int64), 0, n - 1)
    row = np.clip(((p[keep, 1] + spec.half_m) / spec.cell_m).astype(np.int64), 0, n - 1)
    hits = np.bincount(row * n + col, minlength=n * n).reshape(n, n)
    return hits >= spec.min_hits


def cell_grid(spec: GridSpec) -> F64:
    """(size, size, 2) east, north offsets of every cell's centre."""
    centre = np.arange(spec.size) * spec.cell_m - spec.half_m + spec.cell_m / 2
    east, north = np.meshgrid(centre, centre)
    return np.stack([east, north], axis=-1)


def cell_centres(grid: NDArray[np.bool_], spec: GridSpec) -> F64:
    """(M, 2) east, north offsets of the occupied cells' centres."""
    rows, cols = np.nonzero(grid)
    return np.stack([cols, rows], axis=1).astype(np.float64) * spec.cell_m + (
        spec.cell_m / 2 - spec.half_m
    )


def window(surge: float, yaw_rate: float, period_s: float, top: float, p: Planner) -> F64:
    """(K, 2) candidate (surge, yaw rate) pairs reachable within one control period, the
    surge at most `top`."""
    du, dr = p.surge_accel_mps2 * period_s, p.yaw_accel_radps2 * period_s
    high = max(0.0, min(top, p.max_surge_mps, surge + du))
    u = np.linspace(min(max(0.0, surge - du), high), high, p.surges)
    r = np.linspace(
        max(-p.max_yaw_rate_radps, yaw_rate - dr), min(p.max_yaw_rate_radps, yaw_rate + dr),
        p.yaw_rates,
    )  # fmt: skip
    uu, rr = np.meshgrid(u, r, indexing="ij")
    return np.stack([uu.ravel(), rr.ravel()], axis=1)


def rollout(candidates: F64, heading: float, p: Planner) -> F64:
    """(K, T, 2) ENU offsets along each constant-(surge, yaw rate) arc at t = step .. horizon,
    in closed form (a straight line where the yaw rate is nil)."""
    t = np.arange(1, round(p.horizon_s / p.step_s) + 1) * p.step_s
    u, r = candidates[:, :1], candidates[:, 1:]
    straight = np.abs(r) < 1e-6
    rs = np.where(straight, 1.0, r)
    psi = heading + r * t
    x = np.where(straight, u * t * np.cos(heading), u / rs * (np.sin(psi) - np.sin(heading)))
    y = np.where(straight, u * t * np.sin(heading), u / rs * (np.cos(heading) - np.cos(psi)))
    return np.stack([x, y], axis=-1)


def clearance(paths: F64, obstacles: F64, velocities: F64, p: Planner) -> F64:
    """(K,) the least room each path keeps from the obstacle cells (M, 2) moving at
    `velocities` (M, 2), in metres beyond `hull + margin + uncertainty * t` (negative: the
    path may meet one); `clearance_cap_m` with no obstacle at all."""
    if len(obstacles) == 0:
        return np.full(len(paths), p.clearance_cap_m)
    t = np.arange(1, paths.shape[1] + 1) * p.step_s
    ahead = obstacles[None, :, :] + velocities[None, :, :] * t[:, None, None]  # (T, M, 2)
    gap = paths[:, :, None, :].astype(np.float32) - ahead[None].astype(np.float32)
    nearest = np.sqrt(np.einsum("ktmi,ktmi->ktm", gap, gap).min(axis=2))  # (K, T)
    room = nearest - (p.hull_m + p.margin_m + p.uncertainty_mps * t)
    return np.minimum(room.min(axis=1), p.clearance_cap_m)


def choose(
    surge: float, yaw_rate: float, heading: float, goal: F64, obstacles: F64,
    velocities: F64, period_s: float, p: Planner,
) -> tuple[float, float]:  # fmt: skip
    """The (surge, yaw rate) to command: the admissible arc that best trades progress to the
    goal (an ENU offset), clearance and speed; with none admissible, the one with most room
    at the lowest speed (slow down and turn away). Obstacles out of reach are left out."""
    distance = float(np.hypot(*goal))
    cands = window(surge, yaw_rate, period_s, max(0.2, distance / 4.0), p)  # slow near the goal
    paths = rollout(cands, heading, p)
    reach = p.max_surge_mps * p.horizon_s + p.hull_m + p.margin_m + p.clearance_cap_m
    speed = np.hypot(velocities[:, 0], velocities[:, 1]) + p.uncertainty_mps
    near = np.hypot(obstacles[:, 0], obstacles[:, 1]) < reach + speed * p.horizon_s
    room = clearance(paths, obstacles[near], velocities[near], p)
    end = np.hypot(goal[0] - paths[:, -1, 0], goal[1] - paths[:, -1, 1])
    progress = (distance - end) / (p.max_surge_mps * p.horizon_s)
    score = (
        p.w_progress * progress
        + p.w_clearance * np.clip(room, 0.0, None) / p.clearance_cap_m
        + p.w_speed * cands[:, 0] / p.max_surge_mps
    )
    ok = room >= 0.0
    if not ok.any():
        best = int(np.lexsort((cands[:, 0], -room))[0])
    else:
        best = int(np.argmax(np.where(ok, score, -np.inf)))
    return float(cands[best, 0]), float(cands[best, 1])
