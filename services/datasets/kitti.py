"""LiDAR scans with per-point labels in the SemanticKITTI layout, from a run's `run.mcap`.

    OUT/sequences/<NN>/velodyne/<scan>.bin   float32 x, y, z, intensity per point (sensor frame)
    OUT/sequences/<NN>/labels/<scan>.label   uint32 per point: semantic class in the lower 16
                                             bits, instance (the body's World row + 1; 0
                                             none) in the upper 16, as SemanticKITTI
    OUT/sequences/<NN>/poses.txt             the sensor's pose in `map` at each scan (3 x 4,
                                             row-major), calib.txt `Tr` the identity, so
                                             SemanticKITTI's tools chain scans as they are
    OUT/sequences/<NN>/times.txt             simulated seconds of each scan
    OUT/catabot.yaml                         semantic-kitti.yaml's keys (names, colours,
                                             learning_map, content, split), sequence -> LiDAR

One sequence per LiDAR (`<vessel>.<lidar>`, in scenario order), one file pair per scan, one
label per point. The rain flag is a class of its own, 5 `rain` (a raindrop return has no
surface class and no instance): a de-raining network learns it like any class, the way the
WADS snow dataset labels falling snow, and `label & 0xFFFF == 5` selects the rain points.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import LABEL_CLASSES, LidarScan
from catabot.config.sensors import LidarParams
from catabot.run.recorded import RecordedRun, StateTrack
from catabot.world import rotations
from catabot.world.label_colors import CLASS_COLORS, RAIN_COLOR
from catabot.world.world import MountedSensor
from services.datasets.frames import ExportError, ExportOptions

KITTI_CLASSES = (*LABEL_CLASSES, "rain")
RAIN = KITTI_CLASSES.index("rain")
COLORS = {name: rgb[::-1] for name, rgb in (CLASS_COLORS | {"rain": RAIN_COLOR}).items()}
"""BGR, as semantic-kitti.yaml writes them."""


def point_labels(scan: LidarScan) -> NDArray[np.uint32]:
    """SemanticKITTI labels of a scan's points: rain returns class `rain`, instance 0."""
    semantic = np.where(scan.is_rain, RAIN, scan.cls.astype(np.uint32)).astype(np.uint32)
    instance = np.where(scan.is_rain, 0, scan.instance).astype(np.uint32)
    if (instance > 0xFFFF).any():
        raise ExportError(f"scan at tick {scan.tick}: an instance id beyond 16 bits")
    return semantic | (instance << np.uint32(16))


def sensor_pose(states: StateTrack, row: int, stamp_ns: int, start: NDArray[np.float64],
                params: LidarParams) -> NDArray[np.float64]:  # fmt: skip
    """The LiDAR's 3 x 4 pose in `map` when it scanned: the carrier's state stamped at the
    scan (the one the sensors used, DESIGN.md §8), its start pose at tick 0, then the mount."""
    found = np.flatnonzero(states.stamp_ns == stamp_ns)
    pose = start if not len(found) else np.concatenate(
        [states.position[found[0], row], states.orientation[found[0], row]])  # fmt: skip
    body = rotations.matrix(pose[3:])
    if body is None:
        raise ExportError(f"no finite pose of the LiDAR carrier at {stamp_ns} ns")
    mount = rotations.rpy(0.0, params.mount_pitch_deg, params.mount_yaw_deg)
    origin = pose[:3] + body @ np.asarray(params.mount_xyz)
    return np.concatenate([body @ mount, origin[:, None]], axis=1)


def _sequence(
    run: RecordedRun, sensor: MountedSensor, folder: Path, states: StateTrack
) -> tuple[int, NDArray[np.int64]]:
    """Writes one LiDAR's scans; returns how many, and its points per class."""
    (folder / "velodyne").mkdir(parents=True, exist_ok=True)
    (folder / "labels").mkdir(parents=True, exist_ok=True)
    body = run.world.body(sensor.vessel)
    start = run.world.start_states()
    start_pose = np.concatenate([start.position[body.row], start.orientation[body.row]])
    poses, times, classes = [], [], np.zeros(len(KITTI_CLASSES), np.int64)
    for n, scan in enumerate(run.lidar_scans(sensor)):
        cloud = np.concatenate([scan.points, scan.intensity[:, None]], axis=1)
        cloud.astype("<f4").tofile(folder / "velodyne" / f"{n:06d}.bin")
        labels = point_labels(scan)
        labels.astype("<u4").tofile(folder / "labels" / f"{n:06d}.label")
        classes += np.bincount(labels & 0xFFFF, minlength=len(KITTI_CLASSES))
        pose = sensor_pose(states, body.row, scan.stamp_ns, start_pose, sensor.params)
        poses.append(" ".join(f"{v:.9e}" for v in pose.ravel()) + "\n")
        times.append(f"{scan.stamp_ns / 1e9:.9e}\n")
    (folder / "poses.txt").write_text("".join(poses))
    (folder / "times.txt").write_text("".join(times))
    (folder / "calib.txt").write_text("Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n")
    return len(times), classes


def labels_yaml(sequences: dict[str, str], points: NDArray[np.int64]) -> str:
    """semantic-kitti.yaml's keys, which SemanticKITTI's tools and the networks trained on
    it read: names, colours, each class's share of the points (`content`, for class
    weights), the training classes (the same ids; 0 `none` ignored) and a split (every
    sequence for training: move some to valid and test)."""
    ids = range(len(KITTI_CLASSES))
    share = points / max(int(points.sum()), 1)
    same = "".join(f"  {i}: {i}\n" for i in ids)
    seqs = [int(seq) for seq in sequences]
    return "".join([
        _block("labels", KITTI_CLASSES),
        _block("color_map", [f"[{', '.join(map(str, COLORS[n]))}]" for n in KITTI_CLASSES]),
        _block("content", [f"{v:.9f}" for v in share]),
        f"learning_map:\n{same}learning_map_inv:\n{same}",
        _block("learning_ignore", ["true" if i == 0 else "false" for i in ids]),
        f"split:\n  train: {seqs}\n  valid: []\n  test: []\n",
        "sequences:\n", *(f"  '{seq}': {lidar}\n" for seq, lidar in sequences.items()),
    ])  # fmt: skip


def _block(key: str, values: Sequence[str]) -> str:
    return f"{key}:\n" + "".join(f"  {i}: {v}\n" for i, v in enumerate(values))


def export(run: RecordedRun, out: Path, _options: ExportOptions) -> str:
    lidars = [s for s in run.world.sensors if s.config.type == "lidar"]
    if not lidars:
        raise ExportError(f"{run.folder}: the scenario has no LiDAR (kitti exports LiDAR scans)")
    states = run.states()
    sequences, counts, points = {}, [], np.zeros(len(KITTI_CLASSES), np.int64)
    for i, sensor in enumerate(lidars):
        seq = f"{i:02d}"
        sequences[seq] = f"{sensor.vessel}.{sensor.config.name}"
        scans, classes = _sequence(run, sensor, out / "sequences" / seq, states)
        counts.append(scans)
        points += classes
    if not sum(counts):
        raise ExportError(f"{run.folder}: run.mcap holds no LiDAR scan")
    (out / "catabot.yaml").write_text(labels_yaml(sequences, points))
    return ", ".join(
        f"sequence {s} ({n}): {c} scans"
        for (s, n), c in zip(sequences.items(), counts, strict=True)
    )
