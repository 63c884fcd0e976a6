"""Reward and termination, computed online from what the env observes at each step.

The navigation metrics of a whole run are the recorder's (metrics.json, from recorded
states); an agent needs the same events as they happen, from the state it was given:
- progress: metres closer to the goal since the last step (`rewards.progress` a metre);
- reached (navigate): within `goal_radius_m` of the goal, terminated, `rewards.goal` once;
- collision: another body's hull box overlaps the ego's (oriented boxes in the plane:
  separating axes, every body at once), terminated, `-rewards.collision`;
- grounding: a probe on the ego's hull bottom (a grid over its box, rotated with the
  hull's roll and pitch) at or below the terrain's elevation grid under it, terminated,
  `-rewards.grounding`;
- time-out: `max_steps` steps, truncated (the env's own; the run lasts a little longer).
Hull boxes are the ones physics collides and the sensors cast (`VesselModel.hull_box`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from catabot.bus.messages import BodyStates
from catabot.gym.episode import Goal
from catabot.gym.options import EnvOptions
from catabot.world import rotations
from catabot.world.terrain import Terrain
from catabot.world.terrain_grid import any_in_window
from catabot.world.world import World

PROBES = (5, 3)  # along, across the hull box bottom
SINK_M = 3.0  # deepest a hull dips below its rest draft (heave in a heavy sea)


@dataclass(frozen=True)
class Verdict:
    reward: float
    terminated: bool
    distance_m: float
    reached: bool = False
    collision: str | None = None  # the id of the body hit
    grounded: bool = False


class Judge:
    def __init__(self, world: World, vessel: str, options: EnvOptions) -> None:
        self.options, self.terrain = options, world.terrain
        me = world.body(vessel)
        self.row, self.ids = me.row, world.body_ids
        boxes = [b.model.hull_box() for b in world.bodies]
        lo = np.array([box[0] for box in boxes])
        hi = np.array([box[1] for box in boxes])
        self.centre = (lo + hi)[:, :2] / 2  # each box's centre in its body frame (x, y)
        self.half = (hi - lo)[:, :2] / 2
        self.others = np.array([i != me.row for i in range(len(world.bodies))])
        # a body's box lies within this of its origin: pairs farther apart are not tested
        self.reach = np.hypot(*np.abs(self.centre).T) + np.hypot(*self.half.T)
        self.probes = _probes(lo[me.row], hi[me.row])
        self.shallow = _shallow(world.terrain, self.probes)
        self.goal = Goal(0.0, 0.0, 0.0)
        self.last_distance = 0.0

    def start(self, goal: Goal, bodies: BodyStates) -> float:
        """A new episode: the distance the first step's progress is measured from."""
        self.goal = goal
        self.last_distance = self.distance(bodies)
        return self.last_distance

    def distance(self, bodies: BodyStates) -> float:
        x, y = bodies.position[self.row, :2].tolist()
        return math.hypot(self.goal.x_m - x, self.goal.y_m - y)

    def __call__(self, bodies: BodyStates, action: np.ndarray) -> Verdict:
        w, o = self.options.rewards, self.options
        d = self.distance(bodies)
        reward = w.progress * (self.last_distance - d) - w.distance * d - w.time
        reward -= w.energy * float(np.mean(np.square(action)))
        if w.heading:
            off = math.remainder(self._yaw(bodies) - self.goal.yaw_rad, math.tau)
            reward -= w.heading * abs(off)
        self.last_distance = d
        hit, grounded = self.collision(bodies), self.grounded(bodies)
        reached = o.task == "navigate" and d <= o.goal_radius_m
        reward += w.goal if reached else 0.0
        reward -= w.collision if hit else 0.0
        reward -= w.grounding if grounded else 0.0
        done = reached or hit is not None or grounded
        return Verdict(reward, done, d, reached, hit, grounded)

    def _yaw(self, bodies: BodyStates) -> float:
        return float(rotations.yaw_of_quaternions(bodies.orientation[self.row : self.row + 1])[0])

    def collision(self, bodies: BodyStates) -> str | None:
        """The first other body whose hull box overlaps the ego's in the plane (None):
        two boxes are apart when one of their four edge directions separates them."""
        i, xy = self.row, bodies.position[:, :2]
        apart = np.hypot(*(xy - xy[i]).T)
        rows = np.flatnonzero(self.others & (apart <= self.reach + self.reach[i]))
        if not len(rows):
            return None  # the usual case: nothing within reach
        rows = np.concatenate([[i], rows])  # the ego first, then the bodies within reach
        yaw = rotations.yaw_of_quaternions(bodies.orientation[rows])
        fwd = np.stack([np.cos(yaw), np.sin(yaw)], -1)  # (n, 2) each body's x axis
        lat = np.stack([-fwd[:, 1], fwd[:, 0]], -1)
        offset = self.centre[rows]
        centre = xy[rows] + offset[:, :1] * fwd + offset[:, 1:] * lat
        gap = centre - centre[0]
        me = (fwd[:1], lat[:1], self.half[i : i + 1])
        them = (fwd, lat, self.half[rows])
        overlap = np.ones(len(rows), dtype=bool)
        for axis in (np.broadcast_to(fwd[0], fwd.shape), np.broadcast_to(lat[0], fwd.shape),
                     fwd, lat):  # fmt: skip
            overlap &= np.abs(_dot(gap, axis)) <= _reach(*me, axis) + _reach(*them, axis)
        hits = rows[1:][overlap[1:]]
        return self.ids[int(hits[0])] if len(hits) else None

    def grounded(self, bodies: BodyStates) -> bool:
        """Any hull-bottom probe at or below the ground under it."""
        if self.terrain is None or self.shallow is None:
            return False
        x, y = bodies.position[self.row, :2].tolist()
        mpp, (ny, nx) = self.terrain.metres_per_pixel, self.shallow.shape
        if not self.shallow[min(max(int(y / mpp), 0), ny - 1), min(max(int(x / mpp), 0), nx - 1)]:
            return False  # deep water all around: no probe can reach the ground
        rot = rotations.matrices(bodies.orientation[self.row : self.row + 1])[0]
        points = bodies.position[self.row] + self.probes @ rot.T
        ground = self.terrain.height(points[:, 0], points[:, 1])
        return bool(np.any(points[:, 2] <= ground))


def _probes(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """A grid of points over the hull box's bottom face, body frame."""
    xs = np.linspace(lo[0], hi[0], PROBES[0])
    ys = np.linspace(lo[1], hi[1], PROBES[1])
    gx, gy = np.meshgrid(xs, ys)
    return np.stack([gx.ravel(), gy.ravel(), np.full(gx.size, lo[2])], -1)


def _shallow(terrain: Terrain | None, probes: np.ndarray) -> np.ndarray | None:
    """Pixels from which a probe could touch the ground: ground higher than the hull's
    bottom at rest less `SINK_M` within the probes' reach (plus a pixel)."""
    if terrain is None:
        return None
    reach = float(np.hypot(probes[:, 0], probes[:, 1]).max())
    high = terrain.elevation_m > float(probes[0, 2]) - SINK_M
    return any_in_window(high, math.ceil(reach / terrain.metres_per_pixel) + 1)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("nj,nj->n", np.broadcast_to(a, b.shape), b)


def _reach(fwd: np.ndarray, lat: np.ndarray, half: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """How far boxes (centre at 0) reach along `axis`: the projection of their half sizes."""
    return half[:, 0] * np.abs(_dot(fwd, axis)) + half[:, 1] * np.abs(_dot(lat, axis))
