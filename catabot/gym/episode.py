"""One episode's scenario: the user's scenario, the ego at a start drawn from the episode
seed, the env in the ego's controller seat, only the observed sensors, a small recording.

Everything random about an episode is drawn here from its seed with the project's one rule
(catabot.world.seeding: `rng(seed, "gym/start")`, `rng(seed, "gym/goal")`), and the seed is
the scenario's seed too (waves, wind gusts, traffic, sensor noise): the same seed gives the
same scenario file, so the same run, so the same observations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from catabot.config.base import ScenarioError
from catabot.config.load import absolute_paths, load_scenario, parse_scenario
from catabot.config.rates import rate_in_ticks
from catabot.config.scenario import Pose, Scenario
from catabot.config.terrain import TerrainError
from catabot.gym.options import EnvOptions, EnvOptionsError
from catabot.gym.paths import path_points
from catabot.world import seeding
from catabot.world.placement import (
    BUOY_MODEL,
    CLEARANCE_M,
    Models,
    footprint_m,
    keel_depth_m,
    resolve_poses,
    scenario_models,
)
from catabot.world.terrain import load_terrain

TRIES = 4096  # candidate starts (and goals) drawn before giving up: a region with no water
KEEP_CLEAR_M = 2.0  # between the ego's start footprint and any other body's


@dataclass(frozen=True)
class Goal:
    x_m: float
    y_m: float
    yaw_rad: float  # station keeping holds the start heading; navigating ignores it


@dataclass(frozen=True)
class Episode:
    seed: int
    scenario: Scenario
    start: Pose
    goal: Goal


class Draw:
    """The base scenario, read once, and what every episode draws its start and goal from."""

    def __init__(self, options: EnvOptions) -> None:
        self.options = options
        base = _base(options.scenario)
        ids = [v.id for v in base.vessels]
        self.vessel = options.vessel or ids[0]
        if self.vessel not in ids:
            raise EnvOptionsError(f"vessel {self.vessel!r} is not in the scenario (vessels: {ids})")
        try:  # named as the keyword, not as the scenario field it becomes
            rate_in_ticks(options.control_hz, base.dt_ns, where="control_hz")
        except ScenarioError as exc:
            raise EnvOptionsError(str(exc)) from None
        self.terrain = load_terrain(base.terrain) if base.terrain is not None else None
        models = scenario_models(base)
        self.base = resolve_poses(base, self.terrain, models=models)
        self.index = ids.index(self.vessel)
        _no_one_waited_for(base, self.vessel)
        ego = self.base.vessels[self.index]
        self.model = models[ego.model]
        self.radius = footprint_m(self.model)
        self.keel = keel_depth_m(self.model)
        assert ego.pose is not None, "resolve_poses placed every vessel"
        self.home = ego.pose
        self.others = _others(self.base, self.index, models, seconds=run_seconds(options))

    def episode(self, seed: int, world: str) -> Episode:
        start = self._start(seed)
        goal = self._goal(seed, start)
        return Episode(seed, self._scenario(seed, world, start, goal), start, goal)

    def _start(self, seed: int) -> Pose:
        rng = seeding.rng(seed, "gym/start")
        r = self.options.start_radius_m * np.sqrt(rng.random(TRIES))
        bearing, yaw = rng.uniform(-math.pi, math.pi, (2, TRIES))
        xs, ys = self.home.x_m + r * np.cos(bearing), self.home.y_m + r * np.sin(bearing)
        for x, y, heading in zip(xs.tolist(), ys.tolist(), yaw.tolist(), strict=True):
            if self._open(x, y, self.radius + KEEP_CLEAR_M):
                return Pose(x_m=x, y_m=y, yaw_rad=heading)
        raise EnvOptionsError(
            f"no start in open water within start_radius_m={self.options.start_radius_m:g} m of "
            f"({self.home.x_m:g}, {self.home.y_m:g}) clear of every body ({TRIES} draws): "
            f"{self._start_hint()}"
        )

    def _start_hint(self) -> str:
        """What to change: a radius that reaches past the terrain draws starts off it."""
        if self.terrain is not None and self.options.start_radius_m > max(self.terrain.size_m):
            w, h = self.terrain.size_m
            return f"it reaches past the terrain ({w:g} x {h:g} m): narrow it"
        return "widen it or move the vessel's pose"

    def _goal(self, seed: int, start: Pose) -> Goal:
        if self.options.task == "station_keep":
            return Goal(start.x_m, start.y_m, start.yaw_rad)
        rng = seeding.rng(seed, "gym/goal")
        low, high = self.options.goal_distance_m
        dist, bearing = rng.uniform(low, high, TRIES), rng.uniform(-math.pi, math.pi, TRIES)
        xs, ys = start.x_m + dist * np.cos(bearing), start.y_m + dist * np.sin(bearing)
        for x, y in zip(xs.tolist(), ys.tolist(), strict=True):
            if self._open(x, y, self.radius + KEEP_CLEAR_M):
                return Goal(x, y, 0.0)
        raise EnvOptionsError(
            f"no goal in open water {low:g}..{high:g} m from the start ({start.x_m:.1f}, "
            f"{start.y_m:.1f}): change goal_distance_m"
        )

    def _open(self, x: float, y: float, clear_m: float) -> bool:
        """Deep enough for the keel under the whole footprint, clear of every other body."""
        if self.terrain is not None:
            try:
                self.terrain.check_start(
                    x, y, draft_m=self.keel, footprint_m=self.radius, clearance_m=CLEARANCE_M
                )
            except TerrainError:
                return False
        if not len(self.others):
            return True
        gap = np.hypot(self.others[:, 0] - x, self.others[:, 1] - y) - self.others[:, 2]
        return bool(gap.min() > clear_m)

    def _scenario(self, seed: int, world: str, start: Pose, goal: Goal) -> Scenario:
        o = self.options
        data: dict[str, Any] = self.base.model_dump(mode="json")
        data |= {"name": world, "seed": seed, "duration_s": run_seconds(o)}
        data["clock"] |= {
            "deadline_s": 86400.0,  # the env holds the clock while the agent learns
            "start_timeout_s": o.start_timeout_s,
            "realtime_factor": None,
        }
        data["recording"] = {
            "csv": o.recording == "csv", "mcap": False, "dataset": False, "ppi": False,
            "rerun": False, "export": [],
        }  # fmt: skip
        ego = data["vessels"][self.index]
        ego |= {
            "pose": start.model_dump(),
            "script": [],
            "controller": {"participant": o.participant, "rate_hz": o.control_hz,
                           "command": o.action},
            "sensors": self.sensors(ego["sensors"]),
        }  # fmt: skip
        if o.task == "navigate":  # in the run folder's scenario.json; metrics.json times it
            ego["task"] = {"goal": {"x_m": goal.x_m, "y_m": goal.y_m, "radius_m": o.goal_radius_m}}
        where = o.scenario if isinstance(o.scenario, str) else "the env's scenario"
        return parse_scenario(data, source=f"episode {seed} of {where}")

    def sensors(self, own: list[dict[str, Any]]) -> list[dict[str, Any]]:
        """The observed sensors: the scenario's own of each kind, else the env's default;
        the vessel's other sensors are left out (each costs the run time every step)."""
        o, out = self.options, []
        for kind in o.sensors:
            mine = [s for s in own if s["type"] == kind]
            out.append(mine[0] if mine else _default_sensor(kind, o))
        return out

    def sensor_names(self) -> list[str]:
        own = self.base.vessels[self.index].model_dump(mode="json")["sensors"]
        return [s["name"] for s in self.sensors(own)]


