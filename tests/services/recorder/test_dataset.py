"""dataset/: frames at the configured rate, depth also as exact float32 .npy, same bytes twice."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from catabot.bus.messages import CameraFrame
from catabot.config.load import parse_scenario
from catabot.world.world import World
from services.recorder.dataset import Dataset


def _world(rate_hz: float | None) -> World:
    camera = {"name": "cam", "type": "camera", "rate_hz": 10.0, "params": {"width": 4, "height": 3}}
    return World.resolve(parse_scenario({
        "vessels": [{"id": "ego", "sensors": [camera]}],
        "recording": {"dataset_rate_hz": rate_hz},
    }))  # fmt: skip


def _frame(tick: int) -> CameraFrame:
    depth = np.full((3, 4), 12.3456, np.float32)
    depth[0, 0] = np.inf
    return CameraFrame(
        tick=tick, stamp_ns=tick * 10_000_000, width=4, height=3, hfov_rad=1.0, objects=1,
        color=np.zeros((3, 4, 3), np.uint8), depth=depth, normals=np.zeros((3, 4, 3), np.int8),
        segmentation=np.full((3, 4), 3, np.uint8), instance=np.ones((3, 4), np.uint16),
        boxes=np.array([[1, 3, 0, 0, 4, 3]], np.float32),
        box_flags=np.array([[0, 1, 40]], np.uint8),
    )  # fmt: skip


def _record(root: Path, rate_hz: float | None) -> list[dict[str, object]]:
    dataset = Dataset(root, _world(rate_hz))
    for tick in range(0, 110, 10):  # the camera's frames, every 10 ticks
        dataset.write("sensor/ego/cam", _frame(tick))
    lines = (root / "ego.cam" / "labels.jsonl").read_text().splitlines()
    return [json.loads(line) for line in lines]


def test_every_frame_without_a_rate(tmp_path: Path) -> None:
    assert [r["tick"] for r in _record(tmp_path, None)] == list(range(0, 110, 10))


def test_one_frame_in_every_n(tmp_path: Path) -> None:
    # 2.5 Hz: one of every 4 of the camera's frames, which are 10 ticks apart.
    assert [r["tick"] for r in _record(tmp_path, 2.5)] == [0, 40, 80]


def test_depth_as_exact_float32_beside_the_png(tmp_path: Path) -> None:
    record = _record(tmp_path, 5.0)[1]
    files = record["files"]
    assert isinstance(files, dict) and files["depth_m"] == "00000020_depth.npy"
    depth = np.load(tmp_path / "ego.cam" / files["depth_m"])
    assert (
        depth.dtype == np.float32 and np.isinf(depth[0, 0]) and depth[1, 1] == np.float32(12.3456)
    )
    again = tmp_path / "again"
    _record(again, 5.0)
    for name in ("00000020_depth.npy", "00000020_depth.png", "labels.jsonl"):
        assert (tmp_path / "ego.cam" / name).read_bytes() == (again / "ego.cam" / name).read_bytes()


def test_each_object_says_how_much_of_it_is_seen(tmp_path: Path) -> None:
    (first, *_) = _record(tmp_path, None)
    assert first["objects"][0] | {"box": None} == {
        "instance": 1, "body": "ego", "class": "vessel", "box": None,
        "truncated": False, "occluded": True, "visible": 0.4,
    }  # fmt: skip


def test_a_radar_only_dataset_says_where_its_radar_sits(tmp_path: Path) -> None:
    """dataset/ held the PPIs, but calibration.json only came with a camera: the radar's
    mount was in /tf_static alone."""
    radar = {"name": "radar", "type": "radar", "rate_hz": 10.0}
    world = World.resolve(parse_scenario({"vessels": [{"id": "ego", "sensors": [radar]}]}))
    Dataset(tmp_path, world)
    sensors = json.loads((tmp_path / "calibration.json").read_text())["sensors"]
    assert list(sensors) == ["ego.radar"] and "body_from_sensor" in sensors["ego.radar"]
    assert "heading only" in sensors["ego.radar"]["stabilised"]


def test_a_lidar_only_dataset_says_where_its_lidar_sits(tmp_path: Path) -> None:
    """`recording.dataset` with a LiDAR alone wrote no dataset/ at all: a KITTI user had no
    calibration.json to place the scans on the vessel."""
    lidar = {"name": "lidar", "type": "lidar", "rate_hz": 10.0}
    data = {"vessels": [{"id": "ego", "sensors": [lidar]}], "recording": {"dataset": True}}
    Dataset(tmp_path, World.resolve(parse_scenario(data)))
    sensors = json.loads((tmp_path / "calibration.json").read_text())["sensors"]
    assert list(sensors) == ["ego.lidar"] and "body_from_sensor" in sensors["ego.lidar"]
    off = {**data, "recording": {"dataset": False}}
    Dataset(tmp_path / "off", World.resolve(parse_scenario(off)))
    imu = {"name": "imu", "type": "imu", "rate_hz": 10.0}  # no dataset of an IMU alone
    Dataset(
        tmp_path / "imu",
        World.resolve(parse_scenario({"vessels": [{"id": "a", "sensors": [imu]}]})),
    )
    assert not (tmp_path / "off").exists() and not (tmp_path / "imu").exists()
