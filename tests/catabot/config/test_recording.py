"""recording: run.rrd, the exports and the dataset rate are checked before anything starts."""

from __future__ import annotations

import re
from typing import Any

import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import parse_scenario

CAMERA = {"name": "cam", "type": "camera", "rate_hz": 10.0}
LIDAR = {"name": "lidar", "type": "lidar", "rate_hz": 10.0}


def _scenario(recording: dict[str, Any], *sensors: dict[str, Any]) -> dict[str, Any]:
    return {"vessels": [{"id": "ego", "sensors": list(sensors)}], "recording": recording}


def test_defaults_make_no_rrd_and_no_export() -> None:
    rec = parse_scenario(_scenario({})).recording
    assert (rec.rerun, rec.export, rec.dataset_rate_hz) == (False, [], None)
    assert rec.mcap_compression == "zstd"


def test_everything_asked_for_with_its_sources() -> None:
    rec = {"rerun": True, "export": ["yolo", "coco", "kitti"], "dataset_rate_hz": 2.0}
    parsed = parse_scenario(_scenario(rec, CAMERA, LIDAR)).recording
    assert parsed.export == ["yolo", "coco", "kitti"] and parsed.dataset_rate_hz == 2.0
    camera_only = {"mcap": False, "export": ["yolo", "coco", "segmentation"]}  # from dataset/
    assert parse_scenario(_scenario(camera_only, CAMERA)).recording.export[0] == "yolo"


@pytest.mark.parametrize(
    ("recording", "sensors", "message"),
    [
        ({"rerun": True, "mcap": False}, [], "recording.rerun: needs recording.mcap: true"),
        ({"export": ["kitti"], "mcap": False}, [LIDAR], "recording.export: needs recording.mcap"),
        ({"export": ["yolo"]}, [LIDAR], "recording.export: 'yolo' needs a camera"),
        ({"export": ["kitti"]}, [CAMERA], "recording.export: 'kitti' needs a lidar"),
        ({"export": ["coco"], "dataset": False}, [CAMERA], "'coco' needs recording.dataset: true"),
        ({"export": ["voc"]}, [CAMERA], "recording.export.0: must be one of 'yolo', 'coco'"),
        (
            {"export": ["coco"]},
            [CAMERA, {**CAMERA, "name": "c2", "params": {"outputs": {"segmentation": False}}}],
            "'coco' is made from each camera's color and segmentation: vessels.0.sensors.1 (c2) "
            "has segmentation off",
        ),  # it was found as the run ended: a whole run lost, its export half written
        (
            {"export": ["yolo"]},
            [{**CAMERA, "params": {"outputs": {"color": False, "depth": True}}}],
            "'yolo' is made from each camera's color: vessels.0.sensors.0 (cam) has color off",
        ),
        (
            {"mcap_compression": "gzip"},
            [],
            "recording.mcap_compression: must be one of 'zstd', 'lz4' or 'none' (got 'gzip')",
        ),
        ({"dataset_rate_hz": 3.0}, [CAMERA], "recording.dataset_rate_hz: period 333333333 ns"),
        ({"dataset_rate_hz": 0}, [CAMERA], "recording.dataset_rate_hz: must be > 0"),
        (  # kept 0.4 and 0.2 s apart in turn: a camera at 5 Hz, a dataset at 4
            {"dataset_rate_hz": 4.0},
            [{**CAMERA, "rate_hz": 5.0}],
            "recording.dataset_rate_hz: 4 Hz is not ego/cam's 5 Hz divided by a whole number: "
            "the dataset keeps whole camera frames, evenly spaced; rates that fit: 5, 2.5, "
            "1.667, 1.25 Hz, ...",
        ),
        (  # kept 5 Hz, unsaid
            {"dataset_rate_hz": 10.0},
            [{**CAMERA, "rate_hz": 5.0}, {**CAMERA, "name": "c2", "rate_hz": 2.0}],
            "10 Hz is not ego/cam's 5 Hz or ego/c2's 2 Hz divided by a whole number: "
            "the dataset keeps whole camera frames, evenly spaced; rates that fit: 1, 0.5,",
        ),
        ({"rerun": "yes"}, [], "recording.rerun: must be true or false"),
    ],
)
def test_refused_with_the_field_named(
    recording: dict[str, Any], sensors: list[dict[str, Any]], message: str
) -> None:
    with pytest.raises(ScenarioError, match=re.escape(message)):
        parse_scenario(_scenario(recording, *sensors))
