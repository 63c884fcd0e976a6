"""Where vessels start: given poses are checked against the terrain, missing ones chosen.

Runs in the launcher before anything starts (a pose on land is refused there, naming the
vessel), and the chosen poses are written into the resolved scenario that every service
reads, so all processes agree on them. Placement is a pure function of the scenario.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from contextlib import contextmanager

import numpy as np

from catabot.config.base import ScenarioError
from catabot.config.scenario import Pose, Scenario
from catabot.config.terrain import TerrainError
from catabot.config.vessel import VesselModel, VesselModelError, load_vessel_model
from catabot.world.hulls import box_gaps, footprints
from catabot.world.rotations import turn_xy
from catabot.world.terrain import Terrain

CLEARANCE_M = 0.5  # a vessel's keel above the seabed at its start
BUOY_CLEARANCE_M = 0.1  # a moored buoy's: a mark may lie in shallow water
BUOY_MODEL = "buoy"  # every buoy's vessel model
Models = Mapping[str, VesselModel]  # every model a scenario names, by its reference


def scenario_models(scenario: Scenario) -> dict[str, VesselModel]:
    """Each model the scenario names, read once (the placement, the traffic plan and the
    bodies share them), and the buoy's; a model that does not load is named by the field
    that named it."""
    models: dict[str, VesselModel] = {}
    for where, ref in model_fields(scenario):
        try:
            if ref is not None and ref not in models:
                models[ref] = load_vessel_model(ref)
        except VesselModelError as exc:
            raise ScenarioError(f"{where}: {exc}") from None
    return models


def model_fields(scenario: Scenario) -> list[tuple[str, str | None]]:
    """(the field, the model it names) for every model reference, the buoys' last."""
    named: list[tuple[str, str | None]]
    named = [(f"vessels.{i}.model", v.model) for i, v in enumerate(scenario.vessels)]
    named += [(f"traffic.models.{i}.model", m.model) for i, m in enumerate(scenario.traffic.models)]
    named += [(f"traffic.boats.{i}.model", b.model) for i, b in enumerate(scenario.traffic.boats)]
    return [*named, ("buoys", BUOY_MODEL)]


def keel_depth_m(model: VesselModel) -> float:
    """How far the hull reaches below the body origin (an upper bound of the draft)."""
    return max(max(0.0, -(h.center_m[2] - h.vertical_extent_m / 2)) for h in model.hulls)


def footprint_m(model: VesselModel) -> float:
    """Radius of the circle around the body origin that covers every hull."""
    return max(
        math.hypot(abs(h.center_m[0]) + h.length_m / 2, abs(h.center_m[1]) + h.beam_m / 2)
        for h in model.hulls
    )


def resolve_poses(scenario: Scenario, terrain: Terrain | None, *, models: Models) -> Scenario:
    """Every vessel with a pose: given ones checked, missing ones placed in open water."""
    chosen = [models[v.model] for v in scenario.vessels]
    placed = [  # given poses first: a vessel placed for you keeps clear of later ones too
        (v.pose.x_m, v.pose.y_m, footprint_m(m))
        for v, m in zip(scenario.vessels, chosen, strict=True)
        if v.pose is not None
    ]
    vessels = []
    for index, (vessel, model) in enumerate(zip(scenario.vessels, chosen, strict=True)):
        pose = vessel.pose
        if pose is None:
            pose = _choose(index, model, terrain, placed)
            placed.append((pose.x_m, pose.y_m, footprint_m(model)))
        if terrain is not None:
            _check(index, vessel.id, pose, model, terrain)
        vessels.append(vessel.model_copy(update={"pose": pose}))
    return scenario.model_copy(update={"vessels": vessels})


def check_marks(scenario: Scenario, terrain: Terrain | None, *, models: Models) -> None:
    """Buoys, goals and route points in water: a buoy given on land sat on the ground all
    run, and a goal on land is a task no vessel can meet, both accepted without a word."""
    if terrain is None:
        return
    buoy = models[BUOY_MODEL]
    draft, reach = keel_depth_m(buoy), footprint_m(buoy)
    for i, b in enumerate(scenario.buoys):
        with _as_field(f"buoys.{i} ({b.id})"):
            terrain.check_start(b.x_m, b.y_m, draft_m=draft, footprint_m=reach,
                                clearance_m=BUOY_CLEARANCE_M, what="buoy")  # fmt: skip
    for i, v in enumerate(scenario.vessels):
        task, where = v.task, f"vessels.{i}.task"
        if task is not None and task.goal is not None:
            with _as_field(f"{where}.goal ({v.id})"):
                terrain.check_water(task.goal.x_m, task.goal.y_m, what="goal")
        for k, (x, y) in enumerate(task.route or () if task is not None else ()):
            with _as_field(f"{where}.route.{k} ({v.id})"):
                terrain.check_water(x, y, what="route point")