def _base(scenario: str | dict[str, Any]) -> Scenario:
    """A dict's file paths are taken from the current folder, as `--set`'s are, and a bare
    bundled image name (`bay.png`) names the bundled one, as in a file."""
    if isinstance(scenario, dict):
        return parse_scenario(absolute_paths(scenario, Path.cwd()), source="the env's scenario")
    return load_scenario(Path(scenario) if scenario.endswith(".json") else scenario)


def _no_one_waited_for(scenario: Scenario, vessel: str) -> None:
    """Another vessel whose controller no program starts would hold every episode's run
    until its start timeout (a swarm researcher's reset waited 20 s, then failed): said
    before any run, with what to do."""
    for i, v in enumerate(scenario.vessels):
        c = v.controller
        if v.id != vessel and c is not None and c.program is None:
            raise EnvOptionsError(
                f"vessels.{i} ({v.id}) is driven by participant {c.participant!r}, which no "
                f"program starts: an env drives one vessel ({vessel}); give {v.id} a script "
                "or its controller a `program`, or leave it out"
            )


def run_seconds(options: EnvOptions) -> float:
    """An episode's run: its steps and three control periods more (the env ends it)."""
    return (options.max_steps + 3) / options.control_hz


def _others(scenario: Scenario, ego: int, models: Models, *, seconds: float) -> np.ndarray:
    """(x, y, footprint radius) of every buoy, and of every other scenario vessel at each
    point of its path over an episode of `seconds` (paths.py: with a margin)."""
    rows = []
    for i, v in enumerate(scenario.vessels):
        if i != ego:
            path = path_points(v, scenario, seconds=seconds)
            path[:, 2] += footprint_m(models[v.model])
            rows += path.tolist()
    buoy = models[BUOY_MODEL]
    rows += [(b.x_m, b.y_m, footprint_m(buoy)) for b in scenario.buoys]
    return np.array(rows, dtype=np.float64).reshape(-1, 3)


def _default_sensor(kind: str, o: EnvOptions) -> dict[str, Any]:
    """A sensor at the control rate; the LiDAR small (its range image is pooled 4 columns to
    one, so a thin buoy between coarse beams still shows) and no farther than it is read."""
    params: dict[str, Any] = {}
    if kind == "lidar":
        rows, cols = o.lidar_shape
        params = {"preset": None, "channels": rows, "columns": 4 * cols,
                  "vertical_fov_deg": 30.0, "max_range_m": o.lidar_range_m}  # fmt: skip
    return {"name": kind, "type": kind, "rate_hz": o.control_hz, "params": params}
