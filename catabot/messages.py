"""Typed messages of the bus (DESIGN.md §5).

Each message is a frozen dataclass whose fields carry their unit and axis names as
metadata, so the codec can validate payloads and the recorder can name CSV columns
with units without a second, drifting description of the same data.
Small vectors travel as plain msgpack arrays (any language can read them); bulk data
(point clouds, images) as NumPy arrays through the codec's extension type.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

SCHEMA_VERSION = 1

XYZ = ("x", "y", "z")
QUAT = ("x", "y", "z", "w")


def vec(unit: str, axes: tuple[str, ...]) -> Any:
    """A fixed-length float vector field with a unit and axis names."""
    return field(metadata={"unit": unit, "axes": axes})


def scalar(unit: str) -> Any:
    return field(metadata={"unit": unit})


def varvec(unit: str) -> Any:
    """A float vector whose length is set by the data (one entry per thruster, ...)."""
    return field(metadata={"unit": unit, "axes": None})


@dataclass(frozen=True)
class Message:
    """Base of every message; `TYPE` is the wire name, stable across versions."""

    TYPE: ClassVar[str] = ""


@dataclass(frozen=True)
class Tick(Message):
    TYPE: ClassVar[str] = "tick"
    run: str
    tick: int
    stamp_ns: int
    dt_ns: int
    dropped: tuple[str, ...] = ()


@dataclass(frozen=True)
class Ack(Message):
    TYPE: ClassVar[str] = "ack"
    run: str
    tick: int


@dataclass(frozen=True)
class End(Message):
    """The run is over; `error` is empty for a clean end and names the fault otherwise."""

    TYPE: ClassVar[str] = "end"
    run: str
    tick: int
    reason: str
    error: str = ""


@dataclass(frozen=True)
class VesselState(Message):
    """Pose in `map` (ENU), twist and acceleration in the body frame (FLU)."""

    TYPE: ClassVar[str] = "vessel_state"
    tick: int
    stamp_ns: int
    position: tuple[float, ...] = vec("m", XYZ)
    orientation: tuple[float, ...] = vec("", QUAT)
    linear_velocity: tuple[float, ...] = vec("m/s", XYZ)
    angular_velocity: tuple[float, ...] = vec("rad/s", XYZ)
    linear_acceleration: tuple[float, ...] = vec("m/s^2", XYZ)
    angular_acceleration: tuple[float, ...] = vec("rad/s^2", XYZ)


@dataclass(frozen=True)
class ThrustCmd(Message):
    """Per-thruster command, normalised: -1 full reverse, +1 full forward.

    `tick` is the producing tick for lockstep producers and -1 for free-running clients.
    """

    TYPE: ClassVar[str] = "thrust_cmd"
    thrust: tuple[float, ...] = varvec("")
    tick: int = -1
    stamp_ns: int = 0


@dataclass(frozen=True)
class TwistCmd(Message):
    """Desired surge speed and yaw rate for the vessel's velocity controller."""

    TYPE: ClassVar[str] = "twist_cmd"
    surge: float = scalar("m/s")
    yaw_rate: float = scalar("rad/s")
    tick: int = -1
    stamp_ns: int = 0


@dataclass(frozen=True)
class ImuSample(Message):
    """Body-frame specific force (gravity included: +g on z at rest), rate, orientation."""

    TYPE: ClassVar[str] = "imu"
    tick: int
    stamp_ns: int
    orientation: tuple[float, ...] = vec("", QUAT)
    angular_velocity: tuple[float, ...] = vec("rad/s", XYZ)
    linear_acceleration: tuple[float, ...] = vec("m/s^2", XYZ)


@dataclass(frozen=True)
class GpsFix(Message):
    """WGS84 fix of the antenna, with the 1-sigma noise it was drawn with (NavSatFix-like)."""

    TYPE: ClassVar[str] = "gps"
    tick: int
    stamp_ns: int
    latitude: float = scalar("deg")
    longitude: float = scalar("deg")
    altitude: float = scalar("m")
    horizontal_sigma: float = scalar("m")
    vertical_sigma: float = scalar("m")


MESSAGE_TYPES: dict[str, type[Message]] = {
    cls.TYPE: cls for cls in (Tick, Ack, End, VesselState, ThrustCmd, TwistCmd, ImuSample, GpsFix)
}
