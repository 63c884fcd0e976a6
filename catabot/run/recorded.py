"""A recorded run read back as what was on the bus: the one reader of run folders.

The viewer's replay, `run.rrd`, the dataset export and the plots all read a finished run
folder through this module, so the mapping from the recorder's files back to bus messages
(DESIGN.md §7: which MCAP channel holds which stream, in which encoding) is written once.
Sources: `scenario.json` (resolved into the same `World` the run had), `run.mcap` (a ROS 2
bag with the gateway's topics, catabot/ros2/names.py: body poses from `/tf`, vessel twists
from each `odom`, LiDAR `points`, camera `image_raw` and `depth`, IMU `imu`, commands
`thrust` and `cmd_vel`), `run.extra.mcap` (JSON of what has no ROS 2 form: the radar's polar
sweeps) and `dataset/` (camera labels: `recorded_camera.py`).
"""

from __future__ import annotations

import base64
import json
import logging
from collections.abc import Iterator
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
from mcap.records import Schema
from mcap_ros2.decoder import DecoderFactory
from numpy.typing import NDArray

from catabot.bus.fields import FieldSpec, fields_of
from catabot.bus.messages import BodyStates, ImuSample, LidarScan, Message, ThrustCmd, TwistCmd
from catabot.config.load import load_scenario
from catabot.config.ros import RosConfig
from catabot.errors import CataBotError
from catabot.ros2.names import TF, Names
from catabot.run import cdr_columns, recorded_poses
from catabot.run.ending import end_reason, run_record
from catabot.run.mcap_index import Channel, McapIndex
from catabot.world.world import MountedSensor, World

log = logging.getLogger("catabot.recorded")
M = TypeVar("M", bound=Message)
IMAGE_TOPICS = {"color": "image_raw"}  # a camera output -> its topic, where they differ
_POINT_TYPES = {1: "i1", 2: "u1", 3: "<i2", 4: "<u2", 5: "<i4", 6: "<u4", 7: "<f4", 8: "<f8"}


class RunFolderError(CataBotError, ValueError):
    """A folder that is not a (complete enough) run folder for what was asked of it."""


@dataclass(frozen=True)
class StateTrack:
    """Every body's pose at every recorded tick, and each vessel's body-frame twist.

    `position` (T, N, 3) and `orientation` (T, N, 4) come from `/tf` (every body, buoys
    included; traffic and buoys, recorded at `recording.traffic_rate_hz`, are interpolated
    between their samples: `sampled` (T, N) marks the recorded ones, recorded_poses.py);
    `twist` (T, N, 6) linear + angular from each vessel's Odometry, NaN for buoys (no
    Odometry is recorded for them) and where none was recorded. Accelerations are not in the
    MCAP (the CSVs have them).
    """

    ids: tuple[str, ...]
    stamp_ns: NDArray[np.int64]
    position: NDArray[np.float64]
    orientation: NDArray[np.float64]
    twist: NDArray[np.float64]
    sampled: NDArray[np.bool_]

    def __len__(self) -> int:
        return len(self.stamp_ns)

    def batch(self, i: int, dt_ns: int) -> BodyStates:
        """Tick i as the `BodyStates` it was recorded from (accelerations NaN: not recorded)."""
        nan = np.full((len(self.ids), 3), np.nan)
        stamp = int(self.stamp_ns[i])
        twist = self.twist[i]
        return BodyStates(
            stamp // dt_ns - 1, stamp, self.ids, self.position[i], self.orientation[i],
            twist[:, :3], twist[:, 3:], nan, nan,
        )  # fmt: skip


def _check_ticked(folder: Path) -> None:
    """A run stopped before its first tick recorded nothing: say so, not that its run.mcap
    is cut off and has no /tf channel (`log/run.json`; a killed run's folder has none)."""
    try:
        record = run_record(folder) or {}
        ticks, reason = int(record["ticks"]), str(record["reason"])
    except (ValueError, TypeError, KeyError):
        return
    if ticks == 0:
        how = {"fault": "ended by a fault", "interrupted": "was interrupted"}.get(reason, reason)
        raise RunFolderError(f"{folder}: the run recorded no tick (it {how} before its first; "
                             "log/run.json says why)")  # fmt: skip