def check_apart(scenario: Scenario, *, models: Models) -> None:
    """No hull starts inside another or on a buoy (plan-view boxes, physics' collision
    shapes): two vessels given one pose collided at t = 0, and the run said nothing."""
    named = [
        (f"vessels.{i}.pose ({v.id})", v.model, v.pose) for i, v in enumerate(scenario.vessels)
    ]
    named += [(f"buoys.{i} ({b.id})", BUOY_MODEL, Pose(x_m=b.x_m, y_m=b.y_m))
              for i, b in enumerate(scenario.buoys)]  # fmt: skip
    if len(named) < 2:
        return
    offset, half = footprints([models[model] for _, model, _ in named])
    poses = [pose for _, _, pose in named if pose is not None]
    assert len(poses) == len(named), "resolve_poses placed every vessel"
    heading = np.array([p.yaw_rad for p in poses])
    xy = np.array([(p.x_m, p.y_m) for p in poses])
    a, b = np.triu_indices(len(named), k=1)
    gaps = box_gaps(xy + turn_xy(offset, heading), heading, half, a, b)
    over = np.flatnonzero(gaps < 0.0)
    if over.size:
        k = int(over[0])
        raise ScenarioError(
            f"{named[b[k]][0]}: starts overlapping {named[a[k]][0]} by {-gaps[k]:.2f} m "
            "(their hulls as seen from above): start them apart"
        )


Hull = tuple[str, Pose, VesselModel]  # a body already placed: its name, pose and model


def hull_clash(pose: Pose, model: VesselModel, placed: list[Hull]) -> str:
    """Why a hull given its start cannot start there ("" if it can): it overlaps a placed
    hull, their plan-view boxes (physics' collision shapes) as `check_apart` sees them, so
    boats may be given starts alongside each other, as scenario vessels may."""
    if not placed:
        return ""
    poses = [pose, *(p for _, p, _ in placed)]
    offset, half = footprints([model, *(m for _, _, m in placed)])
    heading = np.array([p.yaw_rad for p in poses])
    xy = np.array([(p.x_m, p.y_m) for p in poses])
    others = np.arange(1, len(poses))
    gaps = box_gaps(xy + turn_xy(offset, heading), heading, half, np.zeros_like(others), others)
    k = int(np.argmin(gaps))
    if gaps[k] >= 0.0:
        return ""
    return f"its hull overlaps {placed[k][0]}'s by {-gaps[k]:.2f} m (seen from above)"


@contextmanager
def _as_field(field: str) -> Iterator[None]:
    """A terrain check's refusal as the scenario's, naming the field."""
    try:
        yield
    except TerrainError as exc:
        raise ScenarioError(f"{field}: {exc}") from None


def _check(index: int, vid: str, pose: Pose, model: VesselModel, terrain: Terrain) -> None:
    try:
        terrain.check_start(
            pose.x_m,
            pose.y_m,
            draft_m=keel_depth_m(model),
            footprint_m=footprint_m(model),
            clearance_m=CLEARANCE_M,
            z_m=pose.z_m,
        )
    except TerrainError as exc:
        raise ScenarioError(f"vessels.{index}.pose ({vid}): {exc}") from None


def _choose(
    index: int,
    model: VesselModel,
    terrain: Terrain | None,
    placed: list[tuple[float, float, float]],
) -> Pose:
    """Open water near the terrain centre (or the origin), clear of vessels already placed."""
    radius = footprint_m(model)
    for ring in range(200):
        x, y = _candidate(ring, terrain)
        if terrain is not None:
            try:
                x, y = terrain.find_open_water(
                    keel_depth_m(model), near=(x, y), clearance_m=CLEARANCE_M, footprint_m=radius
                )
            except TerrainError as exc:
                raise ScenarioError(f"vessels.{index}.pose: {exc}") from None
        if all(math.hypot(x - px, y - py) > 2 * (radius + pr) for px, py, pr in placed):
            return Pose(x_m=x, y_m=y, yaw_rad=0.0)
    raise ScenarioError(f"vessels.{index}.pose: no free open water found; give a pose")


def _candidate(ring: int, terrain: Terrain | None) -> tuple[float, float]:
    """A spiral of search points around the centre, 8 m apart."""
    cx, cy = (terrain.size_m[0] / 2, terrain.size_m[1] / 2) if terrain is not None else (0.0, 0.0)
    angle = ring * 2.39996  # golden angle: an even spread without a grid
    r = 8.0 * math.sqrt(ring)
    return cx + r * math.cos(angle), cy + r * math.sin(angle)
