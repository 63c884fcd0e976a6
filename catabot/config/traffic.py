"""The scenario's `traffic` section: how many boats, which models, which behaviours.

Kept apart from scenario.py so the schema of traffic stays readable in one place; the
plan (where each boat starts and what it does) is derived from it by traffic_plan.py,
a pure function every process evaluates the same way.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, StrictBool, field_validator, model_validator

from catabot.config.base import Angle, FieldProblem, Seed, Strict

BEHAVIOURS = ("circle", "waypoints", "hold")
MAX_YAW_RATE = 0.35  # rad/s: the traffic's turn rate limit (a 5 m/s boat, about 20 deg/s)
Behaviour = Literal["circle", "waypoints", "hold"]
Point = tuple[float, float]


class Region(Strict):
    """A square (or rectangle) in `map`: centre and size; null centre = terrain centre or origin."""

    center_m: Point | None = None
    size_m: Point = (500.0, 500.0)

    @field_validator("size_m")
    @classmethod
    def _positive(cls, v: Point) -> Point:
        if min(v) <= 0:
            raise ValueError(f"both sizes must be > 0 m (got {v})")
        return v


class ModelWeight(Strict):
    model: str = "monohull"
    weight: float = Field(1.0, gt=0)


class CircleParams(Strict):
    """The original's Circles: 5 m/s at 15 deg/s, i.e. a radius of about 19 m."""

    radius_m: Point = Field((19.1, 19.1), description="[min, max] radius drawn per boat")
    speed_mps: float = Field(5.0, gt=0, le=20)
    direction: Literal["ccw", "cw", "random"] = "ccw"

    @field_validator("radius_m")
    @classmethod
    def _range(cls, v: Point) -> Point:
        if not 1.0 <= v[0] <= v[1]:
            raise ValueError(f"need 1 <= min <= max (got {v})")
        return v


class WaypointParams(Strict):
    """The original's Waypoints: 5 random points in a 1000 m square, 5 m/s, back and forth."""

    points: list[Point] | None = Field(None, description="explicit path; null: random per boat")
    count: int = Field(5, ge=2, le=50)
    region: Region = Region(size_m=(1000.0, 1000.0))
    mode: Literal["loop", "back_and_forth"] = "back_and_forth"
    speed_mps: float = Field(5.0, gt=0, le=20)
    tolerance_m: float = Field(5.0, gt=0)
    buoys: StrictBool = True

    @field_validator("points")
    @classmethod
    def _enough(cls, v: list[Point] | None) -> list[Point] | None:
        if v is not None and len(v) < 2:
            raise ValueError(f"a path needs at least 2 points (got {len(v)})")
        return v


class HoldParams(Strict):
    gain: float = Field(0.5, gt=0, description="surge set-point per metre of error, 1/s")
    max_speed_mps: float = Field(2.0, gt=0)


class AvoidParams(Strict):
    """Traffic boats keep clear of buoys and of each other: a mark is rounded, not rammed.
    The scenario's own vessels (the stacks under test) are not dodged unless asked: a test
    of a stack's collision avoidance wants traffic that holds its course."""

    buoys: StrictBool = Field(
        True, description="round the buoys at waypoints and steer around every other buoy"
    )
    boats: StrictBool = Field(True, description="steer around the other traffic boats ahead")
    vessels: StrictBool = Field(
        False, description="steer around the scenario's vessels too (the ego and other stacks)"
    )
    lookahead_s: float = Field(
        8.0, gt=0, le=60, description="how far ahead a boat looks, in seconds at its speed"
    )
    clearance_m: float = Field(
        2.0, ge=0, le=50, description="free water kept between hulls, beyond their footprints"
    )


class BoatOverride(Strict):
    """Per-boat settings that replace the drawn ones (index = the boat's number)."""

    index: int = Field(ge=0)
    model: str | None = None
    x_m: float | None = None
    y_m: float | None = None
    yaw_rad: Angle | None = None
    behaviour: Behaviour | None = None
    points: list[Point] | None = None


def boat_id(index: int) -> str:
    return f"boat_{index:03d}"


class TrafficConfig(Strict):
    count: int = Field(0, ge=0, le=500)
    models: list[ModelWeight] = [ModelWeight()]
    region: Region = Region()
    seed: Seed | None = Field(None, description="null: the scenario's seed")
    behaviour_mix: dict[Behaviour, float] = {"circle": 1.0}
    circle: CircleParams = CircleParams()
    waypoints: WaypointParams = WaypointParams()
    hold: HoldParams = HoldParams()
    avoid: AvoidParams = AvoidParams()
    boats: list[BoatOverride] = []
    guidance_hz: float = Field(
        10.0,
        gt=0,
        le=1000,
        description="how often the boats' guidance (their autopilots' outer loop) computes new "
        "set-points; physics holds each one and runs the velocity controller every tick. "
        "A whole number of ticks",
    )
    shards: int = Field(
        1,
        ge=1,
        le=64,
        description="traffic processes, each guiding a contiguous block of the boats "
        "(catabot service traffic --shard I/N); the recording is the same for any number",
    )
    command_timeout_s: float | None = Field(
        None,
        gt=0,
        le=86_400,  # a day: beyond, its nanoseconds overflowed in physics
        description="an outside thrust or twist on a boat not renewed for this long hands it "
        "back to its behaviour (a controller that died stops driving it); null: it holds "
        "until a release",
    )
    setpoint_delay_ticks: int = Field(
        0,
        ge=0,
        le=1000,
        description="extra ticks before physics applies a boat's set-point (autopilot latency); "
        "lets physics step ahead of the traffic service; 0 = the one-tick minimum",
    )

    @property
    def boat_ids(self) -> list[str]:
        """The boats' ids, in `TwistBatch` order: they name keys, files and ROS topics."""
        return [boat_id(i) for i in range(self.count)]

    @model_validator(mode="after")
    def _shards_have_boats(self) -> TrafficConfig:
        if self.shards > max(self.count, 1):
            raise FieldProblem("shards", f"{self.shards} shards for {self.count} boat(s): "
                               "each shard guides at least one")  # fmt: skip
        return self

    @field_validator("models")
    @classmethod
    def _some_model(cls, v: list[ModelWeight]) -> list[ModelWeight]:
        if not v:
            raise ValueError("give at least one vessel model")
        return v

    @field_validator("behaviour_mix")
    @classmethod
    def _weights(cls, v: dict[str, float]) -> dict[str, float]:
        if not v or any(w < 0 for w in v.values()) or sum(v.values()) <= 0:
            raise ValueError(f"weights must be >= 0 with a positive sum (got {v})")
        return v

    @model_validator(mode="after")
    def _overrides_in_range(self) -> TrafficConfig:
        seen: dict[int, int] = {}  # index: the entry that pins it
        for i, b in enumerate(self.boats):
            if b.index >= self.count:
                raise ValueError(f"boats: index {b.index} is not below count {self.count}")
            if seen.setdefault(b.index, i) != i:  # the last had won, unsaid
                raise ValueError(f"boats.{i}: index {b.index} is pinned by boats.{seen[b.index]} "
                                 "already; one entry a boat")  # fmt: skip
        return self
