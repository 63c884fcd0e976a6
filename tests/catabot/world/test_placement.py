"""Marks in water: buoys, a task's goal and route, and given traffic waypoints on land or
off the terrain are refused before anything starts, each naming its field (the bundled bay:
an island about x 416-480 m, y 240-290 m, the north shore from y 470 m); hulls do not start
inside each other or on a buoy."""

from __future__ import annotations

import re
from typing import Any

import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import parse_scenario
from catabot.config.vessel import load_vessel_model
from catabot.world.hulls import footprints
from catabot.world.world import World
from tests.paths import BAY

ISLAND = (440.0, 260.0)
TERRAIN = {"elevation_image": str(BAY), "min_elevation_m": -15.0, "max_elevation_m": 25.0,
           "metres_per_pixel": 2.0}  # fmt: skip


def _resolve(**top: Any) -> World:
    data = {"name": "marks", "terrain": TERRAIN,
            "vessels": [{"id": "ego", "pose": {"x_m": 300.0, "y_m": 200.0}}]} | top  # fmt: skip
    return World.resolve(parse_scenario(data))


def _refusal(**top: Any) -> str:
    with pytest.raises(ScenarioError) as caught:
        _resolve(**top)
    return str(caught.value)


def draw_task(**task: Any) -> list[dict[str, Any]]:
    return [{"id": "ego", "pose": {"x_m": 300.0, "y_m": 200.0}, "task": task}]


def test_marks_in_open_water_are_accepted() -> None:
    world = _resolve(
        buoys=[{"id": "b", "x_m": 350.0, "y_m": 260.0}],
        vessels=draw_task(
            goal={"x_m": 550.0, "y_m": 200.0, "radius_m": 2.0},
            route=[[300.0, 200.0], [550.0, 200.0]],
        ),
    )
    assert [b.id for b in world.buoys] == ["b"]


@pytest.mark.parametrize(
    ("top", "message"),
    [
        (
            {
                "buoys": [
                    {"id": "ok", "x_m": 350.0, "y_m": 260.0},
                    {"id": "rock", "x_m": ISLAND[0], "y_m": ISLAND[1]},
                ]
            },
            "buoys.1 (rock): buoy (440.0, 260.0) is on land: ground elevation",
        ),
        (
            {"buoys": [{"id": "far", "x_m": 700.0, "y_m": 10.0}]},
            "buoys.0 (far): buoy (700.0, 10.0) is outside the terrain (x 0..600 m, y 0..600 m)",
        ),
        (
            {"buoys": [{"id": "beach", "x_m": 300.0, "y_m": 465.0}]},
            "buoys.0 (beach): buoy (300.0, 465.0): water depth",
        ),
        (
            {"vessels": draw_task(goal={"x_m": ISLAND[0], "y_m": ISLAND[1], "radius_m": 2.0})},
            "vessels.0.task.goal (ego): goal (440.0, 260.0) is on land",
        ),
        (
            {"vessels": draw_task(route=[[300.0, 200.0], [-5.0, 3.0]])},
            "vessels.0.task.route.1 (ego): route point (-5.0, 3.0) is outside the terrain",
        ),
    ],
)
def test_marks_on_land_or_off_the_terrain_are_refused_by_field(
    top: dict[str, Any], message: str
) -> None:
    assert message in _refusal(**top)


def _traffic(**traffic: Any) -> dict[str, Any]:
    return {"count": 1, "behaviour_mix": {"waypoints": 1.0},
            "region": {"center_m": [300.0, 150.0], "size_m": [100.0, 100.0]}} | traffic  # fmt: skip


def test_given_waypoints_on_land_are_refused_by_field() -> None:
    """It used to end 2000 start draws later in 'no free open water for boat 0'."""
    points = [[350.0, 150.0], list(ISLAND)]
    message = _refusal(traffic=_traffic(waypoints={"points": points}))
    assert "traffic.waypoints.points.1: waypoint (440.0, 260.0) is on land" in message
    boats = [{"index": 0, "behaviour": "waypoints", "points": [[350.0, 150.0], [300.0, 459.0]]}]
    message = _refusal(traffic=_traffic(boats=boats))
    assert (
        "traffic.boats.0.points.1: waypoint (300.0, 459.0): water 1.67 m deep, needs more than 2 m"
        in message
    )


def test_a_given_leg_across_the_island_is_refused() -> None:
    points = [[350.0, 265.0], [540.0, 265.0]]
    message = _refusal(traffic=_traffic(waypoints={"points": points, "mode": "back_and_forth"}))
    assert message.endswith(
        "traffic.waypoints.points: the leg from (350, 265) to (540, 265) crosses land or "
        "water under 2 m deep"
    )


@pytest.mark.parametrize(
    ("top", "message"),
    [
        ({"vessels": [{"id": "a", "pose": {"x_m": 0.0, "y_m": 0.0}},
                      {"id": "b", "pose": {"x_m": 0.5, "y_m": 0.3, "yaw_rad": 1.0}}]},
         "vessels.1.pose (b): starts overlapping vessels.0.pose (a) by 1.30 m"),
        ({"vessels": [{"id": "a", "pose": {"x_m": 0.0, "y_m": 0.0}}],
          "buoys": [{"id": "m", "x_m": 0.2, "y_m": 0.0}]},
         "buoys.0 (m): starts overlapping vessels.0.pose (a)"),
    ],
)  # fmt: skip
def test_hulls_that_start_inside_each_other_are_refused(top: dict[str, Any], message: str) -> None:
    """Two vessels given one pose collided at t = 0 without a word."""
    with pytest.raises(ScenarioError, match=re.escape(message)):
        World.resolve(parse_scenario({"name": "apart"} | top))


def test_alongside_is_apart_and_a_placed_vessel_keeps_clear_of_later_given_poses() -> None:
    beam = 2 * float(footprints([load_vessel_model("catabot")])[1][0, 1])
    alongside = [{"id": "a", "pose": {"x_m": 0.0, "y_m": 0.0}},
                 {"id": "b", "pose": {"x_m": 0.0, "y_m": beam + 0.05}}]  # fmt: skip
    World.resolve(parse_scenario({"name": "apart", "vessels": alongside}))
    later = [{"id": "a"}, {"id": "b", "pose": {"x_m": 0.0, "y_m": 0.0}}]
    pose = World.resolve(parse_scenario({"name": "apart", "vessels": later})).scenario.vessels[0]
    assert pose.pose is not None and (pose.pose.x_m, pose.pose.y_m) != (0.0, 0.0)
