"""What the example stacks share beyond the connection: the GPS fix in the local frame, line-of-
sight guidance, and a catamaran's thrust for a (surge, yaw rate) wish. Pure functions, tested in
tests/examples/test_guidance.py.

The fix goes to `map` (ENU, origin = the scenario's `origin`) through the simulator's own
geodesy (catabot/world/geo.py's EnuFrame, which needs only NumPy): the inverse of what the
GPS sensor did, exact.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from catabot.world.geo import EnuFrame
from catabot.world.rotations import yaw_of_quaternions


@dataclass(frozen=True)
class LocalFrame:
    """`map` around a WGS84 origin: fixes to east/north metres and back."""

    latitude_deg: float
    longitude_deg: float
    altitude_m: float = 0.0

    @classmethod
    def of_scenario(cls, scenario: dict[str, Any]) -> LocalFrame:
        """The frame of a resolved scenario (`origin`: latitude_deg, longitude_deg, altitude_m)."""
        origin = scenario.get("origin") or {}
        try:
            return cls(
                float(origin["latitude_deg"]), float(origin["longitude_deg"]),
                float(origin.get("altitude_m", 0.0)),
            )  # fmt: skip
        except (KeyError, TypeError, ValueError) as e:
            raise SystemExit(f"the world's scenario has no usable `origin` ({e!r})") from None

    @property
    def _enu(self) -> EnuFrame:
        return EnuFrame(self.latitude_deg, self.longitude_deg, self.altitude_m)

    def to_local(self, latitude_deg: float, longitude_deg: float) -> tuple[float, float]:
        """East, north (m) of a fix."""
        east, north, _ = self._enu.to_enu(latitude_deg, longitude_deg, self.altitude_m)
        return float(east), float(north)

    def to_fix(self, east_m: float, north_m: float) -> tuple[float, float]:
        """Latitude, longitude (deg) of a local position (for tests and logs); the longitude
        continuous around the origin's (past 180 east of a point near the antimeridian)."""
        lat, lon, _ = self._enu.to_geodetic(east_m, north_m, 0.0)
        return float(lat), self.longitude_deg + (float(lon) - self.longitude_deg + 180) % 360 - 180


def yaw_of(q: Sequence[float] | NDArray[np.float64]) -> float:
    """ENU heading (rad, 0 = east, counter-clockwise) of an orientation quaternion (x, y, z, w),
    the IMU's."""
    return float(yaw_of_quaternions(np.asarray([q], dtype=np.float64))[0])


def wrap(angle: float) -> float:
    """An angle folded into [-pi, pi)."""
    return (angle + math.pi) % math.tau - math.pi


def line_of_sight(
    position: tuple[float, float], a: tuple[float, float], b: tuple[float, float],
    lookahead_m: float,
) -> tuple[float, float, float]:  # fmt: skip
    """Heading to steer (rad), signed cross-track error (m, + left of a->b) and how far along
    the leg the vessel is (0 at a, 1 at b), for the leg a -> b (Fossen's lookahead LOS: aim at
    the point `lookahead_m` down the path from the vessel's projection on it)."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    length = math.hypot(dx, dy)
    if length == 0.0:
        raise ValueError(f"a leg needs two different points (got {a} twice)")
    rx, ry = position[0] - a[0], position[1] - a[1]
    along = (rx * dx + ry * dy) / length
    cross = (dx * ry - dy * rx) / length
    heading = math.atan2(dy, dx) - math.atan2(cross, lookahead_m)
    return wrap(heading), cross, along / length


def next_leg(
    position: tuple[float, float], path: list[tuple[float, float]], leg: int, accept_m: float
) -> int:
    """The leg (index of its start point) to follow: the next one once the vessel is within
    `accept_m` of this leg's end or past it. Returns len(path) - 1 when the path is done."""
    while leg < len(path) - 1:
        end = path[leg + 1]
        _, _, along = line_of_sight(position, path[leg], end, 1.0)
        if math.dist(position, end) > accept_m and along < 1.0:
            break
        leg += 1
    return leg


def steer(heading_wanted: float, heading: float, gain: float, max_rate: float) -> float:
    """Yaw rate (rad/s) turning the bow to `heading_wanted`, proportional and clamped."""
    return max(-max_rate, min(max_rate, gain * wrap(heading_wanted - heading)))


@dataclass(frozen=True)
class Catamaran:
    """Feed-forward thrust of the bundled `catabot` model (catabot/data/vessels/catabot.json):
    its surge and yaw damping balanced by two stern thrusters 0.8 m apart (0 port, 1
    starboard), plus a proportional term on the measured yaw rate (the IMU's)."""

    surge_damping: tuple[float, float] = (12.0, 14.0)  # N per m/s, N per (m/s)^2
    yaw_damping: tuple[float, float] = (80.0, 15.0)  # N m per rad/s, N m per (rad/s)^2
    max_forward_n: float = 36.0
    lever_m: float = 0.4
    yaw_gain: float = 150.0  # N m per rad/s of yaw-rate error

    def thrust(self, surge: float, yaw_rate: float, measured_yaw_rate: float) -> list[float]:
        """Port and starboard thrust (-1..1) for a steady (surge, yaw rate)."""
        force = self.surge_damping[0] * surge + self.surge_damping[1] * surge * abs(surge)
        moment = self.yaw_damping[0] * yaw_rate + self.yaw_damping[1] * yaw_rate * abs(yaw_rate)
        moment += self.yaw_gain * (yaw_rate - measured_yaw_rate)
        total = force / self.max_forward_n
        turn = moment / (self.lever_m * self.max_forward_n)  # starboard minus port
        return [max(-1.0, min(1.0, (total - turn) / 2)), max(-1.0, min(1.0, (total + turn) / 2))]


def task_of(scenario: dict[str, Any], vessel: str) -> dict[str, Any]:
    """The vessel's `task` in the resolved scenario ({} when it has none)."""
    for v in scenario.get("vessels", []):
        if v.get("id") == vessel:
            return v.get("task") or {}
    return {}


def goal_of(
    given: list[float] | None, scenario: dict[str, Any], vessel: str
) -> tuple[float, float]:
    """`--goal X Y`, else the scenario's `vessels[].task.goal`; a clear exit with neither."""
    if given is not None:
        return float(given[0]), float(given[1])
    goal = task_of(scenario, vessel).get("goal")
    if not goal:
        raise SystemExit(f"no goal: give --goal X Y or a task.goal for vessel {vessel!r}")
    return float(goal["x_m"]), float(goal["y_m"])


def route_of(
    given: list[float] | None, scenario: dict[str, Any], vessel: str
) -> list[tuple[float, float]]:
    """`--waypoints X Y X Y ...`, else the scenario's `vessels[].task.route`."""
    if given is not None:
        if len(given) < 4 or len(given) % 2:
            raise SystemExit(f"--waypoints takes pairs X Y, at least two (got {len(given)} values)")
        points = list(zip(given[::2], given[1::2], strict=True))
    else:
        points = [(p[0], p[1]) for p in task_of(scenario, vessel).get("route") or []]
        if not points:
            raise SystemExit(f"no path: give --waypoints or a task.route for vessel {vessel!r}")
    for a, b in itertools.pairwise(points):
        if a == b:
            raise SystemExit(f"the path repeats the point {a}: every leg needs two points")
    return [(float(x), float(y)) for x, y in points]
