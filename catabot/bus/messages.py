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

import numpy as np

SCHEMA_VERSION = 1

LABEL_CLASSES = ("none", "water", "terrain", "vessel", "buoy")
"""Semantic classes of LiDAR points, camera pixels and boxes: the id is the index. "none"
is no surface (the sky, a raindrop, beyond range). One table for every producer and reader."""
CLASS_NONE, CLASS_WATER, CLASS_TERRAIN, CLASS_VESSEL, CLASS_BUOY = range(len(LABEL_CLASSES))

XYZ, QUAT = ("x", "y", "z"), ("x", "y", "z", "w")


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
    """On `clock/tick`: every tick up to `tick` may be stepped (a grant; DESIGN.md §4), acked
    every `ack_every` ticks and at its last; a step gets one Tick per tick. `settings`: the
    changes in the ticks it adds (settings.py), a step's those of its tick; `digest`: the
    conductor's scenario's (config/load.py), which every participant checks."""

    TYPE: ClassVar[str] = "tick"
    run: str
    tick: int
    stamp_ns: int
    dt_ns: int
    dropped: tuple[str, ...] = ()
    ack_every: int = 1
    settings: tuple[str, ...] = ()
    digest: str = ""


@dataclass(frozen=True)
class Ack(Message):
    """`tick` and every tick before it stepped. `end` (1-200 printable characters) asks the
    conductor to end the run cleanly after `tick` (a controller whose episode is over);
    `fault`, the same, says why this participant stops on a fault of its own (clock.py)."""

    TYPE: ClassVar[str] = "ack"
    run: str
    tick: int
    end: str = ""
    fault: str = ""


@dataclass(frozen=True)
class End(Message):
    """The run is over; `error` is empty for a clean end and names the fault otherwise."""

    TYPE: ClassVar[str] = "end"
    run: str
    tick: int
    reason: str
    error: str = ""


@dataclass(frozen=True)
class SettingsChange(Message):
    """Recorded on `config/changes`: a setting (JSON text) in effect from the start of `tick`."""

    TYPE: ClassVar[str] = "settings_change"
    tick: int
    stamp_ns: int
    key: str = field(metadata={"unit": ""})
    value: str = field(metadata={"unit": ""})


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


def check_ids(what: str, tick: int, ids: tuple[str, ...], expected: tuple[str, ...]) -> None:
    """Refuse a batch whose rows are not `expected`, in order: a consumer that mapped rows
    to bodies once would otherwise silently write one body's data under another's name."""
    if ids != expected:
        got, want = list(ids)[:8], list(expected)[:8]
        raise ValueError(
            f"{what} at tick {tick} lists {got}..., expected {want}... ({len(expected)} rows)"
        )


@dataclass(frozen=True)
class BodyStates(Message):
    """Every body's state at one instant in one message: row i of each array is `ids[i]`
    (a put, callback and decode per body dominated a tick with hundreds). Rows: every vessel
    (traffic boats included), then every buoy; frames as in `VesselState`; `position` (N, 3)
    m, `orientation` (N, 4) x, y, z, w, velocities and accelerations (N, 3) body frame.
    `commands`: the free commands physics took at the start of this tick (taken.py)."""

    TYPE: ClassVar[str] = "body_states"
    tick: int
    stamp_ns: int
    ids: tuple[str, ...] = field(metadata={"unit": ""})
    position: np.ndarray = field(metadata={"unit": "m"})
    orientation: np.ndarray = field(metadata={"unit": ""})
    linear_velocity: np.ndarray = field(metadata={"unit": "m/s"})
    angular_velocity: np.ndarray = field(metadata={"unit": "rad/s"})
    linear_acceleration: np.ndarray = field(metadata={"unit": "m/s^2"})
    angular_acceleration: np.ndarray = field(metadata={"unit": "rad/s^2"})
    commands: tuple[str, ...] = field(default=(), metadata={"unit": ""})

    def row(self, i: int) -> VesselState:
        """Body i as a `VesselState` (python floats: recorded bytes match the per-body form)."""
        return VesselState(self.tick, self.stamp_ns, *(tuple(a[i].tolist()) for a in self.arrays()))

    def rows(self) -> list[VesselState]:
        """Every body as a `VesselState`, in `ids` order; one `tolist` per array, not per row."""
        cols = [a.tolist() for a in self.arrays()]
        rows = zip(*cols, strict=True)
        return [VesselState(self.tick, self.stamp_ns, *map(tuple, r)) for r in rows]

    def arrays(self) -> tuple[np.ndarray, ...]:
        """The six arrays in `VesselState` field order."""
        return (self.position, self.orientation, self.linear_velocity, self.angular_velocity,
                self.linear_acceleration, self.angular_acceleration)  # fmt: skip


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
class TwistBatch(Message):
    """Twist set-points of many vessels in one message: entry i of each array is `ids[i]`.

    The traffic service steers every boat every tick; one `TwistCmd` per boat cost a put, a
    callback and a decode each in physics and in the recorder (the reason `BodyStates`
    exists, in the other direction). Lockstep only: outside control stays per vessel on
    `vessel/<id>/cmd/twist`. `surge` (N,) m/s, `yaw_rate` (N,) rad/s, float64.
    """

    TYPE: ClassVar[str] = "twist_batch"
    tick: int
    stamp_ns: int
    ids: tuple[str, ...] = field(metadata={"unit": ""})
    surge: np.ndarray = field(metadata={"unit": "m/s"})
    yaw_rate: np.ndarray = field(metadata={"unit": "rad/s"})

    def check(self, expected: tuple[str, ...]) -> None:
        """Refuse a batch for other vessels or with arrays of the wrong shape."""
        check_ids("twist batch", self.tick, self.ids, expected)
        n = len(expected)
        for name in ("surge", "yaw_rate"):
            value = getattr(self, name)
            if not isinstance(value, np.ndarray) or value.shape != (n,):
                shape = getattr(value, "shape", type(value).__name__)
                raise ValueError(f"twist batch at tick {self.tick}: {name} is {shape}, not ({n},)")


