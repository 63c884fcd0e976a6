"""vessels[].task: a goal region and/or a route, refused with the field's path when wrong."""

from __future__ import annotations

from typing import Any

import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import json_schema, parse_scenario


def draw_task(task: Any) -> Any:
    return parse_scenario({"vessels": [{"id": "ego", "task": task}]}).vessels[0].task


def test_goal_and_route() -> None:
    task = draw_task({"goal": {"x_m": 1, "y_m": 2, "radius_m": 3}, "route": [[0, 0], [1, 1.5]]})
    assert (task.goal.x_m, task.goal.radius_m) == (1.0, 3.0)
    assert task.route == [(0.0, 0.0), (1.0, 1.5)]
    assert draw_task({"route": [[0, 0], [5, 0]]}).goal is None


@pytest.mark.parametrize(
    ("task", "message"),
    [
        ({}, "vessels.0.task.goal: give a goal, a route or both"),
        ({"route": [[0, 0]]}, "vessels.0.task.route: needs at least 2 points (got 1)"),
        ({"route": [[0, 0], [1]]}, "vessels.0.task.route.1: must be a point [x_m, y_m]"),
        ({"route": [[0, 0], [1, "x"]]}, "vessels.0.task.route.1.1: must be a number"),
        (
            {"goal": {"x_m": 0, "y_m": 0, "radius_m": 0}},
            "vessels.0.task.goal.radius_m: must be > 0",
        ),
        ({"goal": {"x_m": 0, "y_m": 0}}, "vessels.0.task.goal.radius_m: required field missing"),
        (
            {"goal": {"x_m": 0, "y_m": 0, "radius_m": 1}, "speed": 2},
            "unknown field (allowed: goal, route)",
        ),
    ],
)
def test_bad_tasks_name_the_field(task: Any, message: str) -> None:
    with pytest.raises(ScenarioError) as err:
        draw_task(task)
    assert message in str(err.value)


def test_encounter_radius_is_positive() -> None:
    with pytest.raises(ScenarioError, match=r"recording\.encounter_radius_m: must be > 0"):
        parse_scenario({"vessels": [{"id": "a"}], "recording": {"encounter_radius_m": 0}})


def test_schema_describes_the_task() -> None:
    defs = json_schema()["$defs"]
    assert set(defs["TaskConfig"]["properties"]) == {"goal", "route"}
    assert defs["GoalRegion"]["properties"]["radius_m"]["exclusiveMinimum"] == 0
