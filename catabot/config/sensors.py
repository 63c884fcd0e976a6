"""Every sensor type the scenario accepts, in one registry: its parameters (validated before
anything starts), the message it publishes and the entry point of its model. A new sensor
type is one params model here, one line in SENSOR_TYPES and its model in services/sensors/.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from pydantic import Field, StrictBool, model_validator

from catabot.bus.messages import CameraFrame, GpsFix, ImuSample, LidarScan, Message, RadarSweep
from catabot.config.base import FieldProblem, Strict

Vec3 = tuple[float, float, float]


SENSOR_MEMORY_BUDGET = 2 * 2**30  # bytes one sensor may take while it samples
BYTES_PER_PIXEL = 200  # a camera frame's peak in the whole stack: cast, outputs, message, copies


class SensorParams(Strict):
    """Base of a sensor's parameters: strict, frozen, finite."""

    def memory_problem(self) -> str:
        """Why one sample would not fit in `SENSOR_MEMORY_BUDGET` ("" when it fits)."""
        return ""

    def rate_problem(self, rate_hz: float) -> str:
        """Why these parameters do not go with sampling at `rate_hz` ("" when they do)."""
        return ""

    def rays_per_s(self, rate_hz: float) -> float:
        """Rays cast a second: what a sensor costs, for sharing sensors out between
        processes (catabot/world/shards.py); 0 for a sensor that casts none."""
        return 0.0


class ImuParams(SensorParams):
    gyro_sigma: float = Field(0.009, ge=0, description="rad/s, white noise per sample")
    accel_sigma: float = Field(0.021, ge=0, description="m/s^2, white noise per sample")
    gyro_bias_instability: float = Field(0.0008, ge=0, description="rad/s, Gauss-Markov bias")
    accel_bias_instability: float = Field(0.004, ge=0, description="m/s^2, Gauss-Markov bias")
    bias_tau_s: float = Field(300.0, gt=0, description="s, the biases' correlation time")
    gyro_random_walk: float = Field(0.0, ge=0, description="rad/s/sqrt(s)")
    accel_random_walk: float = Field(0.0, ge=0, description="m/s^2/sqrt(s)")
    lever_arm: Vec3 = Field(
        (0.0, 0.0, 0.0), description="m, the IMU from the body origin (body frame, FLU)"
    )


class GpsParams(SensorParams):
    horizontal_sigma: float = Field(0.5, ge=0, description="m, per axis")
    vertical_sigma: float = Field(1.0, ge=0, description="m")
    antenna_offset: Vec3 = Field(
        (0.0, 0.0, 0.0), description="m, the antenna from the body origin (body frame, FLU)"
    )
    method: Literal["wgs84", "paper_table"] = "wgs84"
    altitude: Literal["local", "ellipsoid"] = Field(
        "local",
        description="local: height above the origin's level (the world as a local map); "
        "ellipsoid: WGS84 height of the flat world (grows as d^2 / 2R from the origin)",
    )

    @model_validator(mode="after")
    def _curvature_needs_wgs84(self) -> GpsParams:
        if self.altitude == "ellipsoid" and self.method != "wgs84":
            raise FieldProblem("altitude", "'ellipsoid' needs method 'wgs84' (the paper's "
                               "tables ignore the Earth's curvature)")  # fmt: skip
        return self


