"""The scenario file (DESIGN.md §6): JSON in, validated models out.

Validation happens before any process starts, and every error names the field and
what is allowed, because a typo found after a ten-minute run is a lost ten minutes.
Files in the original simulator's `SettingsConfig.json` format are mapped by
`catabot.config.settings_config`.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Literal

from pydantic import (
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from catabot.bus.clock import NS_PER_S, ClockError, period_in_ticks, ticks_for
from catabot.bus.keys import check_name
from catabot.config.base import ConfigError, Strict, explain
from catabot.config.environment import CurrentConfig, RainConfig, WindConfig
from catabot.config.sensors import SENSOR_TYPES
from catabot.config.terrain import TerrainConfig
from catabot.config.traffic import TrafficConfig
from catabot.config.waves import WaveConfig

BUNDLED = Path(__file__).parents[1] / "data" / "scenarios"


class ScenarioError(ConfigError):
    """A scenario that cannot run; the message names the file, field and allowed values."""


class ClockConfig(Strict):
    deadline_s: float = Field(10.0, gt=0, description="per-tick deadline for every participant")
    start_timeout_s: float = Field(60.0, gt=0, description="time allowed for services to join")
    policy: Literal["abort", "drop"] = "abort"
    realtime_factor: float | None = Field(None, gt=0, description="1.0 = wall clock; null = AFAP")
    window_ticks: int = Field(
        40, ge=1, le=1000, description="how far a participant may step ahead of the slowest"
    )
    external_participants: list[str] = Field(
        [], description="names of stepping participants started outside `catabot run`"
    )

    @field_validator("external_participants")
    @classmethod
    def _names(cls, names: list[str]) -> list[str]:
        return [check_name("participant", n) for n in names]


class Pose(Strict):
    """Start pose in `map` (ENU); z is ignored for floating vessels (they settle)."""

    x_m: float = 0.0
    y_m: float = 0.0
    yaw_rad: float = 0.0


class TwistStep(Strict):
    surge_mps: float
    yaw_rate_radps: float


class ScriptStep(Strict):
    """From `t_s` on, the vessel gets this command (until the next step)."""

    t_s: float = Field(ge=0)
    thrust: list[float] | None = None
    twist: TwistStep | None = None

    @model_validator(mode="after")
    def _one_command(self) -> ScriptStep:
        if (self.thrust is None) == (self.twist is None):
            raise ValueError("give exactly one of 'thrust' or 'twist'")
        if self.thrust is not None and not all(-1 <= v <= 1 for v in self.thrust):
            raise ValueError("thrust commands are normalised: each in [-1, 1]")
        return self


class SensorConfig(Strict):
    name: str
    type: str = Field(
        description="a sensor type: see catabot/sensor_types.py",
        json_schema_extra={"enum": list(SENSOR_TYPES)},
    )
    rate_hz: float = Field(gt=0)
    noise: bool = True
    params: dict[str, Any] = Field({}, description="the type's parameters (defaults if empty)")

    @field_validator("name")
    @classmethod
    def _key_safe(cls, v: str) -> str:
        return check_name("sensor", v)

    @field_validator("type")
    @classmethod
    def _known_type(cls, v: str) -> str:
        if v not in SENSOR_TYPES:
            allowed = ", ".join(map(repr, SENSOR_TYPES))
            raise ValueError(f"unknown sensor type {v!r}; allowed: {allowed}")
        return v

    @field_validator("params")
    @classmethod
    def _params(cls, v: dict[str, Any], info: ValidationInfo) -> dict[str, Any]:
        kind = SENSOR_TYPES.get(info.data.get("type", ""))
        return kind.params.model_validate(v).model_dump() if kind is not None else v

    def typed_params(self) -> Any:
        """The parameters as the type's own model (every default filled in)."""
        return SENSOR_TYPES[self.type].params.model_validate(self.params)

    @property
    def period_ns(self) -> int:
        return round(NS_PER_S / self.rate_hz)


class VesselConfig(Strict):
    id: str
    model: str = "catabot"
    pose: Pose | None = Field(None, description="null: open water near the terrain centre")
    script: list[ScriptStep] = []
    sensors: list[SensorConfig] = []

    @field_validator("id")
    @classmethod
    def _key_safe(cls, v: str) -> str:
        return check_name("vessel", v)

    @field_validator("sensors")
    @classmethod
    def _unique_names(cls, sensors: list[SensorConfig]) -> list[SensorConfig]:
        names = [s.name for s in sensors]
        if len(set(names)) != len(names):
            raise ValueError(f"sensor names must be unique (got {names})")
        return sensors


class WaterConfig(Strict):
    density_kg_m3: float = Field(1025.0, gt=900, lt=1100)
    waves: WaveConfig = WaveConfig()
    current: CurrentConfig = CurrentConfig()


class BuoyConfig(Strict):
    """A floating buoy body (the bundled `buoy` model), moored at (x_m, y_m) by a soft
    horizontal spring (services/physics/loads.py): it bobs, heels, yields when hit, returns."""

    id: str
    x_m: float
    y_m: float

    @field_validator("id")
    @classmethod
    def _key_safe(cls, v: str) -> str:
        return check_name("buoy", v)


class Origin(Strict):
    """WGS84 position of the world origin (the terrain image's bottom-left corner)."""

    latitude_deg: float = Field(0.0, ge=-90, le=90)
    longitude_deg: float = Field(0.0, ge=-180, le=180)
    altitude_m: float = 0.0


class RecordingConfig(Strict):
    csv: bool = True
    mcap: bool = True


