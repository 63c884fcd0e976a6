"""What a CataBot environment is: its task, scenario, observations, actions and rewards.

One strict model, checked when the env is made (`gymnasium.make("CataBot/Navigate-v0",
sensors=["lidar"])`): a misspelt keyword or a value out of range is an error naming the
field and what is allowed (catabot.config.base.explain), never a failure seconds later in
the run behind the env.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field, ValidationError, model_validator

from catabot.config.base import ConfigError, Strict, VesselId, WorldName, explain

Task = Literal["navigate", "station_keep"]
SensorKind = Literal["gps", "imu", "lidar"]


class EnvOptionsError(ConfigError):
    """Keywords a CataBot env cannot be made with; the message names the field."""


class Rewards(Strict):
    """Weights of the reward terms (per step unless said otherwise)."""

    progress: float = Field(1.0, description="per metre the vessel gets closer to the goal")
    distance: float = Field(0.0, ge=0, description="minus this per metre from the goal (station)")
    heading: float = Field(0.0, ge=0, description="minus this per radian of heading error")
    energy: float = Field(0.01, ge=0, description="minus this times the mean squared command")
    time: float = Field(0.0, ge=0, description="minus this every step")
    goal: float = Field(100.0, description="once, on reaching the goal (navigate)")
    collision: float = Field(100.0, ge=0, description="minus this once, on a collision")
    grounding: float = Field(100.0, ge=0, description="minus this once, on grounding")


class EnvOptions(Strict):
    task: Task = "navigate"
    scenario: str | dict[str, Any] = Field(
        "navigate", description="a bundled scenario's name, a scenario file, or its JSON as a dict"
    )
    vessel: VesselId | None = Field(None, description="the vessel the env drives: the first")
    world: WorldName | None = Field(None, description="key prefix catabot/<world>-gym<pid>x<n>")
    participant: VesselId = Field("gym", description="the env's name in the lockstep")
    action: Literal["thrust", "twist"] = "thrust"
    control_hz: float = Field(10.0, gt=0, description="env steps per simulated second")
    max_steps: int = Field(600, ge=1, le=1_000_000, description="steps before truncation")
    sensors: tuple[SensorKind, ...] = Field((), description="observed besides the state")
    lidar_shape: tuple[int, int] = Field((16, 64), description="range image rows, columns")
    lidar_range_m: float = Field(50.0, gt=0, le=1000, description="farther reads as this")
    start_radius_m: float = Field(40.0, ge=0, description="start within this of the pose")
    goal_distance_m: tuple[float, float] = Field((20.0, 60.0), description="navigate: min, max")
    goal_radius_m: float = Field(3.0, gt=0, description="navigate: reached within this")
    max_surge_mps: float = Field(2.0, gt=0, description="twist actions: surge at |a| = 1")
    max_yaw_rate_radps: float = Field(0.5, gt=0, description="twist: yaw rate at |a| = 1")
    recording: Literal["off", "csv"] = Field("off", description="the episode's run folder")
    runs_dir: str | None = Field(
        None, description="keep each episode's run folder (logs, CSV) here; None: deleted"
    )
    rewards: Rewards = Rewards()
    step_timeout_s: float = Field(60.0, gt=0, description="wait for the run at most this")
    start_timeout_s: float = Field(120.0, gt=0, description="wait for the run to start")
    prelaunch: bool = Field(
        False, description="start the next episode's run in the background (reset(seed=None))"
    )

    @model_validator(mode="after")
    def _ranges(self) -> EnvOptions:
        low, high = self.goal_distance_m
        if not 0 < low <= high:
            raise ValueError(f"goal_distance_m must be 0 < min <= max (got {low}, {high})")
        rows, cols = self.lidar_shape
        if not (1 <= rows <= 256 and 1 <= cols <= 4096):
            raise ValueError(
                f"lidar_shape must be 1..256 rows, 1..4096 columns (got {rows}x{cols})"
            )
        if self.recording != "off" and self.runs_dir is None:
            raise ValueError(f"recording {self.recording!r} needs runs_dir (where to keep it)")
        if len(set(self.sensors)) != len(self.sensors):
            raise ValueError(f"sensors must not repeat (got {list(self.sensors)})")
        return self


def env_options(**kwargs: Any) -> EnvOptions:
    """The options from `gymnasium.make`'s keywords; EnvOptionsError names what is wrong."""
    try:
        return EnvOptions.model_validate(kwargs)
    except ValidationError as exc:
        raise EnvOptionsError(f"CataBot env: {explain(exc, model=EnvOptions)}") from None
