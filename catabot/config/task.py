"""A vessel's navigation task: where it should go (a goal region) and by which way (a route).

The task is data the run publishes (it is part of the resolved scenario every process and
client receives), not a controller: the recorder measures every vessel against its task
(`metrics.json`: time to the goal, cross-track error from the route), a navigator reads its
goal from it, and a training environment sets a new goal per episode by writing this field.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BeforeValidator, Field, model_validator
from pydantic.types import FiniteFloat

from catabot.config.base import FieldProblem, Strict


def _point(value: Any) -> Any:
    """One message for a malformed route point, not one per coordinate."""
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise ValueError("must be a point [x_m, y_m]")
    return value


RoutePoint = Annotated[tuple[FiniteFloat, FiniteFloat], BeforeValidator(_point)]


class GoalRegion(Strict):
    """A disc in `map` (ENU, m): the vessel has reached its goal at the first tick its body
    origin is within `radius_m` of (x_m, y_m)."""

    x_m: FiniteFloat
    y_m: FiniteFloat
    radius_m: FiniteFloat = Field(gt=0, description="the goal region's radius (m)")


class TaskConfig(Strict):
    """What a vessel is asked to do: reach `goal`, follow `route` (a polyline of [x_m, y_m]
    points in `map`, in order), or both; at least one of them."""

    goal: GoalRegion | None = Field(None, description="the region to reach")
    route: list[RoutePoint] | None = Field(
        None, description="waypoints [[x_m, y_m], ...] (>= 2): cross-track error is measured"
    )

    @model_validator(mode="after")
    def _something_to_do(self) -> TaskConfig:
        if self.goal is None and self.route is None:
            raise FieldProblem("goal", "give a goal, a route or both")
        if self.route is not None and len(self.route) < 2:
            raise FieldProblem("route", f"needs at least 2 points (got {len(self.route)})")
        return self