@dataclass(frozen=True)
class WaypointsCmd(Message):
    """A path for a vessel to follow (high-level control), or `mode="release"` to hand the
    vessel back to its scenario behaviour. `points` is flat: x0, y0, x1, y1, ... in `map`;
    `mode` is "loop", "back_and_forth" or "release" (no bool on the wire: any language)."""

    TYPE: ClassVar[str] = "waypoints_cmd"
    points: tuple[float, ...] = varvec("m")
    speed: float = scalar("m/s")
    tolerance: float = scalar("m")
    mode: str = "back_and_forth"
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


@dataclass(frozen=True)
class RadarSweep(Message):
    """The sector a marine radar swept in one sample: per-beam echo profiles and first returns.

    Beam i points at `azimuth_start_rad - i * step` (body frame, counter-clockwise from the bow,
    horizontal: the antenna is stabilised); the antenna turns clockwise seen from above, so
    `azimuth_end_rad` < `azimuth_start_rad` (not wrapped). `heading_rad` (ENU yaw of the vessel)
    turns the sector north-up. `intensity` is (beams, range_bins) uint8, bin j covers
    [j, j + 1) * range_m / range_bins; `ranges` (beams,) float32 is the first return, inf if none.
    """

    TYPE: ClassVar[str] = "radar_sweep"
    tick: int
    stamp_ns: int
    azimuth_start_rad: float = field(metadata={"unit": "rad"})
    azimuth_end_rad: float = field(metadata={"unit": "rad"})
    heading_rad: float = field(metadata={"unit": "rad"})
    range_m: float = field(metadata={"unit": "m"})
    beams: int = field(metadata={"unit": ""})
    intensity: np.ndarray = field(metadata={"unit": ""})
    ranges: np.ndarray = field(metadata={"unit": "m"})


@dataclass(frozen=True)
class CameraFrame(Message):
    """One camera frame; outputs that are switched off are empty arrays.

    Optical frame (ROS): z forward, x right, y down. `depth` (H, W) float32 is the distance
    along z (inf: no hit); `normals` (H, W, 3) int8 are unit normals in the optical frame
    times 127; `segmentation` (H, W) uint8 is the class (`LABEL_CLASSES`: 0 none, 1 water,
    2 terrain, 3 vessel, 4 buoy) and `instance` (H, W) uint16 the instance (0: none).
    `boxes` (K, 6) float32 rows are [instance, class, x0, y0, x1, y1] in pixels (x1, y1
    exclusive) and `box_flags` (K, 3) uint8 [truncated, occluded, visible %].
    """

    TYPE: ClassVar[str] = "camera_frame"
    tick: int
    stamp_ns: int
    width: int = field(metadata={"unit": "px"})
    height: int = field(metadata={"unit": "px"})
    hfov_rad: float = field(metadata={"unit": "rad"})
    objects: int = field(metadata={"unit": ""})
    color: np.ndarray = field(metadata={"unit": ""})
    depth: np.ndarray = field(metadata={"unit": "m"})
    normals: np.ndarray = field(metadata={"unit": ""})
    segmentation: np.ndarray = field(metadata={"unit": ""})
    instance: np.ndarray = field(metadata={"unit": ""})
    boxes: np.ndarray = field(metadata={"unit": "px"})
    box_flags: np.ndarray = field(metadata={"unit": ""})


@dataclass(frozen=True)
class LidarScan(Message):
    """One LiDAR scan in the sensor frame (FLU at the mount), returns only, with labels.

    Bulk fields are arrays, one entry per return: `points` (N, 3) float32 m, `intensity`
    float32 (relative power, paper eq. 4), `ring` uint16 (channel, 0 = lowest beam), `cls` uint8
    (`LABEL_CLASSES`; 0 for raindrops), `instance` int32, `is_rain` bool.
    `range_image` (channels, columns) float32 m holds every beam, inf where nothing returned.
    Its CSV row is a summary: the number of returns and of rain returns (catabot/tabular.py).
    """

    TYPE: ClassVar[str] = "lidar_scan"
    tick: int
    stamp_ns: int
    points: np.ndarray = field(metadata={"unit": "m", "summary": ("returns", "len")})
    intensity: np.ndarray = field(metadata={"unit": ""})
    ring: np.ndarray = field(metadata={"unit": ""})
    cls: np.ndarray = field(metadata={"unit": ""})
    instance: np.ndarray = field(metadata={"unit": ""})
    is_rain: np.ndarray = field(metadata={"unit": "", "summary": ("rain_returns", "count")})
    range_image: np.ndarray = field(metadata={"unit": "m"})


MESSAGE_TYPES: dict[str, type[Message]] = {
    cls.TYPE: cls
    for cls in (
        Tick,
        Ack,
        End,
        SettingsChange,
        VesselState,
        BodyStates,
        ThrustCmd,
        TwistCmd,
        TwistBatch,
        WaypointsCmd,
        ImuSample,
        GpsFix,
        RadarSweep,
        CameraFrame,
        LidarScan,
    )
}