class RadarParams(SensorParams):
    """Marine radar (paper III-B.2.b: 250 m, one turn in 2 s, range noise sigma 0.2 m)."""

    range_m: float = Field(250.0, gt=0, le=100_000, description="out to this slant range")
    rotation_period_s: float = Field(
        2.0, ge=0.25, le=60, description="one antenna turn, clockwise (marine: 1-2.5 s)"
    )
    range_bins: int = Field(512, ge=1, le=4096)
    beam_width_deg: float = Field(1.5, gt=0, le=20, description="horizontal; beams at half")
    sub_rays: int = Field(3, ge=1, le=16, description="rays across one beam's width")
    elevations_deg: tuple[float, ...] = Field(
        (0.0, 1.0, 3.0),
        min_length=1,
        description="rays at or above the horizon (shores, tall ships), 0-60 deg",
    )
    fan_target_height_m: float = Field(
        0.3, ge=0, description="down-looking fan sees targets this tall at any range; 0: no fan"
    )
    fan_min_range_m: float = Field(
        10.0, gt=0, description="nearest sea range of the fan: nearer low targets are unseen"
    )
    range_noise_sigma_m: float = Field(0.2, ge=0)
    antenna_height_m: float = Field(
        3.0, gt=0, description="above the body origin, and above the vessel's shape"
    )
    sea_clutter: StrictBool = Field(False, description="keep returns from the water surface")
    ppi_size_px: int = Field(256, ge=16, le=2048)
    fade_s: float | None = Field(
        None, gt=0, description="PPI returns fade to nothing in this time; null: 1.5 turns"
    )

    @model_validator(mode="after")
    def _geometry(self) -> RadarParams:
        """Limits the fields' descriptions gave and nothing checked: a ray below the horizon
        is the fan's, a fan aimed above the antenna is none, a blind zone past the range
        leaves nothing to see."""
        low = [e for e in self.elevations_deg if not 0.0 <= e <= 60.0]
        if low:
            raise FieldProblem("elevations_deg", f"{low[0]:g} is not 0-60 deg (rays at or "
                               "above the horizon; the fan sees down)")  # fmt: skip
        if self.fan_target_height_m >= self.antenna_height_m:
            raise FieldProblem("fan_target_height_m", f"{self.fan_target_height_m:g} m is not "
                               f"below the antenna ({self.antenna_height_m:g} m); 0: no "
                               "fan")  # fmt: skip
        if self.fan_min_range_m >= self.range_m:
            raise FieldProblem("fan_min_range_m", f"{self.fan_min_range_m:g} m is not within "
                               f"range_m ({self.range_m:g} m)")  # fmt: skip
        return self

    @property
    def fade(self) -> float:
        """The PPI's persistence: by default a turn and a half, so the image made once a turn
        shows the whole turn, the oldest returns faintest (1 s of a 2 s turn showed half)."""
        return self.fade_s if self.fade_s is not None else 1.5 * self.rotation_period_s

    def rate_problem(self, rate_hz: float) -> str:
        if self.rotation_period_s * rate_hz < 1.0:
            return (
                f"rotation_period_s {self.rotation_period_s:g}: one sample sweeps at most one "
                f"turn, so at least 1 / rate_hz = {1.0 / rate_hz:g} s"
            )
        return ""

    def rays_per_s(self, rate_hz: float) -> float:
        beams = 360.0 / (self.beam_width_deg / 2)  # a turn, whatever the sampling rate
        return beams * self.sub_rays * len(self.elevations_deg) / self.rotation_period_s


class CameraOutputs(SensorParams):
    color: StrictBool = True
    depth: StrictBool = True
    normals: StrictBool = True
    segmentation: StrictBool = True


class CameraParams(SensorParams):
    """Pinhole camera (services/sensors/camera.py); the mount is in the body frame (FLU), its
    rpy turn the camera's forward-looking axes (x forward, z up; positive pitch looks down)
    before the optical frame (z forward, x right, y down). Rain is the scenario's
    `rain.rate_mm_h`; it veils and streaks the colour image only."""

    width: int = Field(640, ge=2, le=4096)
    height: int = Field(480, ge=2, le=4096)
    hfov_deg: float = Field(80.0, gt=1, lt=170)
    mount_xyz: Vec3 = Field(
        (0.5, 0.0, 1.5),
        description="m, body FLU; above the vessel's shape (which is in the scene)",
    )
    mount_rpy_deg: Vec3 = (0.0, 0.0, 0.0)
    outputs: CameraOutputs = CameraOutputs()
    max_range_m: float = Field(1000.0, gt=0)
    occluded_fraction: float = Field(
        0.5, ge=0, le=1, description="occluded when visible px < fraction x its silhouette"
    )

    def rays_per_s(self, rate_hz: float) -> float:
        return float(self.width * self.height) * rate_hz

    def memory_problem(self) -> str:
        need = self.width * self.height * BYTES_PER_PIXEL
        if need <= SENSOR_MEMORY_BUDGET:
            return ""
        most = SENSOR_MEMORY_BUDGET // BYTES_PER_PIXEL / 1e6
        return (
            f"a {self.width} x {self.height} camera needs about {need / 1e9:.1f} GB a frame, "
            f"over the {SENSOR_MEMORY_BUDGET / 2**30:g} GiB a sensor may take: at most about "
            f"{most:.1f} million pixels (3840 x 2160 fits)"
        )


PAPER_REFLECTIVITY = 0.9  # the paper's s, every surface alike


class SurfaceReflectivity(Strict):
    """Each labelled surface's diffuse reflectance s at a LiDAR's 905 nm (rho = s / pi), for
    `reflection: "lambertian"`. Calm water sends the beam on, away from the sensor (specular),
    and returns little; painted hulls and buoys much; soil and rock between. Estimates."""

    water: float = Field(0.02, gt=0, le=1)
    terrain: float = Field(0.3, gt=0, le=1)
    vessel: float = Field(0.6, gt=0, le=1)
    buoy: float = Field(0.8, gt=0, le=1)


