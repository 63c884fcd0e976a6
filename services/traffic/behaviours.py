"""Traffic behaviours as guidance laws over all boats at once: pose in, twist set-point out.

Every law returns (surge m/s, yaw rate rad/s) per boat for the physics service's
TwistController, so traffic boats are driven by forces exactly like the ego vessel.
They act on the course over ground (heading plus drift angle), not the heading, so a
boat that slips sideways in a turn still holds its circle or its track.
One NumPy pass per tick for 100-500 boats; the per-boat work is only index bookkeeping.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from catabot.config.traffic import MAX_YAW_RATE, TrafficConfig
from catabot.world.rotations import wrap
from catabot.world.traffic_plan import Boat
from services.traffic.avoid import (
    KeepClear,
    Obstacles,
    corridor_turn,
    drifted,
    mark_aim,
    marks_on,
    near_pairs,
)
from services.traffic.colregs import OFFSETS, SPEEDS, choose
from services.traffic.predict import Movers

Array = NDArray[np.float64]
CIRCLE, WAYPOINTS, HOLD = 0, 1, 2
KINDS = {"circle": CIRCLE, "waypoints": WAYPOINTS, "hold": HOLD}
YAW_GAIN = 1.0  # 1/s: yaw rate per radian of course error (pursuit, hold)
CIRCLE_LOOKAHEAD_M = 8.0  # radial error at which the correction reaches 45 degrees
# 1/s: the circle's course loop. Half of YAW_GAIN because the vector field's own turn rate is
# fed forward: 1.0 left a limit cycle with set-points held 0.1 s (a 10 Hz guidance rate).
CIRCLE_GAIN = 0.5
HOLD_RADIUS_M = 3.0  # closer than this, hold the heading instead of turning to the point
BACK_OFF_MPS = 1.0  # astern, while an obstacle is under the bow (avoid.py)
PATROL_M = 100.0  # a boat set to waypoints with no path patrols this far ahead and back


def course(yaw: Array, velocity_b: Array) -> Array:
    """Course over ground: heading plus drift angle, the heading itself when nearly still."""
    u, v = velocity_b[:, 0], velocity_b[:, 1]
    moving = np.hypot(u, v) > 0.5
    return np.where(moving, yaw + np.arctan2(v, np.where(moving, u, 1.0)), yaw)


def circle_law(
    pos: Array,
    chi: Array,
    sog: Array,
    centre: Array,
    radius: Array,
    direction: Array,
    speed: Array,
) -> tuple[Array, Array]:
    """A vector field round the circle (course tangent on it, turning in with the radial
    error, as in Nelson et al. 2007), the field's own turn rate along the boat's motion fed
    forward, plus CIRCLE_GAIN times the course error. Feeding forward only U/R, as before,
    left a boat that started 15 m inside its circle oscillating a minute later."""
    rel = pos - centre
    theta = np.arctan2(rel[:, 1], rel[:, 0])
    dist = np.maximum(np.hypot(rel[:, 0], rel[:, 1]), 1.0)
    error = (dist - radius) / CIRCLE_LOOKAHEAD_M
    desired = theta + direction * (np.pi / 2 + np.arctan(error))
    # d(desired)/dt: the bearing turns at U sin(chi - theta) / d, the correction with U cos(...)
    bearing_rate = sog * np.sin(chi - theta) / dist
    approach_rate = sog * np.cos(chi - theta) / CIRCLE_LOOKAHEAD_M / (1 + error**2)
    rate = bearing_rate + direction * approach_rate + CIRCLE_GAIN * wrap(desired - chi)
    return speed.copy(), np.clip(rate, -MAX_YAW_RATE, MAX_YAW_RATE)


def pursuit_law(pos: Array, chi: Array, target: Array, speed: Array) -> tuple[Array, Array]:
    """Head for the target; slow down while the course error is large, so the boat turns
    tightly enough not to orbit a point inside its turning circle."""
    rel = target - pos
    err = wrap(np.arctan2(rel[:, 1], rel[:, 0]) - chi)
    surge = speed * np.clip(np.cos(err), 0.3, 1.0)
    return surge, np.clip(YAW_GAIN * err, -MAX_YAW_RATE, MAX_YAW_RATE)


def hold_law(
    pos: Array, yaw: Array, target: Array, target_yaw: Array, gain: float, max_speed: Array
) -> tuple[Array, Array]:
    """Station keeping: P on the body-frame position error; face the point while far."""
    rel = target - pos
    ahead = rel[:, 0] * np.cos(yaw) + rel[:, 1] * np.sin(yaw)
    far = np.hypot(rel[:, 0], rel[:, 1]) > HOLD_RADIUS_M
    face = np.where(far, np.arctan2(rel[:, 1], rel[:, 0]), target_yaw)
    surge = np.clip(gain * ahead, -max_speed / 2, max_speed)
    return surge, np.clip(YAW_GAIN * wrap(face - yaw), -MAX_YAW_RATE, MAX_YAW_RATE)


class Behaviours:
    """Every boat's behaviour state; `command` gives all set-points for one tick."""

    def __init__(
        self, boats: Sequence[Boat], *, hold_gain: float = 0.5, clear: KeepClear | None = None
    ) -> None:
        n = len(boats)
        self.boats = list(boats)
        self.hold_gain = hold_gain
        self.clear = clear or KeepClear(np.zeros((0, 2)), np.zeros(n), np.zeros(n), 0.0)
        self.marked = np.zeros((n, 1), dtype=bool)  # path points that carry a buoy
        self._last_pick = np.zeros(n, dtype=np.intp)  # each boat's last choice (colregs.py)
        self.kind = np.array([KINDS[b.behaviour] for b in boats], dtype=np.int64)
        self.speed = np.array([b.speed_mps for b in boats], dtype=np.float64)
        self.centre = np.array([b.center for b in boats], dtype=np.float64).reshape(n, 2)
        self.radius = np.array([max(b.radius_m, 1.0) for b in boats], dtype=np.float64)
        self.direction = np.array([b.direction for b in boats], dtype=np.float64)
        self.hold_yaw = np.array([b.pose.yaw_rad for b in boats], dtype=np.float64)
        self.paths = np.zeros((n, 1, 2))  # (N, longest path, 2), padded
        self.length = np.ones(n, dtype=np.int64)  # points in each boat's path
        self.index = np.zeros(n, dtype=np.int64)
        self.step = np.ones(n, dtype=np.int64)
        self.loop = np.zeros(n, dtype=bool)
        self.tol = np.array([b.tolerance_m for b in boats], dtype=np.float64)
        self._away: dict[int, tuple[int, int]] = {}  # off their own: their place on it
        self._buoys: Obstacles | None = None  # the last command's obstacles (_target)
        for i, b in enumerate(boats):
            if b.behaviour == "waypoints":
                self._follow(i, np.array(b.path), b.speed_mps, loop=b.loop, tol=b.tolerance_m)

    def set_path(self, i: int, points: Array, speed: float, *, loop: bool, tol: float) -> None:
        """Boat i follows `points` (K, 2) from the first one on, in place of its own."""
        self._leave(i)
        self._follow(i, points, speed, loop=loop, tol=tol)

    def _follow(self, i: int, points: Array, speed: float, *, loop: bool, tol: float) -> None:
        self.kind[i], self.speed[i], self.loop[i], self.tol[i] = WAYPOINTS, speed, loop, tol
        self._store_path(i, np.asarray(points, dtype=np.float64).reshape(-1, 2))

    def _leave(self, i: int) -> None:
        """Boat i leaves its scenario behaviour: where it was on its path, for a release."""
        self._away.setdefault(i, (int(self.index[i]), int(self.step[i])))

    def _store_path(self, i: int, points: Array) -> None:
        """Boat i's path into the padded array (widened when a longer path arrives)."""
        if len(points) > self.paths.shape[1]:
            self.paths, self.marked = (
                _wider(self.paths, len(points)),
                _wider(self.marked, len(points)),
            )
        self.paths[i, : len(points)] = points
        self.marked[i] = False
        if self.clear.pass_m[i] > 0.0:
            self.marked[i, : len(points)] = marks_on(points, self.clear.anchors)
        self.length[i] = max(len(points), 1)
        self.index[i], self.step[i] = 0, 1

    def release(self, i: int) -> None:
        """Boat i goes back to its scenario behaviour, from where it is now, at the point of
        its path it had left for (one only taken by a twist or thrust, as by a timeout, goes
        on: a release had sent it back to its first point, passed long before)."""
        place = self._away.pop(i, None)
        if place is None:
            return
        b = self.boats[i]
        self.kind[i], self.speed[i] = KINDS[b.behaviour], b.speed_mps
        self.tol[i], self.loop[i] = b.tolerance_m, b.loop
        self.centre[i], self.radius[i] = b.center, max(b.radius_m, 1.0)  # set_behaviour's
        self.hold_yaw[i] = b.pose.yaw_rad  # were kept: a circle came back about a hold point
        self._store_path(i, np.array(b.path, dtype=np.float64).reshape(-1, 2))
        self.index[i], self.step[i] = place

    def set_behaviour(
        self, i: int, behaviour: str, here: Array, yaw: float, cfg: TrafficConfig
    ) -> None:
        """Boat i changes behaviour at run time (`catabot set traffic.<boat>.behaviour`), from
        where it is (`here`, `yaw`): hold there; circle from here at the scenario's speed, on its
        own circle's radius (else the smallest drawn) and sense; follow its path, else the
        scenario's points, else back and forth between here and `PATROL_M` ahead."""
        boat, x, y = self.boats[i], float(here[0]), float(here[1])
        self._leave(i)
        if behaviour == "hold":
            self.kind[i], self.speed[i], self.hold_yaw[i] = HOLD, cfg.hold.max_speed_mps, yaw
            self.centre[i] = (x, y)
        elif behaviour == "circle":
            r = boat.radius_m if boat.radius_m >= 1.0 else cfg.circle.radius_m[0]
            d = self.direction[i]
            self.kind[i], self.speed[i], self.radius[i] = CIRCLE, cfg.circle.speed_mps, r
            self.centre[i] = (x - d * r * math.sin(yaw), y + d * r * math.cos(yaw))
        else:
            ahead = (x + PATROL_M * math.cos(yaw), y + PATROL_M * math.sin(yaw))
            path = boat.path or cfg.waypoints.points or [(x, y), ahead]
            w = cfg.waypoints
            self.set_path(i, np.array(path), w.speed_mps, loop=w.mode == "loop", tol=w.tolerance_m)

    def command(
        self, pos: Array, yaw: Array, velocity_b: Array, obstacles: Obstacles | None = None
    ) -> tuple[Array, Array]:
        """Set-points for every boat: pos (N, 2) m, yaw (N,), body velocity (N, >=2); boats
        under way keep clear of `obstacles` (avoid.py)."""
        chi = course(yaw, velocity_b)
        sog = np.hypot(velocity_b[:, 0], velocity_b[:, 1])
        self._buoys = obstacles  # where the marks' buoys ride now (_target)
        surge, rate = np.zeros(len(yaw)), np.zeros(len(yaw))
        for kind, law in ((CIRCLE, self._circle), (WAYPOINTS, self._path), (HOLD, self._hold)):
            rows = np.flatnonzero(self.kind == kind)
            if rows.size:
                surge[rows], rate[rows] = law(rows, pos[rows], yaw[rows], chi[rows], sog[rows])
        if obstacles is not None and len(obstacles.xy):
            # The rules of the road first, then the buoys: the turn a rule picks is checked
            # against them (a give-way turn had steered a boat onto a buoy and pinned it).
            surge, rate = self._give_way(pos, chi, sog, obstacles, (surge, rate))
            surge, rate = self._keep_clear(pos, chi, sog, obstacles, (surge, rate))
        return surge, rate

    def _keep_clear(
        self, pos: Array, chi: Array, sog: Array, obstacles: Obstacles, order: tuple[Array, Array]
    ) -> tuple[Array, Array]:
        """The clear turn nearest each blocked boat's own (avoid.py), backing off while an
        obstacle is under the bow (holding boats stay put)."""
        surge, rate = order
        speed = np.maximum(np.maximum(sog, np.abs(surge)), 1.0)  # its law slows to turn
        reach, marks = self.clear.lookahead_s * speed, self._own_marks()
        own = (rate / MAX_YAW_RATE, MAX_YAW_RATE / speed)  # its law's turn; a full turn's arc
        turn, stop = corridor_turn(pos, chi, *own, reach, self.clear.width, obstacles, marks)
        turn[self.kind == HOLD], stop[self.kind == HOLD] = np.nan, False
        steered = ~np.isnan(turn)
        surge = np.where(stop, -BACK_OFF_MPS, surge)
        return surge, np.where(steered, turn * MAX_YAW_RATE, rate)

    def _give_way(
        self,
        pos: Array,
        chi: Array,
        sog: Array,
        obstacles: Obstacles,
        order: tuple[Array, Array],
    ) -> tuple[Array, Array]:
        """Boats meeting boats: each takes the course change and speed that keeps clear at
        least cost under the rules of the road (colregs.py); the buoys are checked after."""
        surge, rate = order
        cruise = np.maximum(sog, surge)  # a slowed boat's candidates at the speed it resumes
        vel = cruise[:, None] * np.column_stack((np.cos(chi), np.sin(chi)))
        own = Movers(pos, vel, chi, rate, self.clear.width)  # on its own law's arc
        v = obstacles.velocity
        course = np.arctan2(v[:, 1], v[:, 0])
        other = Movers(obstacles.xy, v, course, obstacles.turn_rate, obstacles.radius)
        pairs = self._meetings(pos, sog, obstacles)
        pick = choose(own, other, pairs, horizon_s=self.clear.lookahead_s, last=self._last_pick)
        offset, part = OFFSETS[pick], SPEEDS[pick]
        self._last_pick = pick
        act = pick != 0
        steer = act & (offset != 0.0)
        surge = np.where(act & (surge > 0.0), surge * part, surge)
        rate = np.where(steer, np.clip(YAW_GAIN * offset, -MAX_YAW_RATE, MAX_YAW_RATE), rate)
        return surge, rate

    def _meetings(
        self, pos: Array, sog: Array, obstacles: Obstacles
    ) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
        """(boat, obstacle) pairs of boats under way that could meet within the lookahead,
        never a boat with itself nor a holding boat (it stays put)."""
        moving = np.flatnonzero(obstacles.under_way)
        fastest = float(np.hypot(*obstacles.velocity[moving].T).max(initial=0.0))
        far = (np.maximum(sog, self.speed) + fastest) * self.clear.lookahead_s + self.clear.width
        boat, obs = near_pairs(pos, far + obstacles.radius.max(), obstacles, np.arange(len(pos)))
        keep = obstacles.under_way[obs] & (obs != obstacles.own[boat]) & (self.kind[boat] != HOLD)
        return boat[keep], obs[keep]

    def _own_marks(self) -> Array:
        """(N, K, 2): the mark each boat steers for now, nan where none (it rounds it). Its
        later marks are obstacles like any buoy: left out too, a boat whose third mark lay
        on its way to the first rammed it at 4 m/s and dragged it 6 m."""
        current = np.arange(self.paths.shape[1])[None, :] == self.index[:, None]
        on = self.marked & current & (self.kind == WAYPOINTS)[:, None]
        return np.where(on[..., None], self.paths, np.nan)

    def _circle(
        self, rows: NDArray[np.intp], pos: Array, _: Array, chi: Array, sog: Array
    ) -> tuple[Array, Array]:
        centre, radius, direction = self.centre[rows], self.radius[rows], self.direction[rows]
        return circle_law(pos, chi, sog, centre, radius, direction, self.speed[rows])

    def _hold(
        self, rows: NDArray[np.intp], pos: Array, yaw: Array, *_: Array
    ) -> tuple[Array, Array]:
        target = self.centre[rows]
        return hold_law(pos, yaw, target, self.hold_yaw[rows], self.hold_gain, self.speed[rows])

    def _path(
        self, rows: NDArray[np.intp], pos: Array, _: Array, chi: Array, __: Array
    ) -> tuple[Array, Array]:
        target, off = self._target(rows)
        reached = rows[np.hypot(*(target - pos).T) < self.tol[rows] + off]
        if reached.size:
            self._advance(reached)
            target, off = self._target(rows)
        if off.any():  # marks are rounded, not rammed (avoid.py)
            target = np.where(off[:, None] > 0.0, mark_aim(pos, target, off), target)
        return pursuit_law(pos, chi, target, self.speed[rows])

    def _target(self, rows: NDArray[np.intp]) -> tuple[Array, Array]:
        """Each boat's waypoint now (a mark: where its buoy rides), and how far off it passes
        it (0 unless it is a mark)."""
        k = self.index[rows]
        marked, points = self.marked[rows, k], self.paths[rows, k]
        points = np.where(marked[:, None], drifted(points, self._buoys), points)
        return points, np.where(marked, self.clear.pass_m[rows], 0.0)

    def _advance(self, rows: NDArray[np.intp]) -> None:
        """Next point: wrap round when looping, turn back at either end otherwise."""
        k, n = self.index[rows] + self.step[rows], self.length[rows]
        back = ~self.loop[rows] & ((k < 0) | (k >= n))
        self.step[rows[back]] *= -1
        k[back] = self.index[rows[back]] + self.step[rows[back]]
        self.index[rows] = np.where(self.loop[rows], k % n, np.clip(k, 0, n - 1))  # 1 point


def _wider(table: NDArray[Any], width: int) -> NDArray[Any]:
    """A per-boat path table (N, K, ...) padded with zeros to `width` points."""
    out = np.zeros((table.shape[0], width, *table.shape[2:]), dtype=table.dtype)
    out[:, : table.shape[1]] = table
    return out
