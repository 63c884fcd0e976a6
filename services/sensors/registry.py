"""Sensor types by scenario name: a new sensor is one module plus one line in SENSOR_TYPES.

A factory turns a vessel's `SensorConfig` into a model whose `sample(state, tick=,
stamp_ns=)` returns one message. Every model draws its noise from a generator seeded with
the scenario seed and the name `<vessel_id>/<sensor_name>` (common.sensor_rng), so a
sensor's samples stay the same when sensors are added, removed or moved between processes.
(The scenario schema's `SensorConfig.type` lists the allowed names too; a new type is added
there as well, so that a typo is caught when the scenario is loaded.)
"""

from __future__ import annotations

from typing import Protocol

from catabot.messages import Message, VesselState
from catabot.scenario import Origin, SensorConfig
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


class SensorFactory(Protocol):
    """Builds a sensor of one type for one vessel."""

    def __call__(
        self,
        config: SensorConfig,
        *,
        vessel_id: str,
        seed: int,
        origin: Origin,
        dt_ns: int,
        scene: Scene | None = None,
    ) -> Sensor: ...


def source_name(vessel_id: str, config: SensorConfig) -> str:
    """The name a sensor's randomness is seeded with."""
    return f"{vessel_id}/{config.name}"


def _imu(
    config: SensorConfig,
    *,
    vessel_id: str,
    seed: int,
    origin: Origin,
    dt_ns: int,
    scene: Scene | None = None,
) -> ImuModel:
    params = config.typed_params().model_dump()
    return ImuModel(**params, noise=config.noise, seed=seed, name=source_name(vessel_id, config))


def _gps(
    config: SensorConfig,
    *,
    vessel_id: str,
    seed: int,
    origin: Origin,
    dt_ns: int,
    scene: Scene | None = None,
) -> GpsModel:
    return GpsModel(
        origin_lat_deg=origin.latitude_deg,
        origin_lon_deg=origin.longitude_deg,
        origin_alt_m=origin.altitude_m,
        **config.typed_params().model_dump(),
        noise=config.noise,
        seed=seed,
        name=source_name(vessel_id, config),
    )


def _radar(
    config: SensorConfig,
    *,
    vessel_id: str,
    seed: int,
    origin: Origin,
    dt_ns: int,
    scene: Scene | None = None,
) -> RadarModel:
    return RadarModel(
        config.typed_params(),
        scene=scene,
        period_ns=config.period_ns,
        noise=config.noise,
        seed=seed,
        name=source_name(vessel_id, config),
    )


def _camera(
    config: SensorConfig,
    *,
    vessel_id: str,
    seed: int,
    origin: Origin,
    dt_ns: int,
    scene: Scene | None = None,
) -> CameraModel:
    return CameraModel(
        config.typed_params(), scene=scene, seed=seed, name=source_name(vessel_id, config)
    )


def _lidar(
    config: SensorConfig,
    *,
    vessel_id: str,
    seed: int,
    origin: Origin,
    dt_ns: int,
    scene: Scene | None = None,
) -> LidarModel:
    name = source_name(vessel_id, config)
    params = config.typed_params()
    return LidarModel(params, scene=scene, noise=config.noise, seed=seed, name=name)


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
    return factory(config, vessel_id=vessel_id, seed=seed, origin=origin, dt_ns=dt_ns, scene=scene)