class RecordedRun:
    """One run folder: its world, and its streams read back on demand."""

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder)
        if not self.folder.is_dir():
            what = "a file, not a run folder" if self.folder.exists() else "no such run folder"
            raise RunFolderError(f"{self.folder}: {what}")
        scenario = self.folder / "scenario.json"
        if not scenario.is_file():
            raise RunFolderError(f"{self.folder}: not a run folder (it has no scenario.json)")
        _check_ticked(self.folder)
        self.world = World.resolve(load_scenario(scenario))
        self.names = Names(self.world, self.world.scenario.ros or RosConfig())  # the recorder's
        self._ros2 = DecoderFactory()

    @property
    def dt_ns(self) -> int:
        return self.world.scenario.dt_ns

    @cached_property
    def mcap(self) -> McapIndex:
        path = self.folder / "run.mcap"
        if not path.is_file():
            raise RunFolderError(
                f"{self.folder}: no run.mcap (recorded with recording.mcap false?); "
                "replay, plots and the KITTI export read it"
            )
        index = McapIndex(path)
        if not index.finished:  # what is there is read, and the reader is told so
            count = sum(len(c) for c in index.channels.values())
            log.warning("%s: no end yet (the run is still going, or was killed, or the file "
                        "was cut short); read to its last whole record, %d messages", path,
                        count)  # fmt: skip
        return index

    @cached_property
    def extra(self) -> McapIndex | None:
        path = self.folder / "run.extra.mcap"
        return McapIndex(path) if path.is_file() else None

    def topic(self, topic: str) -> Channel | None:
        """A channel of run.mcap by its ROS 2 topic (`self.names` spells them)."""
        return self.mcap.channel(topic)

    def stream(self, sensor: MountedSensor) -> str:
        return self.world.keys.relative(sensor.key)

    def metrics(self) -> dict[str, Any] | None:
        path = self.folder / "metrics.json"
        return json.loads(path.read_text()) if path.is_file() else None

    def end_reason(self) -> str:
        return end_reason(run_record(self.folder), self.metrics())

    def ended(self) -> str:
        """How the run ended, for a tool's report: a tool that read an interrupted run as a
        whole one said nothing of it."""
        reason, planned = self.end_reason(), self.world.scenario.duration_s
        return "completed" if reason == "completed" else f"{reason}, of {planned:g} s planned"

    def states(self) -> StateTrack:
        """Every body's recorded state (see `StateTrack`)."""
        tf = self.mcap.channel(TF)
        if tf is None or len(tf.stamps) == 0:
            raise RunFolderError(f"{self.folder}: run.mcap has no readable /tf channel")
        ids = self.world.body_ids
        frames = [self.names.base_link(b) for b in ids]
        try:
            poses = recorded_poses.track(self.mcap.rows_by_length(tf), frames, len(tf.stamps))
        except ValueError as exc:
            raise RunFolderError(f"{self.folder}: {exc}") from None
        pose = poses.pose
        stamps = np.asarray(tf.stamps, dtype=np.int64)
        twist = np.full((len(stamps), len(ids), 6), np.nan)
        for row, body in enumerate(self.world.vessels):
            self._fill_twist(twist[:, row], stamps, body.id)
        return StateTrack(ids, stamps, pose[..., :3], pose[..., 3:], twist, poses.sampled)

    def _fill_twist(self, out: NDArray[np.float64], stamps: NDArray[np.int64], vid: str) -> None:
        chan = self.topic(self.names.odom(vid))
        rows = self.mcap.rows(chan) if chan is not None else None
        if chan is None or rows is None:
            return
        own = np.asarray(chan.stamps, dtype=np.int64)
        at = np.searchsorted(stamps, own)
        found = (at < len(stamps)) & (stamps[np.minimum(at, len(stamps) - 1)] == own)
        out[at[found]] = cdr_columns.odometry(rows, what=chan.topic).twist[found]

    def messages(self, stream: str, cls: type[M]) -> Iterator[M]:
        """The samples of a stream with no ROS 2 form (a radar's sweeps), from
        run.extra.mcap's JSON (topic `/<stream>`), as `cls`."""
        chan = self.extra.channel("/" + stream.strip("/")) if self.extra else None
        for i in range(len(chan) if chan is not None else 0):
            assert chan is not None and self.extra is not None
            yield from_json(cls, json.loads(self.extra.payload(chan, i)))

    def thrust(self, vessel: str) -> Iterator[tuple[int, ThrustCmd]]:
        """(stamp_ns, command) of every thrust command the vessel was given (`thrust`)."""
        for stamp, m in self.decoded(self.names.topic(vessel, "thrust")):
            yield stamp, ThrustCmd(tuple(float(v) for v in m.data))

    def twist(self, vessel: str) -> Iterator[tuple[int, TwistCmd]]:
        """(stamp_ns, set-point) of every twist the vessel was given (`cmd_vel`): scripted,
        sent from outside or by the traffic service."""
        for stamp, m in self.decoded(self.names.topic(vessel, "cmd_vel")):
            yield stamp, TwistCmd(float(m.linear.x), float(m.angular.z))

    def imu(self, sensor: MountedSensor) -> Iterator[ImuSample]:
        """Every sample of an IMU from its sensor_msgs/Imu (`<sensor>/imu`)."""
        for stamp, m in self.decoded(self.names.sensor_topic(sensor, "imu")):
            q, w, a = m.orientation, m.angular_velocity, m.linear_acceleration
            yield ImuSample(stamp // self.dt_ns, stamp, (q.x, q.y, q.z, q.w), (w.x, w.y, w.z),
                            (a.x, a.y, a.z))  # fmt: skip

    def decoded(self, topic: str) -> Iterator[tuple[int, Any]]:
        """(stamp_ns, message) of every message on a topic of run.mcap; none if absent."""
        chan = self.topic(topic)
        for i in range(len(chan) if chan is not None else 0):
            assert chan is not None
            yield chan.stamps[i], self.ros2(chan, i)

    def ros2(self, chan: Channel, i: int) -> Any:
        """Message i of a CDR channel, decoded by mcap_ros2 (PointCloud2, Image)."""
        schema = Schema(
            id=chan.id, name=chan.schema_name, encoding=chan.schema_encoding, data=chan.schema_data
        )
        decoder = self._ros2.decoder_for(chan.encoding, schema)
        if decoder is None:
            raise RunFolderError(f"{chan.topic}: no decoder for {chan.schema_name!r}")
        return decoder(self.mcap.payload(chan, i))

    def lidar_scans(self, sensor: MountedSensor) -> Iterator[LidarScan]:
        """Every scan of a LiDAR, labels included (no range image: the MCAP has returns)."""
        for stamp, cloud in self.decoded(self.names.sensor_topic(sensor, "points")):
            yield scan_of(cloud, stamp, self.dt_ns)

    def images(self, sensor: MountedSensor, output: str) -> Iterator[tuple[int, np.ndarray]]:
        """(stamp_ns, pixels) of one camera output in the MCAP (`color` rgb8 from `image_raw`,
        `depth` 32FC1, ...)."""
        topic = self.names.sensor_topic(sensor, IMAGE_TOPICS.get(output, output))
        for stamp, msg in self.decoded(topic):
            yield stamp, image_of(msg)


