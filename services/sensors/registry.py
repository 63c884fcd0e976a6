"""Sensor types by scenario name: a new sensor is one module plus one line in SENSOR_TYPES.

A factory turns a vessel's `SensorConfig` into a model whose `sample(state, tick=,
stamp_ns=)` returns one message. Every model draws its noise from a generator seeded with
the scenario seed and the name `<vessel_id>/<sensor_name>` (common.sensor_rng), so a
sensor's samples stay the same when sensors are added, removed or moved between processes.
(The scenario schema's `SensorConfig.type` lists the allowed names too; a new type is added
there as well, so that a typo is caught when the scenario is loaded.)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from catabot.bus.messages import Message, VesselState
from catabot.config.scenario import Origin, SensorConfig
from services.sensors.camera import CameraModel
from services.sensors.common import SensorError
from services.sensors.gps import GpsModel
from services.sensors.imu import ImuModel
from services.sensors.lidar import LidarModel
from services.sensors.radar import RadarModel
from services.sensors.scene import Scene


class Sensor(Protocol):
    """What the sensors service needs of a model: its message type and one sample."""

    @property
    def message(self) -> type[Message]: ...

    def sample(self, state: VesselState, *, tick: int, stamp_ns: int) -> Message: ...


@dataclass(frozen=True)
class Mount:
    """Everything a factory may use to build one sensor on one vessel."""

    config: SensorConfig
    vessel_id: str
    seed: int
    origin: Origin
    dt_ns: int
    scene: Scene | None

    @property
    def name(self) -> str:
        """The name the sensor's randomness is seeded with: `<vessel_id>/<sensor_name>`."""
        return f"{self.vessel_id}/{self.config.name}"

    def params(self) -> Any:
        return self.config.typed_params()


SensorFactory = Callable[[Mount], Sensor]


def _imu(m: Mount) -> ImuModel:
    return ImuModel(**m.params().model_dump(), noise=m.config.noise, seed=m.seed, name=m.name)


def _gps(m: Mount) -> GpsModel:
    origin = m.origin
    return GpsModel(
        origin_lat_deg=origin.latitude_deg,
        origin_lon_deg=origin.longitude_deg,
        origin_alt_m=origin.altitude_m,
        **m.params().model_dump(),
        noise=m.config.noise,
        seed=m.seed,
        name=m.name,
    )


def _lidar(m: Mount) -> LidarModel:
    return LidarModel(m.params(), scene=m.scene, noise=m.config.noise, seed=m.seed, name=m.name)


def _radar(m: Mount) -> RadarModel:
    period = m.config.period_ns
    return RadarModel(
        m.params(), scene=m.scene, period_ns=period, noise=m.config.noise, seed=m.seed, name=m.name
    )


def _camera(m: Mount) -> CameraModel:
    return CameraModel(m.params(), scene=m.scene, seed=m.seed, name=m.name)


SENSOR_TYPES: dict[str, SensorFactory] = {
    "imu": _imu,
    "gps": _gps,
    "lidar": _lidar,
    "radar": _radar,
    "camera": _camera,
}


def build_sensor(
    config: SensorConfig,
    *,
    vessel_id: str,
    seed: int,
    origin: Origin,
    dt_ns: int,
    scene: Scene | None = None,
) -> Sensor:
    """The model for one configured sensor; refuses unknown types and fractional periods."""
    where = f"vessel {vessel_id!r} sensor {config.name!r}"
    factory = SENSOR_TYPES.get(config.type)
    if factory is None:
        raise SensorError(f"{where}: unknown type {config.type!r} (known: {sorted(SENSOR_TYPES)})")
    if dt_ns <= 0 or config.period_ns % dt_ns:
        raise SensorError(
            f"{where}: period {config.period_ns} ns ({config.rate_hz} Hz) is not a whole "
            f"number of {dt_ns} ns ticks"
        )
    return factory(Mount(config, vessel_id, seed, origin, dt_ns, scene))
