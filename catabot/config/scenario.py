"""The scenario (DESIGN.md §6): one model per section, and the rules that span sections
(rates in whole ticks, which services and participants a scenario needs). Reading files
is `catabot.config.load`; what a scenario means for a run is `catabot.world.World`."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import (
    Field,
    StrictBool,
    StrictInt,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from catabot.bus.clock import NS_PER_S, ticks_for
from catabot.config.base import (
    BuoyId,
    FieldProblem,
    ParticipantName,
    Seed,
    SensorName,
    Strict,
    VesselId,
    WorldName,
    naming_allowed,
    unique,
)
from catabot.config.controller import ControllerConfig, check_programs
from catabot.config.environment import CurrentConfig, RainConfig, WindConfig
from catabot.config.live import SettingChange, check_timeline
from catabot.config.pose import MAX_RATE_RADPS, MAX_SPEED_MPS, Pose, Velocity
from catabot.config.ros import GATEWAY, RosConfig, check_ros
from catabot.config.sensors import SENSOR_TYPES, SensorFarmConfig, shard_names
from catabot.config.task import TaskConfig
from catabot.config.terrain import TerrainConfig
from catabot.config.traffic import TrafficConfig
from catabot.config.waves import WaveConfig


class ClockConfig(Strict):
    deadline_s: float = Field(10.0, gt=0, description="per-tick deadline for every participant")
    start_timeout_s: float = Field(60.0, gt=0, description="time allowed for services to join")
    policy: Literal["abort", "drop"] = "abort"
    realtime_factor: float | None = Field(None, gt=0, description="1.0 = wall clock; null = AFAP")
    window_ticks: int = Field(
        40, ge=1, le=1000, description="how far a participant may step ahead of the slowest"
    )
    external_participants: list[ParticipantName] = Field(
        [], description="names of stepping participants started outside `catabot run`"
    )

    @field_validator("external_participants")
    @classmethod
    def _own_names(cls, names: list[str]) -> list[str]:
        """Each once, and none a CataBot process's: a stack named `physics` took its place."""
        taken = [n for n in names if n.partition(".")[0] in SERVICE_NAMES]
        if taken:
            raise ValueError(f"{taken[0]!r} is a CataBot process's name; pick another")
        if len(set(names)) != len(names):
            raise ValueError(f"each name once (got {names})")
        return names


class TwistStep(Strict):
    """The velocity set-point a script step gives: the bus's limits (catabot/bus/checks.py)."""

    surge_mps: float = Field(ge=-MAX_SPEED_MPS, le=MAX_SPEED_MPS)
    yaw_rate_radps: float = Field(ge=-MAX_RATE_RADPS, le=MAX_RATE_RADPS)


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
            raise FieldProblem("thrust", "commands are normalised: each in [-1, 1] "
                               f"(got {[round(v, 6) for v in self.thrust]})")  # fmt: skip
        return self


class SensorConfig(Strict):
    name: SensorName
    type: str = Field(
        description="a sensor type (catabot/config/sensors.py); `params` follow its model",
        json_schema_extra={"enum": list(SENSOR_TYPES)},
    )
    rate_hz: float = Field(gt=0)
    noise: StrictBool = Field(True, description="false: ideal, without its random noise and "
                              "biases; the world's effects stay (rain, occlusion)")  # fmt: skip
    params: dict[str, Any] = Field({}, validate_default=True,  # filled when left out too
        description="the type's parameters (defaults if empty)")  # fmt: skip

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
        if kind is None:
            return v
        try:
            return kind.params.model_validate(v).model_dump()
        except ValidationError as exc:
            raise naming_allowed(exc, model=kind.params) from None

    def typed_params(self) -> Any:
        """The parameters as the type's own model (every default filled in)."""
        return SENSOR_TYPES[self.type].params.model_validate(self.params)

    @property
    def period_ns(self) -> int:
        return round(NS_PER_S / self.rate_hz)