def scan_of(cloud: Any, stamp_ns: int, dt_ns: int) -> LidarScan:
    """A PointCloud2 of the recorder's layout (convert_sensors.py) as the LidarScan it came from;
    fields are found by name, so their order and offsets may change."""
    kinds = {f.name: (f.offset, _POINT_TYPES[f.datatype]) for f in cloud.fields}
    missing = {"x", "y", "z", "intensity", "label", "rain", "instance"} - set(kinds)
    if missing:
        raise RunFolderError(f"point cloud without field(s) {sorted(missing)}")
    names = list(kinds)
    dtype = np.dtype(
        {"names": names, "formats": [kinds[n][1] for n in names],
         "offsets": [kinds[n][0] for n in names], "itemsize": cloud.point_step}
    )  # fmt: skip
    pts = np.frombuffer(bytes(cloud.data), dtype=dtype, count=cloud.width * cloud.height)
    ring = pts["ring"].astype(np.uint16) if "ring" in kinds else np.zeros(len(pts), np.uint16)
    return LidarScan(
        tick=stamp_ns // dt_ns,
        stamp_ns=stamp_ns,
        points=np.stack([pts["x"], pts["y"], pts["z"]], axis=1).astype(np.float32),
        intensity=pts["intensity"].astype(np.float32),
        ring=ring,
        cls=pts["label"].astype(np.uint8),
        instance=pts["instance"].astype(np.int32),
        is_rain=pts["rain"].astype(bool),
        range_image=np.empty((0, 0), np.float32),
    )


def image_of(msg: Any) -> np.ndarray:
    """A sensor_msgs/Image (rgb8, mono8, 32FC1, 16UC1) as a NumPy array."""
    kinds = {"rgb8": ("u1", 3), "mono8": ("u1", 1), "32FC1": ("<f4", 1), "16UC1": ("<u2", 1)}
    if msg.encoding not in kinds:
        raise RunFolderError(f"image encoding {msg.encoding!r} not read (known: {list(kinds)})")
    dtype, channels = kinds[msg.encoding]
    width = msg.width * channels
    rows = np.frombuffer(bytes(msg.data), dtype=np.uint8).reshape(msg.height, msg.step)
    pixels = rows[:, : width * np.dtype(dtype).itemsize].copy().view(dtype)
    return pixels.reshape(msg.height, msg.width, channels) if channels > 1 else pixels


def from_json(cls: type[M], record: dict[str, Any]) -> M:
    """A message from the recorder's JSON (json_schemas.py): null floats are NaN, arrays
    `{dtype, shape, data}` in base64."""
    values = {f.name: _value(f, record.get(f.name)) for f in fields_of(cls) if f.name in record}
    try:
        return cls(**values)
    except TypeError as exc:
        raise RunFolderError(f"a recorded {cls.__name__} lacks fields: {exc}") from None


def _value(spec: FieldSpec, value: Any) -> Any:
    if spec.kind == "array":
        data = base64.b64decode(value["data"])
        return np.frombuffer(data, dtype=np.dtype(value["dtype"])).reshape(value["shape"])
    if spec.kind == "vector":
        return tuple(np.nan if v is None else float(v) for v in value)
    if spec.kind == "names":
        return tuple(value)
    if spec.kind == "float":
        return np.nan if value is None else float(value)
    return value