class LidarParams(SensorParams):
    """A spinning LiDAR (paper III-B.2.a: OS1-like, 32 x 512, 45 deg vertical, 360 deg, 100 m)
    and the constants of its rain model (services/sensors/rain.py; paper defaults, Q at 905 nm).
    The rain rate itself is the scenario's `rain.rate_mm_h`. `preset: "os1"` is those figures.
    The carrier's own shape is in the scene: mount the sensor where it sees over it."""

    preset: Literal["os1"] | None = "os1"
    channels: int = Field(32, ge=1, le=256)
    columns: int = Field(512, ge=1, le=8192)
    vertical_fov_deg: float = Field(45.0, gt=0, le=180, description="symmetric about level")
    max_range_m: float = Field(100.0, gt=0)
    min_range_m: float = Field(
        0.0,
        ge=0,
        description="returns nearer are dropped, raindrops too (the paper's model "
        "has no blind zone: 0; an OS1's data sheet gives 0.3-0.8 m)",
    )
    range_noise_sigma_m: float = Field(0.01, ge=0)
    mount_xyz: Vec3 = (0.0, 0.0, 1.0)
    mount_yaw_deg: float = Field(0.0, ge=-360, le=360)
    mount_pitch_deg: float = Field(0.0, ge=-90, le=90, description="+ nose down (FLU pitch)")
    drop_diameter_mm: float = Field(
        3.25, gt=0, le=10, description="the paper's text; the original's code used 2.75 "
        "(2.5 x the drops a cubic metre: N(D) falls with D, eq. 1)",
    )  # fmt: skip
    beam_radius_m: float = Field(0.02, gt=0)
    detection_threshold: float = Field(5e-6, gt=0)
    reflectivity: float = Field(PAPER_REFLECTIVITY, gt=0, le=1, description="s in rho = s / pi")
    q_ext: float = Field(2.0, ge=0)
    q_back: float = Field(2.0, ge=0)
    reflection: Literal["paper", "lambertian"] = Field(
        "paper",
        description="paper: every surface returns `reflectivity` and the detection threshold "
        "applies only with a raindrop in the beam, as the paper's model; lambertian: each "
        "surface its `surface_reflectivity` times the cosine of the beam's incidence, and "
        "every return must pass the threshold (water returns only near the sensor)",
    )
    surface_reflectivity: SurfaceReflectivity = SurfaceReflectivity()

    def rays_per_s(self, rate_hz: float) -> float:
        return float(self.channels * self.columns) * rate_hz

    @model_validator(mode="after")
    def _blind_zone_inside_the_range(self) -> LidarParams:
        if self.min_range_m >= self.max_range_m:
            raise FieldProblem("min_range_m", f"{self.min_range_m:g} m must be less than "
                               f"max_range_m ({self.max_range_m:g} m)")  # fmt: skip
        return self

    @model_validator(mode="after")
    def _reflectivities_of_their_model(self) -> LidarParams:
        """A value the chosen model would ignore is a mistake to name, not to drop (values,
        not fields given: a resolved scenario.json spells out every default)."""
        if self.reflection == "paper" and self.surface_reflectivity != SurfaceReflectivity():
            raise FieldProblem("surface_reflectivity", "applies with reflection 'lambertian'; "
                               "the paper's model gives every surface `reflectivity`")  # fmt: skip
        if self.reflection == "lambertian" and self.reflectivity != PAPER_REFLECTIVITY:
            raise FieldProblem("reflectivity", "is the paper model's one value for every "
                               "surface; with reflection 'lambertian' set "
                               "surface_reflectivity")  # fmt: skip
        return self


class SensorFarmConfig(Strict):
    """The sensors service as several processes (`catabot service sensors --shard i/N`), each
    owning some of the sensors (catabot/world/shards.py), on one machine or spread over
    several; the recording is the same for any number."""

    shards: int = Field(1, ge=1, le=64, description="sensor processes, sharing the sensors out")


def shard_names(service: str, shards: int) -> list[str]:
    """The participant names of a service split `shards` ways (one: the service's own)."""
    return [service] if shards == 1 else [f"{service}.{i}" for i in range(shards)]


def service_of(name: str, names: list[str]) -> tuple[str, list[str]]:
    """The program a participant of `names` runs and its shard flag: `sensors.1` of four
    sensor shards runs `catabot service sensors --shard 1/4`."""
    base, _, index = name.partition(".")
    n = sum(1 for other in names if other.partition(".")[0] == base)
    return base, ["--shard", f"{index}/{n}"] if index else []


@dataclass(frozen=True)
class SensorSpec:
    """One sensor type (Gymnasium's `EnvSpec` shape): its parameters, validated before anything
    starts; the message it publishes; and its model, `"module:Class"`, which the sensors
    service imports and builds as `Class(params, mount)` (the library never imports it)."""

    params: type[SensorParams]
    message: type[Message]
    entry_point: str
    casts: bool = False  # casts rays into the shared scene (terrain, bodies, water)


SENSOR_TYPES: dict[str, SensorSpec] = {
    "imu": SensorSpec(ImuParams, ImuSample, "services.sensors.imu:ImuModel"),
    "gps": SensorSpec(GpsParams, GpsFix, "services.sensors.gps:GpsModel"),
    "radar": SensorSpec(RadarParams, RadarSweep, "services.sensors.radar:RadarModel", casts=True),
    "camera": SensorSpec(CameraParams, CameraFrame, "services.sensors.camera:CameraModel", True),
    "lidar": SensorSpec(LidarParams, LidarScan, "services.sensors.lidar:LidarModel", casts=True),
}
