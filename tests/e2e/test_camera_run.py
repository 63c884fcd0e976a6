"""Cameras and radar through `catabot run`: the labelled dataset, PPI images, MCAP channels."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from conftest import basic_scenario, catabot, csv_rows, only_run_dir, scenario_file

from catabot.config.load import load_scenario
from catabot.world.world import World
from services.recorder.mcap_read import read_mcap_messages


def _scenario() -> dict[str, Any]:
    """Ego with a small camera (all outputs, 2 Hz) and a fast-turning radar; a boat ahead."""
    data = basic_scenario("cameras", duration_s=1.0)
    data["vessels"][0]["sensors"] = [
        {"name": "cam", "type": "camera", "rate_hz": 2.0, "params": {"width": 160, "height": 120}},
        {"name": "radar", "type": "radar", "rate_hz": 20.0, "params": {"rotation_period_s": 0.5}},
    ]
    data["vessels"].append({"id": "other", "pose": {"x_m": 30.0, "y_m": 0.0}})
    data["vessels"][0]["pose"] = {"x_m": 0.0, "y_m": 0.0}
    data["rain"] = {"rate_mm_h": 10.0}
    return data


def _files(run: Path) -> dict[str, bytes]:
    paths = [*sorted(p for p in (run / "dataset").rglob("*") if p.is_file()), *run.glob("*.mcap")]
    return {str(p.relative_to(run)): p.read_bytes() for p in paths}


def test_camera_and_radar_run_writes_dataset_and_mcap(tmp_path: Path, out: Path) -> None:
    data = _scenario()
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    run = only_run_dir(out)
    cam = run / "dataset" / "ego.cam"
    lines = [json.loads(line) for line in (cam / "labels.jsonl").read_text().splitlines()]
    assert [line["tick"] for line in lines] == [0, 50]
    for name in ("color", "depth", "normals", "class", "instance"):
        assert (cam / lines[0]["files"][name]).is_file()
    assert any(o["class"] == "vessel" for line in lines for o in line["objects"])
    world = World.resolve(load_scenario(run / "scenario.json"))  # each object names its body
    rows = {b.id: b.row for b in world.bodies}
    assert all(rows[o["body"]] + 1 == o["instance"] for line in lines for o in line["objects"])
    assert sorted(p.name for p in (run / "dataset" / "ego.radar").glob("ppi_*.png"))
    topics = {m.topic: m.schema_name for m in read_mcap_messages(run / "run.mcap")}
    for output in ("image_raw", "depth", "segmentation", "instance", "normals", "camera_info"):
        assert topics[f"/ego/cam/{output}"].startswith("sensor_msgs/msg/")
    assert topics["/ego/radar/points"] == "sensor_msgs/msg/PointCloud2"
    assert topics["/ego/radar/ppi"] == "sensor_msgs/msg/Image"
    extra = read_mcap_messages(run / "run.extra.mcap")
    assert [m.decoded["tick"] for m in extra if m.topic == "/ego/cam/labels"] == [0, 50]
    header, *rows = csv_rows(run / "sensor.ego.cam.csv")
    assert header[:2] == ["stamp_ns", "tick"] and "objects" in header and len(rows) == 2


def test_same_seed_gives_the_same_dataset_bytes(tmp_path: Path) -> None:
    runs = []
    for name in ("a", "b"):
        out = tmp_path / name
        out.mkdir()
        result = catabot(
            "run", str(scenario_file(tmp_path, _scenario())), "--out", str(out), "--quiet"
        )
        assert result.returncode == 0, result.stderr
        runs.append(_files(only_run_dir(out)))
    assert runs[0].keys() == runs[1].keys() and len(runs[0]) > 10
    assert all(runs[0][k] == runs[1][k] for k in runs[0]), "a file differs between runs"
