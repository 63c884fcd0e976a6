"""Sensor samples as ROS 2 messages, one converter per mounted sensor (convert.py uses them).

- IMU -> sensor_msgs/Imu, covariances from the noise parameters: per axis, the white noise
  and the bias instability added in variance (sigma^2 + bias^2); zero with noise off, and for
  the orientation, which is the true one;
- GPS -> sensor_msgs/NavSatFix, status FIX, the fix's sigmas as a diagonal covariance;
- LiDAR -> sensor_msgs/PointCloud2, 24 bytes a point: x y z intensity float32, ring uint16,
  label uint8 (`LABEL_CLASSES`, 0 for a raindrop), rain uint8, instance int32;
- radar -> PointCloud2 of the swept sector (x y z intensity float32: one point per echo cell,
  in the radar frame, level) and, once per antenna turn, the north-up PPI as a mono8 Image;
- camera -> Images in the optical frame (image_raw rgb8, depth 32FC1 in metres with +inf
  where nothing was hit, as REP 118 says, segmentation mono8 classes, instance mono16,
  normals rgb8 = (n + 1) / 2 as the dataset's PNGs) and a CameraInfo from the pinhole.
"""

from __future__ import annotations

import math
import typing
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from catabot.bus.messages import CameraFrame, GpsFix, ImuSample, LidarScan, Message, RadarSweep
from catabot.ros2 import types
from catabot.ros2.cdr import pointcloud2_encoder
from catabot.ros2.cdr_more import image_encoder, imu_encoder, navsatfix_encoder, restamper
from catabot.ros2.names import Names, camera_images
from catabot.ros2.ppi import Ppi
from catabot.world.world import MountedSensor


@dataclass(frozen=True)
class Out:
    """One ROS 2 message: its topic, type and CDR bytes (with the encapsulation header)."""

    topic: str
    type: str
    data: bytes


Want = Callable[[str], bool]
"""Which topics to build (the gateway builds only what someone subscribes to)."""
Convert = Callable[[Message, Want], list[Out]]


def everything(topic: str) -> bool:
    return True


FLOAT32, UINT8, UINT16, INT32 = 7, 2, 4, 5  # sensor_msgs/PointField datatypes
_LIDAR = (("x", "<f4", FLOAT32), ("y", "<f4", FLOAT32), ("z", "<f4", FLOAT32),
          ("intensity", "<f4", FLOAT32), ("ring", "<u2", UINT16), ("label", "u1", UINT8),
          ("rain", "u1", UINT8), ("instance", "<i4", INT32))  # fmt: skip
_RADAR = _LIDAR[:4]


Fields = list[dict[str, typing.Any]]


def point_type(layout: tuple[tuple[str, str, int], ...]) -> tuple[np.dtype, Fields]:
    """The packed NumPy dtype of a point layout and its PointField list."""
    dtype = np.dtype([(name, kind) for name, kind, _ in layout])
    offsets = np.cumsum([0] + [np.dtype(kind).itemsize for _, kind, _ in layout])  # packed
    fields = [
        {"name": name, "offset": int(offset), "datatype": code, "count": 1}
        for (name, _, code), offset in zip(layout, offsets, strict=False)
    ]
    return dtype, fields


LIDAR_POINT, LIDAR_FIELDS = point_type(_LIDAR)
RADAR_POINT, RADAR_FIELDS = point_type(_RADAR)


def converter(names: Names, sensor: MountedSensor) -> Convert:
    """The conversion of one sensor's samples; ValueError for a sample of another type."""
    kind = sensor.config.type
    build = {"imu": _imu, "gps": _gps, "lidar": _lidar, "radar": _radar, "camera": _camera}
    if kind not in build:
        raise ValueError(f"{sensor.seed_name}: no ROS 2 form for sensor type {kind!r}")
    return build[kind](names, sensor)


def _expect(msg: Message, cls: type[Message], sensor: MountedSensor) -> None:
    if not isinstance(msg, cls):
        raise ValueError(f"{sensor.seed_name}: a {type(msg).__name__}, not a {cls.__name__}")


def imu_covariances(sensor: MountedSensor) -> tuple[list[float], list[float], list[float]]:
    """orientation, angular velocity, linear acceleration float64[9] (row-major 3x3)."""
    p = sensor.params
    on = sensor.config.noise
    gyro = p.gyro_sigma**2 + p.gyro_bias_instability**2 if on else 0.0
    accel = p.accel_sigma**2 + p.accel_bias_instability**2 if on else 0.0
    return [0.0] * 9, _diagonal(gyro), _diagonal(accel)