class VesselConfig(Strict):
    id: VesselId
    model: str = "catabot"
    pose: Pose | None = Field(None, description="null: open water near the terrain centre")
    velocity: Velocity = Field(Velocity(), description="body-frame velocity at t = 0")
    script: list[ScriptStep] = []
    command_timeout_s: float | None = Field(
        None, gt=0, le=86_400, description="an outside (free) thrust or twist not renewed for "
        "this long hands the vessel back to its script, or rest (a stack that died stops "
        "steering it); null: it holds until a release",
    )  # fmt: skip
    sensors: list[SensorConfig] = []
    controller: ControllerConfig | None = Field(
        None, description="a lockstep stack outside `catabot run` that commands this vessel"
    )
    task: TaskConfig | None = Field(
        None, description="a goal region and/or a route, measured in metrics.json"
    )

    @field_validator("sensors")
    @classmethod
    def _unique_names(cls, sensors: list[SensorConfig]) -> list[SensorConfig]:
        return unique(sensors, attr="name", what="sensor names")


class WaterConfig(Strict):
    density_kg_m3: float = Field(1025.0, gt=900, lt=1100)
    waves: WaveConfig = WaveConfig()
    current: CurrentConfig = CurrentConfig()


class BuoyConfig(Strict):
    """A floating buoy body (the bundled `buoy` model), moored at (x_m, y_m) by a soft
    horizontal spring (services/physics/loads.py): it bobs, heels, yields when hit, returns."""

    id: BuoyId
    x_m: float
    y_m: float


class Origin(Strict):
    """WGS84 position of the world origin (the terrain image's bottom-left corner)."""

    latitude_deg: float = Field(0.0, ge=-90, le=90)
    longitude_deg: float = Field(0.0, ge=-180, le=180)
    altitude_m: float = 0.0


class RecordingConfig(Strict):
    csv: StrictBool = True
    mcap: StrictBool = True
    mcap_compression: Literal["zstd", "lz4", "none"] = Field(
        "zstd", description="the MCAP files' chunks: zstd (smallest; as cheap as none), lz4 or none"
    )
    dataset: StrictBool = Field(True, description="camera frames as PNGs + labels in dataset/")
    dataset_rate_hz: float | None = Field(
        None,
        gt=0,
        description="camera frames saved to dataset/ per second, each camera's rate divided by a "
        "whole number; null: every frame",
    )
    ppi: StrictBool = Field(True, description="the radar's PPI (the paper's minimap) in dataset/")
    rerun: StrictBool = Field(False, description="run.rrd for the rerun viewer, from run.mcap")
    traffic_rate_hz: float | None = Field(
        10.0,
        gt=0,
        description="traffic boats' and buoys' states recorded per second (CSV, odom, /tf); "
        "null: every tick. Scenario vessels are recorded every tick",
    )
    encounter_radius_m: float = Field(
        50.0, gt=0, description="metrics.json: two vessels this close are an encounter (CPA)"
    )
    export: list[Literal["yolo", "coco", "kitti", "segmentation"]] = Field(
        [], description="datasets converted into export/<format>/ when the run ends"
    )

    @model_validator(mode="after")
    def _needs_mcap(self) -> RecordingConfig:
        """run.rrd and the KITTI export are made from run.mcap after the run (YOLO, COCO and
        segmentation from dataset/: they were refused without run.mcap, which they never
        read)."""
        wanted = ["export (kitti)"] if "kitti" in self.export else []
        wanted += ["rerun"] if self.rerun else []
        if wanted and not self.mcap:
            raise FieldProblem(wanted[0].split()[0], "needs recording.mcap: true (made from it)")
        return self


