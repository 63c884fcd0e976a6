"""The traffic plan: where each boat starts and what it does, a pure function of the scenario.

Every process derives the same plan from the same scenario (once, in `World.resolve`), so
the boats need no announcement on the bus. Randomness comes from the traffic seed and the
name "traffic" only (DESIGN.md §2), so adding a sensor does not move a boat.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from catabot.config.scenario import BuoyConfig, Pose, Scenario, ScenarioError
from catabot.config.terrain import TerrainError
from catabot.config.traffic import (
    BEHAVIOURS,
    BoatOverride,
    Point,
    Region,
    TrafficConfig,
    boat_id,
)
from catabot.config.vessel import VesselModel, load_vessel_model
from catabot.world import seeding
from catabot.world.placement import CLEARANCE_M, footprint_m, keel_depth_m
from catabot.world.terrain import Terrain

TRIES = 2000


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


def plan_traffic(scenario: Scenario, terrain: Terrain | None) -> TrafficPlan:
    """The plan of a scenario whose vessels all have poses (World.resolve calls it once)."""
    if scenario.traffic.count == 0:
        return TrafficPlan((), ())
    return Planner(scenario, terrain).plan()


class Planner:
    """Draws boats one by one; a boat that finds no free deep water in TRIES draws is an error."""

    def __init__(self, scenario: Scenario, terrain: Terrain | None) -> None:
        self.cfg: TrafficConfig = scenario.traffic
        self.terrain = terrain
        seed = scenario.seed if self.cfg.seed is None else self.cfg.seed
        self.rng = seeding.rng(seed, "traffic")
        self._models: dict[str, VesselModel] = {}
        self.placed = _Rows(3)  # vessels' starts: x, y, footprint radius
        for v in scenario.vessels:
            assert v.pose is not None
            self.placed.add(v.pose.x_m, v.pose.y_m, footprint_m(self._model(v.model)))
        self.buoy_r = footprint_m(self._model("buoy"))
        # Buoys are moored: a boat must not start on one, nor circle through one every lap.
        self.marks = _Rows(3)  # buoys: x, y, footprint radius
        for b in scenario.buoys:
            self.marks.add(b.x_m, b.y_m, self.buoy_r)
        self.rings = _Rows(4)  # circling boats: centre x, y, radius, hull footprint
        self.footprints: dict[str, float] = {}  # by model, as drawn
        self.overrides = {b.index: b for b in self.cfg.boats}

    def plan(self) -> TrafficPlan:
        boats = tuple(self._boat(i) for i in range(self.cfg.count))
        buoys: list[BuoyConfig] = []
        laid = _Rows(3)
        for b in boats:
            if b.behaviour != "waypoints" or not self.cfg.waypoints.buoys:
                continue
            for k, (x, y) in enumerate(b.path):  # a point several paths share (given
                if _clear(np.array([(x, y)]), self.buoy_r, laid.array):  # points): one buoy
                    buoys.append(BuoyConfig(id=f"{b.id}_wp{k}", x_m=x, y_m=y))
                    laid.add(x, y, self.buoy_r)
        return TrafficPlan(boats, tuple(buoys))

    def _boat(self, index: int) -> Boat:
        over = self.overrides.get(index, BoatOverride(index=index))
        model = over.model or self._pick([m.model for m in self.cfg.models], self._model_w())
        mix = self.cfg.behaviour_mix
        behaviour = over.behaviour or self._pick(list(mix), list(mix.values()))
        hull = self._model(model)
        radius, draft = footprint_m(hull), keel_depth_m(hull)
        self.footprints[model] = radius
        for _ in range(TRIES):
            x, y = self._point(self.cfg.region)
            x, y = over.x_m if over.x_m is not None else x, over.y_m if over.y_m is not None else y
            yaw = over.yaw_rad if over.yaw_rad is not None else self.rng.uniform(-math.pi, math.pi)
            if not self._free(x, y, radius, draft):
                if over.x_m is not None and over.y_m is not None:
                    raise ScenarioError(f"traffic.boats: boat {index} at ({x}, {y}) is not free")
                continue
            boat = self._behave(index, model, Pose(x_m=x, y_m=y, yaw_rad=yaw), behaviour, over)
            if boat is not None:
                self.placed.add(x, y, radius)
                return boat
        raise ScenarioError(f"traffic: no free open water for boat {index} in {TRIES} draws")

    def _model(self, ref: str) -> VesselModel:
        """Each model file read once per plan (500 boats share a handful of models)."""
        if ref not in self._models:
            self._models[ref] = load_vessel_model(ref)
        return self._models[ref]

    def _model_w(self) -> list[float]:
        return [m.weight for m in self.cfg.models]

    def _pick(self, names: list[str], weights: list[float]) -> str:
        p = np.asarray(weights, dtype=np.float64)
        return names[int(self.rng.choice(len(names), p=p / p.sum()))]

    def _point(self, region: Region) -> Point:
        cx, cy = self._centre(region)
        w, h = region.size_m
        return float(cx + self.rng.uniform(-w / 2, w / 2)), float(
            cy + self.rng.uniform(-h / 2, h / 2)
        )

    def _centre(self, region: Region) -> Point:
        if region.center_m is not None:
            return region.center_m
        if self.terrain is not None:
            w, h = self.terrain.size_m
            return w / 2, h / 2
        return 0.0, 0.0

    def _free(self, x: float, y: float, radius: float, draft: float) -> bool:
        """Clear of every vessel and buoy placed so far, and in water deep enough for the hull."""
        here = np.array([(x, y)])
        if not (_clear(here, radius, self.placed.array) and _clear(here, radius, self.marks.array)):
            return False
        if self.terrain is None:
            return True
        try:
            self.terrain.check_start(
                x, y, draft_m=draft, footprint_m=radius, clearance_m=CLEARANCE_M
            )
        except TerrainError:
            return False
        return True

    def _wet(self, xs: np.ndarray, ys: np.ndarray) -> bool:
        """Every point of a track in water (2 m of depth: boats must not run aground)."""
        if self.terrain is None:
            return True
        w, h = self.terrain.size_m
        inside = bool(((xs >= 0) & (xs <= w) & (ys >= 0) & (ys <= h)).all())
        return inside and bool((self.terrain.depth(xs, ys) > 2.0).all())

    def _buoys_clear(self, path: Sequence[Point], boat: Boat) -> bool:
        """Random waypoints (each to get a buoy) clear of every start, the boat's own
        included, of every buoy and of every circling boat's track."""
        if not self.cfg.waypoints.buoys:
            return True
        points, r = np.array(path, dtype=np.float64).reshape(-1, 2), self.buoy_r
        own = np.array([(boat.pose.x_m, boat.pose.y_m, self.footprints[boat.model])])
        return (
            _clear(points, r, self.placed.array)
            and _clear(points, r, self.marks.array)
            and _clear(points, r, own)
            and _off_rings(points, r, self.rings.array)
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
        if not _off_rings(marks[:, :2], marks[:, 2], np.array([ring])):
            return None
        self.rings.add(*ring)
        return Boat(base.id, base.model, p, "circle", c.speed_mps, (cx, cy), radius, direction)

    def _waypoints(self, base: Boat, points: list[Point] | None) -> Boat | None:
        w = self.cfg.waypoints
        given = points or w.points
        for _ in range(1 if given else 50):
            path = (
                [(float(q[0]), float(q[1])) for q in given]
                if given
                else [self._point(w.region) for _ in range(w.count)]
            )
            track = np.array([(base.pose.x_m, base.pose.y_m), *path])
            if not given and not self._buoys_clear(path, base):
                continue
            if self._wet(*_densify(track, loop=w.mode == "loop")):
                if w.buoys:
                    for x, y in path:
                        self.marks.add(x, y, self.buoy_r)
                return Boat(
                    base.id, base.model, base.pose, "waypoints", w.speed_mps,
                    path=tuple((float(x), float(y)) for x, y in path),
                    loop=w.mode == "loop", tolerance_m=w.tolerance_m,
                )  # fmt: skip
        return None


class _Rows:
    """Rows added one at a time, read as one array: the planner tests every draw against
    all of them (1300 buoys with 500 boats). Storage doubles when full, so an add is O(1)."""

    def __init__(self, width: int) -> None:
        self._data = np.zeros((16, width))
        self._count = 0

    def add(self, *row: float) -> None:
        if self._count == len(self._data):
            self._data = np.concatenate((self._data, np.zeros_like(self._data)))
        self._data[self._count] = row
        self._count += 1

    @property
    def array(self) -> np.ndarray:
        return self._data[: self._count]


def _clear(points: np.ndarray, r: float | np.ndarray, discs: np.ndarray) -> bool:
    """Footprints of radius r at points (K, 2) clear of discs (M, 3: x, y, radius)."""
    gap = np.hypot(points[:, None, 0] - discs[:, 0], points[:, None, 1] - discs[:, 1])
    return not bool((gap <= np.reshape(r, (-1, 1)) + discs[:, 2] + CLEARANCE_M).any())


def _off_rings(points: np.ndarray, r: float | np.ndarray, rings: np.ndarray) -> bool:
    """Footprints at points (K, 2) clear of what boats circling rings (M, 4: centre x, y,
    radius, hull footprint) sweep."""
    d = np.hypot(points[:, None, 0] - rings[:, 0], points[:, None, 1] - rings[:, 1])
    reach = np.reshape(r, (-1, 1)) + rings[:, 3] + CLEARANCE_M
    return not bool((np.abs(d - rings[:, 2]) <= reach).any())


def _densify(
    track: np.ndarray, *, loop: bool, step_m: float = 5.0
) -> tuple[np.ndarray, np.ndarray]:
    """Points every `step_m` along a polyline (closed back to its second point if looping)."""
    if loop:
        track = np.vstack([track, track[1:2]])
    parts = [track[:1]]
    for a, b in itertools.pairwise(track):
        n = max(int(np.hypot(*(b - a)) / step_m), 1)
        t = np.linspace(0, 1, n + 1)[1:, None]
        parts.append(a + t * (b - a))
    pts = np.vstack(parts)
    return pts[:, 0], pts[:, 1]
