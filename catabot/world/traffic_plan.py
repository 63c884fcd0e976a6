"""The traffic plan: where each boat starts and what it does, a pure function of the scenario.

Every process derives the same plan from the same scenario (once, in `World.resolve`), so
the boats need no announcement on the bus. Randomness comes from the traffic seed and the
name "traffic" only (DESIGN.md §2), so adding a sensor does not move a boat.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from catabot.config.base import ScenarioError
from catabot.config.scenario import BuoyConfig, Pose, Scenario
from catabot.config.terrain import TerrainError
from catabot.config.traffic import BEHAVIOURS, BoatOverride, Point, Region, TrafficConfig, boat_id
from catabot.config.vessel import VesselModel
from catabot.world import seeding
from catabot.world.clearance import Discs, Rows, clear, densify, off_lanes, off_rings
from catabot.world.placement import (
    BUOY_MODEL,
    CLEARANCE_M,
    Hull,
    Models,
    footprint_m,
    hull_clash,
    keel_depth_m,
)
from catabot.world.terrain import Terrain
from catabot.world.traffic_checks import TRACK_DEPTH_M, check_given, check_room

TRIES = 2000
START_ROOM_M = 10.0  # more water between a drawn start and every vessel's: see README § traffic
PATH_DRAWS = 5000  # random paths per boat before the plan is refused


@dataclass(frozen=True)
class Boat:
    """One traffic boat: model, start pose and behaviour with its parameters."""

    id: str
    model: str
    pose: Pose
    behaviour: str
    speed_mps: float = 0.0
    center: Point = (0.0, 0.0)  # circle centre, or the hold point
    radius_m: float = 0.0
    direction: int = 1  # +1 counter-clockwise, -1 clockwise
    path: tuple[Point, ...] = ()
    loop: bool = False
    tolerance_m: float = 5.0


@dataclass(frozen=True)
class TrafficPlan:
    boats: tuple[Boat, ...]
    buoys: tuple[BuoyConfig, ...]


Progress = Callable[[int, int], None]  # (boats planned, boats in all)


def plan_traffic(
    scenario: Scenario, terrain: Terrain | None, *, models: Models, progress: Progress | None = None
) -> TrafficPlan:
    """The plan of a scenario whose vessels all have poses (World.resolve calls it once)."""
    if scenario.traffic.count == 0:
        return TrafficPlan((), ())
    return Planner(scenario, terrain, models=models, progress=progress).plan()


class Planner:
    """Draws boats one by one; a boat that finds no free deep water in TRIES draws is an error."""

    def __init__(
        self,
        scenario: Scenario,
        terrain: Terrain | None,
        *,
        models: Models,
        progress: Progress | None = None,
    ) -> None:
        self.cfg: TrafficConfig = scenario.traffic
        self.terrain, self.progress = terrain, progress
        self._path_draws = 0  # paths drawn for the current boat
        seed = scenario.seed if self.cfg.seed is None else self.cfg.seed
        self.rng = seeding.rng(seed, "traffic")
        self._model = models.__getitem__  # scenario_models: each model file read once
        self.placed, self.named = Discs(), []  # vessels' starts: x, y, footprint radius; ids
        self.hulls: list[Hull] = []  # the same, as hulls: a start given beside one (hull_clash)
        for v in scenario.vessels:
            assert v.pose is not None
            self.named.append(v.id)
            self.placed.add(v.pose.x_m, v.pose.y_m, footprint_m(self._model(v.model)))
            self.hulls.append((v.id, v.pose, self._model(v.model)))
        self.buoy_r = footprint_m(self._model(BUOY_MODEL))
        self.lanes = task_lanes(scenario, self._model)  # no drawn buoy on a vessel's way
        # Buoys are moored: a boat must not start on one, nor circle through one every lap.
        self.marks = Discs()  # buoys: x, y, footprint radius
        for b in scenario.buoys:
            self.marks.add(b.x_m, b.y_m, self.buoy_r)
        self.rings = Rows(4)  # circling boats: centre x, y, radius, hull footprint
        self.footprints: dict[str, float] = {}  # by model, as drawn
        self.overrides = {b.index: b for b in self.cfg.boats}
        check_room(self.cfg, self.buoy_r)
        check_given(self.cfg, self.terrain, self._wet)

    def plan(self) -> TrafficPlan:
        boats = tuple(self._planned(i) for i in range(self.cfg.count))
        buoys: list[BuoyConfig] = []
        laid = Discs()
        for b in boats:
            if b.behaviour != "waypoints" or not self.cfg.waypoints.buoys:
                continue
            for k, (x, y) in enumerate(b.path):  # a point several paths share (given
                if laid.clear_of(np.array([(x, y)]), self.buoy_r):  # points): one buoy
                    buoys.append(BuoyConfig(id=f"{b.id}_wp{k}", x_m=x, y_m=y))
                    laid.add(x, y, self.buoy_r)
        self._none_under_a_boat(boats, buoys)
        return TrafficPlan(boats, tuple(buoys))

    def _none_under_a_boat(self, boats: tuple[Boat, ...], buoys: list[BuoyConfig]) -> None:
        """A given waypoint where a boat starts (its own first point, often) laid its buoy
        under that boat: a collision from tick 0 in every run."""
        starts = np.array([(b.pose.x_m, b.pose.y_m) for b in boats]).reshape(-1, 2)
        reach = np.array([self.footprints[b.model] for b in boats]) + self.buoy_r
        marks = np.array([(m.x_m, m.y_m) for m in buoys]).reshape(-1, 2)
        gaps = np.hypot(*(marks[:, None] - starts[None]).transpose(2, 0, 1))  # (buoys, boats)
        under = np.argwhere(gaps < reach)
        if under.size:
            (i, j), mark = under[0], buoys[int(under[0][0])]
            raise ScenarioError(
                f"traffic: {mark.id.rsplit('_wp', 1)[0]}'s waypoint ({mark.x_m:g}, {mark.y_m:g}) "
                f"is {gaps[i, j]:.2f} m from where {boats[int(j)].id} starts: its buoy would "
                "start under that boat; move the point or the start, or "
                "traffic.waypoints.buoys: false"
            )

    def _planned(self, index: int) -> Boat:
        self._path_draws = 0
        boat = self._boat(index)
        if self.progress is not None:
            self.progress(index + 1, self.cfg.count)
        return boat

    def _boat(self, index: int) -> Boat:
        over = self.overrides.get(index, BoatOverride(index=index))
        models = self.cfg.models
        model = over.model or self._pick([m.model for m in models], [m.weight for m in models])
        mix = self.cfg.behaviour_mix
        behaviour = over.behaviour or self._pick(list(mix), list(mix.values()))
        hull = self._model(model)
        radius, draft = footprint_m(hull), keel_depth_m(hull)
        self.footprints[model] = radius
        for _ in range(TRIES):
            x, y = self._point(self.cfg.region)
            x, y = over.x_m if over.x_m is not None else x, over.y_m if over.y_m is not None else y
            yaw = over.yaw_rad if over.yaw_rad is not None else self.rng.uniform(-math.pi, math.pi)
            fixed = over.x_m is not None and over.y_m is not None  # the user's spot: as given
            pose = Pose(x_m=x, y_m=y, yaw_rad=yaw)
            blocked = hull_clash(pose, hull, self.hulls) if fixed else ""
            blocked = blocked or self._blocked(
                x, y, radius, draft, room=None if fixed else START_ROOM_M
            )
            if blocked:
                if fixed:
                    raise ScenarioError(f"traffic.boats: boat {index} at ({x}, {y}): {blocked}")
                continue
            boat = self._behave(index, model, pose, behaviour, over)
            if boat is not None:
                self.placed.add(x, y, radius)
                self.named.append(boat.id)
                self.hulls.append((boat.id, pose, hull))
                return boat
        if behaviour == "waypoints" and (over.points or self.cfg.waypoints.points):
            raise ScenarioError(
                f"traffic: boat {index}: no free start in traffic.region from which the way to "
                f"its first given waypoint stays in {TRACK_DEPTH_M:g} m of water ({TRIES} "
                f"draws): give it a start (traffic.boats[].x_m, y_m) or a nearer region"
            )
        raise ScenarioError(f"traffic: no free open water for boat {index} in {TRIES} draws: "
                            "give a larger traffic.region (on the terrain's water, if it "
                            "has one) or fewer boats (traffic.count "
                            f"{self.cfg.count})")  # fmt: skip

    def _pick(self, names: list[str], weights: list[float]) -> str:
        p = np.asarray(weights, dtype=np.float64)
        return names[int(self.rng.choice(len(names), p=p / p.sum()))]

    def _points(self, region: Region, count: int) -> list[Point]:
        """`count` points drawn as `_point` draws them one by one (x then y, in order)."""
        lo, hi = self._bounds(region)
        return [(float(x), float(y)) for x, y in self.rng.uniform(lo, hi, (count, 2)).tolist()]

    def _point(self, region: Region) -> Point:
        (x0, y0), (x1, y1) = self._bounds(region)
        return float(self.rng.uniform(x0, x1)), float(self.rng.uniform(y0, y1))

    def _bounds(self, region: Region) -> tuple[Point, Point]:
        """The region's corners, cut to the terrain's (beyond its edge there is no water: a
        default 1000 m region over the bundled 600 m bay drew two points in five off it)."""
        (cx, cy), (w, h) = self._centre(region), region.size_m
        lo, hi = (cx - w / 2, cy - h / 2), (cx + w / 2, cy + h / 2)
        if self.terrain is None:
            return lo, hi
        (tw, th) = self.terrain.size_m
        cut = (max(lo[0], 0.0), max(lo[1], 0.0)), (min(hi[0], tw), min(hi[1], th))
        return cut if cut[0][0] < cut[1][0] and cut[0][1] < cut[1][1] else (lo, hi)

    def _centre(self, region: Region) -> Point:
        if region.center_m is not None:
            return region.center_m
        if self.terrain is not None:
            w, h = self.terrain.size_m
            return w / 2, h / 2
        return 0.0, 0.0

    def _nearest(self, x: float, y: float) -> str:
        """The vessel or boat placed so far whose footprint comes nearest (x, y)."""
        disc = self.placed.array
        return self.named[int(np.argmin(np.hypot(disc[:, 0] - x, disc[:, 1] - y) - disc[:, 2]))]

    def _blocked(
        self, x: float, y: float, radius: float, draft: float, *, room: float | None
    ) -> str:
        """Why a start is not free ("" if it is): clear of every vessel placed so far by
        `room` more than their footprints (None: not tested here, a given start's hull is)
        and of every buoy, and in water deep enough for the hull."""
        here = np.array([(x, y)])
        if room is not None and not self.placed.clear_of(here, radius + room):
            return f"its {radius:.2f} m footprint overlaps {self._nearest(x, y)}'s (or its room)"
        if not self.marks.clear_of(here, radius):
            where = "(scenario or waypoint)"
            return f"its footprint ({radius:.2f} m about its origin) overlaps a buoy {where}"
        if self.terrain is None:
            return ""
        try:
            self.terrain.check_start(
                x, y, draft_m=draft, footprint_m=radius, clearance_m=CLEARANCE_M
            )
        except TerrainError as exc:
            return str(exc)
        return ""

    def _wet(self, xs: np.ndarray, ys: np.ndarray) -> bool:
        """Every point of a track in water (2 m of depth: boats must not run aground)."""
        if self.terrain is None:
            return True
        w, h = self.terrain.size_m
        inside = bool(((xs >= 0) & (xs <= w) & (ys >= 0) & (ys <= h)).all())
        return inside and bool((self.terrain.depth(xs, ys) > TRACK_DEPTH_M).all())

    def _buoys_clear(self, path: Sequence[Point], boat: Boat) -> bool:
        """Random waypoints (each to get a buoy) clear of every start, the boat's own
        included, of every buoy, of every circling boat's track and of every scenario
        vessel's way to its task (a moored buoy on it would be an obstacle the task set)."""
        if not self.cfg.waypoints.buoys:
            return True
        points, r = np.array(path, dtype=np.float64).reshape(-1, 2), self.buoy_r
        own = np.array([(boat.pose.x_m, boat.pose.y_m, self.footprints[boat.model])])
        return (
            self.placed.clear_of(points, r)
            and self.marks.clear_of(points, r)
            and clear(points, r, own)
            and off_rings(points, r, self.rings.array)
            and off_lanes(points, r, self.lanes)
        )

    def _behave(
        self, index: int, model: str, pose: Pose, behaviour: str, over: BoatOverride
    ) -> Boat | None:
        """The boat's behaviour parameters, or None when its track would cross land."""
        assert behaviour in BEHAVIOURS
        base = Boat(boat_id(index), model, pose, behaviour)
        if behaviour == "circle":
            return self._circle(base)
        if behaviour == "waypoints":
            return self._waypoints(base, over.points)
        return Boat(base.id, model, pose, "hold", self.cfg.hold.max_speed_mps, (pose.x_m, pose.y_m))

    def _circle(self, base: Boat) -> Boat | None:
        c = self.cfg.circle
        radius = float(self.rng.uniform(*c.radius_m))
        direction = {"ccw": 1, "cw": -1}.get(c.direction) or int(self.rng.choice([-1, 1]))
        p = base.pose  # the boat starts on its circle, heading along it
        cx = p.x_m - direction * radius * math.sin(p.yaw_rad)
        cy = p.y_m + direction * radius * math.cos(p.yaw_rad)
        a = np.linspace(0, 2 * math.pi, 48, endpoint=False)
        if not self._wet(cx + (radius + 3) * np.cos(a), cy + (radius + 3) * np.sin(a)):
            return None
        ring = (cx, cy, radius, self.footprints[base.model])
        marks = self.marks.array
        if not off_rings(marks[:, :2], marks[:, 2], np.array([ring])):
            return None
        self.rings.add(*ring)
        return Boat(base.id, base.model, p, "circle", c.speed_mps, (cx, cy), radius, direction)

    def _waypoints(self, base: Boat, points: list[Point] | None) -> Boat | None:
        w = self.cfg.waypoints
        given = points or w.points
        for _ in range(1 if given else 50):
            self._path_draws += 1
            if self._path_draws > PATH_DRAWS:
                raise ScenarioError(
                    f"traffic: no path of {w.count} waypoints clear of land, buoys and other "
                    f"boats' tracks for {base.id} in {PATH_DRAWS} draws: use fewer points or "
                    "boats, or a traffic.waypoints.region over more open water (beyond the "
                    "terrain's edge there is none)"
                )
            path = (
                [(float(q[0]), float(q[1])) for q in given]
                if given
                else self._points(w.region, w.count)
            )
            track = np.array([(base.pose.x_m, base.pose.y_m), *path])
            if not given and not self._buoys_clear(path, base):
                continue
            if self._wet(*densify(track, loop=w.mode == "loop")):
                if w.buoys:
                    for x, y in path:
                        self.marks.add(x, y, self.buoy_r)
                return Boat(
                    base.id, base.model, base.pose, "waypoints", w.speed_mps,
                    path=tuple((float(x), float(y)) for x, y in path),
                    loop=w.mode == "loop", tolerance_m=w.tolerance_m,
                )  # fmt: skip
        return None


def task_lanes(scenario: Scenario, model: Callable[[str], VesselModel]) -> np.ndarray:
    """(M, 5) segments x0, y0, x1, y1, half-width: each scenario vessel's way from its start
    through its route to its goal, as wide as its footprint, and its goal disc (a segment of
    no length, as wide as the goal or the footprint)."""
    lanes = [np.zeros((0, 5))]
    for v in scenario.vessels:
        if v.task is None or v.pose is None:
            continue
        half = footprint_m(model(v.model))
        goal = v.task.goal
        to = [(goal.x_m, goal.y_m)] if goal else []
        ends = np.array([(v.pose.x_m, v.pose.y_m), *(v.task.route or ()), *to], dtype=np.float64)
        lanes.append(np.column_stack([ends[:-1], ends[1:], np.full(len(ends) - 1, half)]))
        if goal is not None:
            lanes.append(np.array([[*to[0], *to[0], max(half, goal.radius_m)]]))
    return np.concatenate(lanes)