class Scenario(Strict):
    name: WorldName = "default"
    seed: Seed = 0
    duration_s: float = Field(60.0, gt=0, le=1e7, description="simulated seconds (<= 115 days)")
    dt_ns: StrictInt = Field(
        10_000_000,
        ge=100_000,
        le=100_000_000,
        description="physics tick, integer ns (0.1 ms to 100 ms, or a stiff model's own limit)",
    )
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
    sensors: SensorFarmConfig = SensorFarmConfig()
    ros: RosConfig | None = Field(None, description="the ROS 2 gateway (services/ros)")
    settings: list[SettingChange] = Field(
        [], description="run-time setting changes by time (catabot/config/live.py; catabot set)"
    )

    @field_validator("vessels")
    @classmethod
    def _unique_ids(cls, vessels: list[VesselConfig]) -> list[VesselConfig]:
        return unique(vessels, attr="id", what="vessel ids")

    @model_validator(mode="after")
    def _ros_names(self) -> Scenario:
        check_ros(self.ros, self.vessels, self.traffic.boat_ids, self.clock.deadline_s)
        return self

    @model_validator(mode="after")
    def _controller_programs(self) -> Scenario:
        check_programs([v.controller for v in self.vessels], SERVICE_NAMES, bridge=GATEWAY)
        return self

    @model_validator(mode="after")
    def _exports_have_sources(self) -> Scenario:
        """Camera datasets need a camera and dataset/; KITTI scans need a LiDAR."""
        types = {s.type for v in self.vessels for s in v.sensors}
        rec = self.recording
        for fmt in rec.export:
            need = "lidar" if fmt == "kitti" else "camera"
            if need not in types:
                raise FieldProblem("recording.export", f"{fmt!r} needs a {need} on a vessel")
            if need == "camera" and not rec.dataset:
                raise FieldProblem("recording.export", f"{fmt!r} needs recording.dataset: true")
            if need == "camera":
                self._cameras_give(fmt, EXPORT_OUTPUTS[fmt])
        return self

    def _cameras_give(self, fmt: str, outputs: tuple[str, ...]) -> None:
        """Every camera's frames go into the export: each must make what it is built from
        (found at the end of the run, a whole run was lost, its export half written)."""
        for i, vessel in enumerate(self.vessels):
            for j, sensor in enumerate(vessel.sensors):
                if sensor.type != "camera":
                    continue
                on = sensor.typed_params().outputs
                off = [o for o in outputs if not getattr(on, o)]
                if off:
                    raise FieldProblem(
                        "recording.export",
                        f"{fmt!r} is made from each camera's {' and '.join(outputs)}: "
                        f"vessels.{i}.sensors.{j} ({sensor.name}) has {', '.join(off)} off",
                    )

    @model_validator(mode="after")
    def _shards_have_sensors(self) -> Scenario:
        count = sum(len(v.sensors) for v in self.vessels)
        if self.sensors.shards > max(count, 1):
            raise FieldProblem(
                "sensors.shards",
                f"{self.sensors.shards} shards for {count} sensor(s): each shard owns at least one",
            )
        return self

    @model_validator(mode="after")
    def _settings_timeline(self) -> Scenario:
        check_timeline(self)
        return self

    @property
    def duration_ns(self) -> int:
        return round(self.duration_s * NS_PER_S)

    @property
    def ticks(self) -> int:
        return ticks_for(self.duration_ns, self.dt_ns)


EXPORT_OUTPUTS = {  # the camera outputs each camera dataset is made from
    "yolo": ("color",), "coco": ("color", "segmentation"),
    "segmentation": ("color", "segmentation"),
}  # fmt: skip
SERVICE_NAMES = ("conductor", "physics", "sensors", "traffic", "recorder", GATEWAY, "viewer")


def services(scenario: Scenario) -> list[str]:
    """The CataBot services a scenario needs, in start order."""
    names = ["physics"]
    if any(v.sensors for v in scenario.vessels):
        names += shard_names("sensors", scenario.sensors.shards)
    if scenario.traffic.count > 0:
        names += shard_names("traffic", scenario.traffic.shards)
    if scenario.recording.csv or scenario.recording.mcap:
        names.append("recorder")
    if scenario.ros is not None:
        names.append(GATEWAY)
    return names


def shard_count(scenario: Scenario, service: str) -> int:
    """How many processes a service runs as (`sensors.shards`, `traffic.shards`)."""
    return {"sensors": scenario.sensors.shards, "traffic": scenario.traffic.shards}.get(service, 1)


def participants(scenario: Scenario) -> list[str]:
    """Every stepping participant of the run: services (the ROS gateway only with
    `ros.lockstep`: otherwise it observes), then external ones (named in
    `clock.external_participants` or as a vessel's controller), each once."""
    observer = scenario.ros is not None and not scenario.ros.lockstep
    stepping = [s for s in services(scenario) if not (observer and s == GATEWAY)]
    controllers = [v.controller.participant for v in scenario.vessels if v.controller]
    external = dict.fromkeys([*scenario.clock.external_participants, *controllers])
    return stepping + [n for n in external if n not in stepping]
