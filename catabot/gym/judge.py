"""Reward and termination, computed online from what the env observes at each step.

The navigation metrics of a whole run are the recorder's (metrics.json, from recorded
states); an agent needs the same events as they happen, from the state it was given:
- progress: metres closer to the goal since the last step (`rewards.progress` a metre);
- reached (navigate): within `goal_radius_m` of the goal, terminated, `rewards.goal` once;
- collision: another body's hull box overlaps the ego's (the recorder's plan-view boxes and
  separating axes, catabot/world/hulls.py, for the bodies within reach), terminated,
  `-rewards.collision`;
- grounding: one of the ego's hull probes (the points physics pushes off the ground,
  catabot/world/hulls.py), rotated with its roll and pitch, at or below the terrain's
  elevation grid under it, terminated, `-rewards.grounding`;
- time-out: `max_steps` steps, truncated (the env's own; the run lasts a little longer).
Hull boxes are the ones physics collides and the sensors cast (`VesselModel.hull_box`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from catabot.bus.messages import BodyStates
from catabot.gym.episode import Goal
from catabot.gym.options import EnvOptions
from catabot.world import rotations
from catabot.world.hulls import CONTACT_M, box_gaps, footprints, model_probes
from catabot.world.terrain import Terrain
from catabot.world.terrain_grid import any_in_window
from catabot.world.world import World

SINK_M = 3.0  # deepest a hull dips below its rest draft (heave in a heavy sea)


@dataclass(frozen=True)
class Verdict:
    reward: float
    terminated: bool
    distance_m: float
    reached: bool = False
    collision: str | None = None  # the id of the body hit
    grounded: bool = False

    def why(self, steps: int) -> str:
        """The episode's end in words: the run's end reason (log/run.json)."""
        what = ("goal reached" if self.reached else f"collision with {self.collision}"
                if self.collision else "grounded" if self.grounded else "")  # fmt: skip
        return f"episode {'terminated' if what else 'truncated'} after {steps} steps" + (
            f": {what}" if what else ""
        )


class Judge:
    def __init__(self, world: World, vessel: str, options: EnvOptions) -> None:
        self.options, self.terrain = options, world.terrain
        me = world.body(vessel)
        self.row, self.ids = me.row, world.body_ids
        self.centre, self.half = footprints([b.model for b in world.bodies])  # body frame
        self.others = np.arange(len(world.bodies)) != me.row
        # a body's box lies within this of its origin: pairs farther apart are not tested
        self.reach = np.hypot(*np.abs(self.centre).T) + np.hypot(*self.half.T)
        self.probes = model_probes(me.model)
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
        w = self.options.rewards
        d = self.distance(bodies)
        reward = w.progress * (self.last_distance - d) - w.distance * d - w.time
        reward -= w.energy * float(np.mean(np.square(action)))
        if w.heading:
            off = math.remainder(self._yaw(bodies) - self.goal.yaw_rad, math.tau)
            reward -= w.heading * abs(off)
        self.last_distance = d
        hit, grounded, reached = self.collision(bodies), self.grounded(bodies), self.reached(d)
        reward += w.goal if reached else 0.0
        reward -= w.collision if hit else 0.0
        reward -= w.grounding if grounded else 0.0
        done = reached or hit is not None or grounded
        return Verdict(reward, done, d, reached, hit, grounded)

    def reached(self, distance_m: float) -> bool:
        return self.options.task == "navigate" and distance_m <= self.options.goal_radius_m

    def flags(self, bodies: BodyStates) -> dict[str, Any]:
        """The outcome keys of step's info for a frame, so reset's info has them too (a
        vector env's info arrays, code that reads info['collision'] after any call)."""
        return {"reached": self.reached(self.distance(bodies)),
                "collision": self.collision(bodies), "grounded": self.grounded(bodies)}  # fmt: skip

    def _yaw(self, bodies: BodyStates) -> float:
        return float(rotations.yaw_of_quaternions(bodies.orientation[self.row : self.row + 1])[0])

    def collision(self, bodies: BodyStates) -> str | None:
        """The first other body whose hull box overlaps the ego's in the plane (None)."""
        i, xy = self.row, bodies.position[:, :2]
        apart = np.hypot(*(xy - xy[i]).T)
        rows = np.flatnonzero(self.others & (apart <= self.reach + self.reach[i]))
        if not len(rows):
            return None  # the usual case: nothing within reach
        yaw = np.zeros(len(xy))
        both = np.concatenate([[i], rows])
        yaw[both] = rotations.yaw_of_quaternions(bodies.orientation[both])
        c, s = np.cos(yaw[both]), np.sin(yaw[both])
        ox, oy = self.centre[both].T
        centre = np.zeros_like(xy)
        centre[both] = xy[both] + np.stack([c * ox - s * oy, s * ox + c * oy], -1)
        gaps = box_gaps(centre, yaw, self.half, np.full(len(rows), i), rows)
        hits = rows[gaps <= CONTACT_M]  # touching, as the recorder's metrics.json counts it
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


def _shallow(terrain: Terrain | None, probes: np.ndarray) -> np.ndarray | None:
    """Pixels from which a probe could touch the ground: ground higher than the hull's
    bottom at rest less `SINK_M` within the probes' reach (plus a pixel)."""
    if terrain is None:
        return None
    reach = float(np.hypot(probes[:, 0], probes[:, 1]).max())
    high = terrain.elevation_m > float(probes[:, 2].min()) - SINK_M
    return any_in_window(high, math.ceil(reach / terrain.metres_per_pixel) + 1)
