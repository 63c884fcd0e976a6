"""Samples of every message and helpers shared by the codec tests."""

from __future__ import annotations

import dataclasses

import msgpack
import numpy as np

from catabot.bus import codec
from catabot.bus.messages import (
    Ack,
    BodyStates,
    CameraFrame,
    End,
    GpsFix,
    ImuSample,
    LidarScan,
    Message,
    RadarSweep,
    SettingsChange,
    ThrustCmd,
    Tick,
    TwistBatch,
    TwistCmd,
    VesselState,
    WaypointsCmd,
)

SAMPLES: dict[str, Message] = {
    "tick": Tick(run="3f2a9c1d0b7e", tick=41, stamp_ns=410_000_000, dt_ns=10_000_000),
    "ack": Ack(run="3f2a9c1d0b7e", tick=41),
    "settings_change": SettingsChange(tick=500, stamp_ns=5_000_000_000, key="rain", value="25.0"),
    "end": End(
        run="3f2a9c1d0b7e",
        tick=5999,
        reason="fault",
        error="participant 'sensors' missed the 10 s deadline of tick 6000",
    ),
    "vessel_state": VesselState(
        tick=120,
        stamp_ns=1_200_000_000,
        position=(12.5, -3.25, 0.084),
        orientation=(0.0012, -0.0031, 0.3826834323650898, 0.9238795325112867),
        linear_velocity=(1.42, -0.03, 0.001),
        angular_velocity=(0.0, 0.002, -0.2),
        linear_acceleration=(0.15, 0.0, -0.01),
        angular_acceleration=(0.0, 0.0, 1e-5),
    ),
    "twist_batch": TwistBatch(
        tick=7,
        stamp_ns=70_000_000,
        ids=("boat_000", "boat_001"),
        surge=np.array([2.0, 1.5]),
        yaw_rate=np.array([0.1, -0.05]),
    ),
    "body_states": BodyStates(
        tick=120,
        stamp_ns=1_200_000_000,
        ids=("ego", "boat_000", "buoy_0"),
        position=np.arange(9, dtype=np.float64).reshape(3, 3) / 3,
        orientation=np.tile([0.0, 0.0, 0.3826834323650898, 0.9238795325112867], (3, 1)),
        linear_velocity=np.full((3, 3), 1.42),
        angular_velocity=np.zeros((3, 3)),
        linear_acceleration=np.full((3, 3), -0.01),
        angular_acceleration=np.full((3, 3), 1e-5),
    ),
    "thrust_cmd": ThrustCmd(thrust=(0.8, -0.35), tick=7, stamp_ns=70_000_000),
    "twist_cmd": TwistCmd(surge=1.5, yaw_rate=-0.2, tick=-1, stamp_ns=0),
    "waypoints_cmd": WaypointsCmd(
        points=(10.0, 0.0, 10.0, 25.0), speed=5.0, tolerance=3.0, mode="loop"
    ),
    "imu": ImuSample(
        tick=99,
        stamp_ns=990_000_000,
        orientation=(0.0, 0.0, 0.0, 1.0),
        angular_velocity=(0.001, -0.002, 0.05),
        linear_acceleration=(0.02, 0.01, 9.80665),
    ),
    "gps": GpsFix(
        tick=100,
        stamp_ns=1_000_000_000,
        latitude=40.7003123,
        longitude=-74.0170456,
        altitude=1.2,
        horizontal_sigma=0.0,
        vertical_sigma=0.0,
    ),
    "lidar_scan": LidarScan(
        tick=20,
        stamp_ns=200_000_000,
        points=np.arange(12, dtype=np.float32).reshape(4, 3),
        intensity=np.array([1e-4, 2e-5, 3e-3, 4e-6], dtype=np.float32),
        ring=np.array([0, 1, 1, 31], dtype=np.uint16),
        cls=np.array([1, 2, 0, 3], dtype=np.uint8),
        instance=np.array([0, 0, 0, 2], dtype=np.int32),
        is_rain=np.array([False, False, True, False]),
        range_image=np.full((2, 3), np.inf, dtype=np.float32),
    ),
    "radar_sweep": RadarSweep(
        tick=21,
        stamp_ns=210_000_000,
        azimuth_start_rad=0.5,
        azimuth_end_rad=0.48,
        heading_rad=-1.0,
        range_m=250.0,
        beams=2,
        intensity=np.array([[0, 200, 0], [0, 0, 9]], dtype=np.uint8),
        ranges=np.array([90.0, np.inf], dtype=np.float32),
    ),
    "camera_frame": CameraFrame(
        tick=22,
        stamp_ns=220_000_000,
        width=3,
        height=2,
        hfov_rad=1.4,
        objects=1,
        color=np.zeros((2, 3, 3), dtype=np.uint8),
        depth=np.full((2, 3), np.inf, dtype=np.float32),
        normals=np.zeros((0,), dtype=np.uint8),
        segmentation=np.array([[0, 3, 3], [1, 1, 1]], dtype=np.uint8),
        instance=np.array([[0, 2, 2], [0, 0, 0]], dtype=np.uint16),
        boxes=np.array([[2, 3, 1, 0, 3, 1]], dtype=np.float32),
        box_flags=np.array([[0, 1, 40]], dtype=np.uint8),
    ),
}

DTYPES = ["bool", "u1", "u2", "u4", "u8", "i1", "i2", "i4", "i8", "f2", "f4", "f8"]


def _body(msg: Message) -> dict:
    return codec.unpack(codec.encode(msg))


def _payload(body: dict) -> bytes:
    return msgpack.packb(body, use_bin_type=True)


def _same(a: Message, b: Message) -> bool:
    """Field-by-field equality, arrays by value, dtype and shape (== on arrays is elementwise)."""
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
            if not (np.array_equal(x, y) and x.dtype == y.dtype and x.shape == y.shape):
                return False
        elif x != y:
            return False
    return type(a) is type(b)


def _root(arr: np.ndarray) -> object:
    base: object = arr
    while isinstance(base, np.ndarray) and base.base is not None:
        base = base.base
    return base
