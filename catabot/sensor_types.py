"""Every sensor type the scenario accepts: its parameters (validated before anything
starts) and the message it publishes. The sensor's model lives in `services/sensors/`
and is registered there under the same name; this table is the library's half, so the
scenario, the stream table and the recorder know a type without importing a service.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from catabot.messages import GpsFix, ImuSample, Message

Vec3 = tuple[float, float, float]


class SensorParams(BaseModel):
    """Base of a sensor's parameters: strict, frozen, finite."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class ImuParams(SensorParams):
    gyro_sigma: float = Field(0.009, ge=0, description="rad/s, white noise per sample")
    accel_sigma: float = Field(0.021, ge=0, description="m/s^2, white noise per sample")
    gyro_bias_instability: float = Field(0.0008, ge=0, description="rad/s, Gauss-Markov bias")
    accel_bias_instability: float = Field(0.004, ge=0, description="m/s^2, Gauss-Markov bias")
    bias_tau_s: float = Field(300.0, gt=0)
    gyro_random_walk: float = Field(0.0, ge=0, description="rad/s/sqrt(s)")
    accel_random_walk: float = Field(0.0, ge=0, description="m/s^2/sqrt(s)")
    lever_arm: Vec3 = (0.0, 0.0, 0.0)


class GpsParams(SensorParams):
    horizontal_sigma: float = Field(0.5, ge=0, description="m, per axis")
    vertical_sigma: float = Field(1.0, ge=0, description="m")
    antenna_offset: Vec3 = (0.0, 0.0, 0.0)
    method: Literal["wgs84", "paper_table"] = "wgs84"


@dataclass(frozen=True)
class SensorType:
    params: type[SensorParams]
    message: type[Message]


SENSOR_TYPES: dict[str, SensorType] = {
    "imu": SensorType(ImuParams, ImuSample),
    "gps": SensorType(GpsParams, GpsFix),
}