class Scenario(Strict):
    name: str = "default"
    seed: int = 0
    duration_s: float = Field(60.0, gt=0)
    dt_ns: int = Field(10_000_000, gt=0, description="physics tick, integer nanoseconds")
    clock: ClockConfig = ClockConfig()
    origin: Origin = Origin()
    water: WaterConfig = WaterConfig()
    wind: WindConfig = WindConfig()
    rain: RainConfig = RainConfig()
    terrain: TerrainConfig | None = None
    buoys: list[BuoyConfig] = []
    vessels: list[VesselConfig] = Field(min_length=1)
    traffic: TrafficConfig = TrafficConfig()
    recording: RecordingConfig = RecordingConfig()

    @field_validator("name")
    @classmethod
    def _key_safe(cls, v: str) -> str:
        return check_name("world", v)

    @field_validator("vessels")
    @classmethod
    def _unique_ids(cls, vessels: list[VesselConfig]) -> list[VesselConfig]:
        ids = [v.id for v in vessels]
        if len(set(ids)) != len(ids):
            raise ValueError(f"vessel ids must be unique (got {ids})")
        return vessels

    @property
    def duration_ns(self) -> int:
        return round(self.duration_s * NS_PER_S)

    @property
    def ticks(self) -> int:
        return ticks_for(self.duration_ns, self.dt_ns)


def check_rates(scenario: Scenario) -> None:
    """Refuse sensor and guidance rates that are not a whole number of ticks (DESIGN.md §4)."""
    for v_index, vessel in enumerate(scenario.vessels):
        for s_index, sensor in enumerate(vessel.sensors):
            where = f"vessels.{v_index}.sensors.{s_index}.rate_hz ({vessel.id}/{sensor.name})"
            rate_in_ticks(sensor.rate_hz, scenario.dt_ns, where=where)
    if scenario.traffic.count:
        guidance_period_ticks(scenario)
    try:
        scenario.ticks  # noqa: B018 - validates duration against dt
    except ClockError as exc:
        raise ScenarioError(f"duration_s: {exc}") from None


def rate_in_ticks(rate_hz: float, dt_ns: int, *, where: str) -> int:
    """The period of a rate in ticks; ScenarioError naming `where` unless it is whole."""
    try:  # first, so that e.g. 30 Hz at 10 ms names the allowed rates
        ticks = period_in_ticks(round(NS_PER_S / rate_hz), dt_ns, what=where)
    except ClockError as exc:
        raise ScenarioError(str(exc)) from None
    exact = NS_PER_S / rate_hz
    if not math.isclose(exact, round(exact), rel_tol=1e-12, abs_tol=1e-6):
        raise ScenarioError(f"{where}: {rate_hz} Hz is not a whole number of ns")
    return ticks


def guidance_period_ticks(scenario: Scenario) -> int:
    """Ticks between two rounds of traffic set-points (`traffic.guidance_hz`)."""
    return rate_in_ticks(scenario.traffic.guidance_hz, scenario.dt_ns, where="traffic.guidance_hz")


def services(scenario: Scenario) -> list[str]:
    """The CataBot services a scenario needs, in start order."""
    names = ["physics"]
    if any(v.sensors for v in scenario.vessels):
        names.append("sensors")
    if scenario.traffic.count > 0:
        names.append("traffic")
    if scenario.recording.csv or scenario.recording.mcap:
        names.append("recorder")
    return names


def participants(scenario: Scenario) -> list[str]:
    """Every stepping participant of the run: services, then external ones."""
    return services(scenario) + list(scenario.clock.external_participants)


def parse_scenario(data: Any, *, source: str = "<data>") -> Scenario:
    from catabot.config.settings_config import is_settings_config, map_settings_config

    if isinstance(data, dict) and is_settings_config(data):
        data = map_settings_config(data, source=source)
    try:
        scenario = Scenario.model_validate(data)
    except ValidationError as exc:
        raise ScenarioError(f"scenario {source}: {explain(exc, model=Scenario)}") from None
    check_rates(scenario)
    return scenario


def load_scenario(path: str | Path | None = None) -> Scenario:
    """Load a scenario file, or the bundled default when `path` is None."""
    file = BUNDLED / "default.json" if path is None else Path(path)
    if not file.is_file():
        bundled = BUNDLED / f"{file.name}.json"
        if path is not None and "/" not in str(path) and bundled.is_file():
            file = bundled
        else:
            raise ScenarioError(f"scenario file {str(file)!r} does not exist")
    try:
        data = json.loads(file.read_text())
    except json.JSONDecodeError as exc:
        raise ScenarioError(f"scenario {file}: not valid JSON: {exc}") from None
    return parse_scenario(absolute_paths(data, file.parent.resolve()), source=str(file))


def absolute_paths(data: Any, base: Path) -> Any:
    """Input files named relative to the scenario become absolute, so the resolved copy in
    the run folder (and every service reading it) finds the same files."""
    if not isinstance(data, dict):
        return data
    data = json.loads(json.dumps(data))
    _absolute(_node(data, "terrain"), "elevation_image", base)
    _absolute(_node(data, "water", "current", "map"), "path", base)
    vessels = data.get("vessels")
    for vessel in vessels if isinstance(vessels, list) else []:
        if isinstance(vessel, dict) and str(vessel.get("model", "")).endswith(".json"):
            _absolute(vessel, "model", base)
    return data


def _node(data: dict[str, Any], *path: str) -> dict[str, Any]:
    for key in path:
        child = data.get(key)
        if not isinstance(child, dict):
            return {}
        data = child
    return data


def _absolute(node: dict[str, Any], key: str, base: Path) -> None:
    if isinstance(node.get(key), str):
        node[key] = str(base / Path(node[key]).expanduser())


def json_schema() -> dict[str, Any]:
    """The scenario's JSON Schema, for editors (`catabot scenario schema`)."""
    schema = Scenario.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "CataBot scenario"
    return schema