def _diagonal(value: float) -> list[float]:
    return [value if i % 4 == 0 else 0.0 for i in range(9)]


def _imu(names: Names, sensor: MountedSensor) -> Convert:
    encode = imu_encoder(names.sensor_frame(sensor), imu_covariances(sensor))
    topic = names.sensor_topic(sensor, "imu")

    def convert(msg: Message, want: Want) -> list[Out]:
        _expect(msg, ImuSample, sensor)
        if not want(topic):
            return []
        m = typing.cast(ImuSample, msg)
        values = (*m.orientation, *m.angular_velocity, *m.linear_acceleration)
        return [Out(topic, types.IMU, encode(m.stamp_ns, values))]

    return convert


def _gps(names: Names, sensor: MountedSensor) -> Convert:
    encode = navsatfix_encoder(names.sensor_frame(sensor))
    topic = names.sensor_topic(sensor, "fix")

    def convert(msg: Message, want: Want) -> list[Out]:
        _expect(msg, GpsFix, sensor)
        if not want(topic):
            return []
        m = typing.cast(GpsFix, msg)
        values = (m.latitude, m.longitude, m.altitude, m.horizontal_sigma, m.vertical_sigma)
        return [Out(topic, types.NAVSATFIX, encode(m.stamp_ns, values))]

    return convert


def lidar_points(scan: LidarScan) -> np.ndarray:
    """The scan's returns as one structured array of LIDAR_POINT (no per-point Python)."""
    out = np.empty(len(scan.points), dtype=LIDAR_POINT)
    for i, axis in enumerate("xyz"):
        out[axis] = scan.points[:, i]
    out["intensity"], out["ring"] = scan.intensity, scan.ring
    out["label"], out["rain"], out["instance"] = scan.cls, scan.is_rain, scan.instance
    return out


def _lidar(names: Names, sensor: MountedSensor) -> Convert:
    encode = pointcloud2_encoder(names.sensor_frame(sensor), LIDAR_FIELDS, LIDAR_POINT.itemsize)
    topic = names.sensor_topic(sensor, "points")

    def convert(msg: Message, want: Want) -> list[Out]:
        _expect(msg, LidarScan, sensor)
        if not want(topic):
            return []
        scan = typing.cast(LidarScan, msg)
        cloud = lidar_points(scan)
        return [Out(topic, types.POINTCLOUD2, encode(cloud, len(cloud), scan.stamp_ns))]

    return convert


def beam_step(sensor: MountedSensor) -> float:
    """Radians between two radar beams (half a beam width, a whole number per turn)."""
    return 2 * math.pi / max(1, round(720.0 / sensor.params.beam_width_deg))


def radar_points(sweep: RadarSweep, step: float) -> np.ndarray:
    """One point per echo cell (beam, range bin) with a return, at the bin's middle, level in
    the radar frame (azimuth counter-clockwise from the bow), its echo strength 0-255."""
    beam, cell = np.nonzero(sweep.intensity)
    bins = sweep.intensity.shape[1] if sweep.intensity.ndim == 2 else 1
    r = (cell + 0.5) * (sweep.range_m / bins)
    azimuth = sweep.azimuth_start_rad - step * beam
    out = np.zeros(len(beam), dtype=RADAR_POINT)
    out["x"], out["y"] = r * np.cos(azimuth), r * np.sin(azimuth)
    out["intensity"] = sweep.intensity[beam, cell]
    return out


def _radar(names: Names, sensor: MountedSensor) -> Convert:
    frame, p = names.sensor_frame(sensor), sensor.params
    cloud = pointcloud2_encoder(frame, RADAR_FIELDS, RADAR_POINT.itemsize)
    image = image_encoder(frame, "mono8")
    points, ppi_topic = names.sensor_topic(sensor, "points"), names.sensor_topic(sensor, "ppi")
    step, period_ns = beam_step(sensor), sensor.config.period_ns
    ppi = Ppi(size_px=p.ppi_size_px, range_m=p.range_m, fade_s=p.fade, beam_step_rad=step)
    turn_ns = round(p.rotation_period_s * 1e9)

    def convert(msg: Message, want: Want) -> list[Out]:
        """Every sweep paints the PPI, wanted or not: it shows the last `fade_s` of them."""
        _expect(msg, RadarSweep, sensor)
        sweep = typing.cast(RadarSweep, msg)
        out = []
        if want(points):
            echoes = radar_points(sweep, step)
            out.append(Out(points, types.POINTCLOUD2, cloud(echoes, len(echoes), sweep.stamp_ns)))
        ppi.add(sweep)
        turn_ends = (sweep.stamp_ns + period_ns) // turn_ns > sweep.stamp_ns // turn_ns
        if turn_ends and want(ppi_topic):
            picture = image(ppi.render(sweep.stamp_ns), sweep.stamp_ns)
            out.append(Out(ppi_topic, types.IMAGE, picture))
        return out

    return convert


