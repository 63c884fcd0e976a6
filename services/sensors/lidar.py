"""A spinning LiDAR: the scene's ray cast, range noise, then the paper's rain model.

Beams are a (channels x columns) grid fixed in the sensor frame (FLU at the mount): channel c
at elevation -fov/2 + c fov/(channels-1) (ring 0 is the lowest beam), column j at azimuth
2 pi j / columns counter-clockwise from the sensor's forward axis. Their directions are
computed once; a scan rotates them by the vessel's pose and the mount, casts them through the
shared Scene (terrain, bodies, waves), adds Gaussian range noise to real returns, and passes
every beam through services/sensors/rain.py. The whole scan is taken at one instant (no
motion skew within the turn). The scan is published in the sensor frame with labels.

Randomness: one generator per sensor (`seeding.rng(seed, "<vessel>/<sensor>")`); each scan draws
a fixed number of values (noise, Poisson, uniform per beam) whatever it sees, so a sensor's
draws never depend on other sensors or on the scene.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import CLASS_NONE, LABEL_CLASSES, LidarScan, VesselState
from catabot.config.sensors import LidarParams
from catabot.world import rotations, seeding
from services.sensors.common import SensorError, rotation_from_quaternion
from services.sensors.cull import grid_pairs
from services.sensors.mount import Mount
from services.sensors.rain import RainParams, apply_rain
from services.sensors.scene import Hits

F64 = NDArray[np.float64]


def beam_elevations(channels: int, vertical_fov_deg: float) -> F64:
    """Elevation (rad) of each channel, lowest first."""
    half = math.radians(vertical_fov_deg) / 2
    return np.linspace(-half, half, channels) if channels > 1 else np.zeros(1)


def beam_directions(channels: int, columns: int, vertical_fov_deg: float) -> F64:
    """Unit directions (channels * columns, 3) in the sensor frame, channel-major."""
    elevation = beam_elevations(channels, vertical_fov_deg)
    azimuth = 2.0 * math.pi * np.arange(columns) / columns
    el, az = np.meshgrid(elevation, azimuth, indexing="ij")
    dirs = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=-1)
    return dirs.reshape(-1, 3)


def mount_rotation(yaw_deg: float, pitch_deg: float) -> F64:
    """Sensor-to-body rotation Rz(yaw) @ Ry(pitch); positive pitch tilts the sensor nose-down."""
    return rotations.rpy(0.0, pitch_deg, yaw_deg)


class LidarModel:
    """One LiDAR on one vessel; `sample` casts a full scan from the vessel's state."""

    message = LidarScan

    def __init__(self, params: LidarParams, mount: Mount) -> None:
        scene, noise, seed, name = mount.scene, mount.noise, mount.seed, mount.name
        if scene is None:
            raise SensorError(f"lidar {name!r} needs the ray-casting scene")
        self.params, self.scene, self.noise = params, scene, noise
        self.rain = RainParams(
            drop_diameter_mm=params.drop_diameter_mm,
            beam_radius_m=params.beam_radius_m,
            detection_threshold=params.detection_threshold,
            reflectivity=params.reflectivity,
            q_ext=params.q_ext,
            q_back=params.q_back,
        )
        self.shape = (params.channels, params.columns)
        self.dirs = beam_directions(params.channels, params.columns, params.vertical_fov_deg)
        self.elevations = beam_elevations(params.channels, params.vertical_fov_deg)
        self.dirs_t = np.ascontiguousarray(self.dirs.T)  # (3, N): points are built per axis
        self.mount_rot = mount_rotation(params.mount_yaw_deg, params.mount_pitch_deg)
        self.mount_xyz = np.asarray(params.mount_xyz, dtype=np.float64)
        self.ring = np.repeat(np.arange(params.channels, dtype=np.uint16), params.columns)
        self.rng = seeding.rng(seed, name)
        self.lambertian = params.reflection == "lambertian"
        shown = params.surface_reflectivity  # s of each label class, by its index
        self.s_of_class = np.array([getattr(shown, c, 0.0) for c in LABEL_CLASSES]) / math.pi

    def _backscatter(self, beams: F64, hits: Hits) -> F64:
        """rho of each beam's surface, Lambertian: s / pi times the cosine of its incidence."""
        incidence = np.abs(np.einsum("ij,ij->i", beams, hits.normal))
        return np.asarray(self.s_of_class[hits.cls] * incidence)

    def sample(self, state: VesselState, *, tick: int, stamp_ns: int) -> LidarScan:
        """One scan at the vessel's pose in `state`, stamped `stamp_ns`."""
        p = self.params
        body_rot = rotation_from_quaternion(state.orientation)
        origin = np.asarray(state.position, dtype=np.float64) + body_rot @ self.mount_xyz
        rot = body_rot @ self.mount_rot  # sensor -> map
        cones = self.scene.cones(origin, p.max_range_m)  # bodies: only the beams near each
        unit = (cones.axis / cones.dist[:, None]) @ rot  # in the sensor frame
        pairs = grid_pairs(unit, cones.cos_half, self.elevations, p.columns)
        pairs = pairs[0], cones.body[pairs[1]]
        beams = self.dirs @ rot.T
        hits = self.scene.cast(origin, beams, p.max_range_m, pairs, normals=self.lambertian)
        distance = hits.range.astype(np.float64)
        noise = self.rng.normal(0.0, p.range_noise_sigma_m, distance.shape)
        if self.noise:
            distance = np.maximum(distance + noise, 0.0)  # inf stays inf
        rho = self._backscatter(beams, hits) if self.lambertian else None
        rain = apply_rain(distance, p.max_range_m, self.scene.rain_rate_mm_h, self.rain, self.rng,
                          rho=rho, gated=self.lambertian)  # fmt: skip
        if p.min_range_m > 0:  # the blind zone: a drop (or a surface) nearer gives no return
            blind = rain.range < p.min_range_m
            rain.range[blind], rain.intensity[blind], rain.is_rain[blind] = np.inf, 0.0, False
        keep = np.flatnonzero(np.isfinite(rain.range))
        r = np.take(rain.range, keep)
        rain_hit = np.take(rain.is_rain, keep)
        points = np.empty((keep.size, 3), dtype=np.float32)
        np.multiply(np.take(self.dirs_t, keep, axis=1), r, out=points.T, casting="same_kind")
        return LidarScan(
            tick=tick,
            stamp_ns=stamp_ns,
            points=points,
            intensity=np.take(rain.intensity, keep).astype(np.float32),
            ring=np.take(self.ring, keep),
            cls=np.where(rain_hit, np.uint8(CLASS_NONE), np.take(hits.cls, keep)),
            instance=np.where(rain_hit, np.int32(0), np.take(hits.instance, keep)),
            is_rain=rain_hit,
            range_image=rain.range.reshape(self.shape).astype(np.float32),
        )