_AS_INT8 = np.arange(256, dtype=np.uint8).view(np.int8).astype(np.float64)
_NORMALS = np.rint((_AS_INT8 / 127.0 + 1.0) * 127.5).clip(0, 255).astype(np.uint8)
"""rgb8 of each int8 normal component, indexed by its byte: a table look-up a pixel."""


_TABLE = _NORMALS.tobytes()


def normals_rgb(normals: np.ndarray) -> np.ndarray:
    """int8 normals x 127 as rgb8 (n + 1) / 2, the dataset PNGs' mapping (`bytes.translate`
    is the table look-up: twice as fast as NumPy's, whose indices become int64 first)."""
    rgb = np.ascontiguousarray(normals).tobytes().translate(_TABLE)
    return np.frombuffer(rgb, np.uint8).reshape(normals.shape)


EMPTY = np.empty(0, np.uint8)
_PIXELS = {  # topic suffix -> the frame's array, with the encoding's dtype
    "image_raw": lambda f: f.color,
    "depth": lambda f: f.depth.astype("<f4", copy=False),
    "segmentation": lambda f: f.segmentation,
    "instance": lambda f: f.instance.astype("<u2", copy=False),
    "normals": lambda f: normals_rgb(f.normals),
}


def camera_matrix(sensor: MountedSensor) -> np.ndarray:
    """K (3 x 3) of a camera's pinhole from its field of view (square pixels, no
    distortion), with ROS's and OpenCV's pixel-centre convention: pixel u's centre at u
    (the camera's rays go through u + 0.5, services/sensors/camera.py)."""
    p = sensor.params
    f = (p.width / 2) / math.tan(math.radians(p.hfov_deg) / 2)
    return np.array([[f, 0.0, p.width / 2 - 0.5], [0.0, f, p.height / 2 - 0.5], [0, 0, 1.0]])


def camera_info(names: Names, sensor: MountedSensor) -> bytes:
    """sensor_msgs/CameraInfo of the pinhole at stamp 0: no distortion, K of `camera_matrix`."""
    p = sensor.params
    k = camera_matrix(sensor)
    info = types.new(
        types.CAMERA_INFO,
        header=types.header(0, names.optical_frame(sensor)),
        height=p.height, width=p.width, distortion_model="plumb_bob",
        d=np.zeros(5), k=k.ravel(), r=np.eye(3).ravel(),
        p=np.hstack([k, np.zeros((3, 1))]).ravel(), binning_x=0, binning_y=0,
        roi=types.new("sensor_msgs/msg/RegionOfInterest", x_offset=0, y_offset=0, height=0,
                      width=0, do_rectify=False),
    )  # fmt: skip
    return types.serialize(info, types.CAMERA_INFO)


def _camera(names: Names, sensor: MountedSensor) -> Convert:
    frame = names.optical_frame(sensor)
    images = [
        (names.sensor_topic(sensor, suffix), _PIXELS[suffix], image_encoder(frame, encoding))
        for suffix, encoding in camera_images(sensor)
    ]
    info = restamper(camera_info(names, sensor))
    info_topic = names.sensor_topic(sensor, "camera_info")

    def convert(msg: Message, want: Want) -> list[Out]:
        _expect(msg, CameraFrame, sensor)
        f = typing.cast(CameraFrame, msg)
        out = []
        for topic, pixels, encode in images:
            array = pixels(f) if want(topic) else EMPTY
            if array.size:  # an output the frame has (all do unless switched off)
                out.append(Out(topic, types.IMAGE, encode(array, f.stamp_ns)))
        if want(info_topic):
            out.append(Out(info_topic, types.CAMERA_INFO, info(f.stamp_ns)))
        return out

    return convert
