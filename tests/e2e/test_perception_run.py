"""The bundled `perception` scenario through `catabot run`: every ray-cast sensor in one
scene (camera with its four outputs, LiDAR in rain, radar), traffic and buoys in view, and a
labelled dataset, from its name alone."""

from __future__ import annotations

import json
from pathlib import Path

from conftest import catabot, csv_rows, only_run_dir


def test_perception_runs_by_name_and_labels_what_it_sees(tmp_path: Path) -> None:
    out = tmp_path / "runs"
    result = catabot("run", "perception", "--duration", "1", "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stdout + result.stderr
    run = only_run_dir(out)
    frames = [json.loads(x) for x in (run / "dataset/ego.camera/labels.jsonl").read_text().split()]
    assert len(frames) == 5  # 5 Hz over 1 s, from t = 0
    assert set(frames[0]["files"]) == {"color", "depth", "normals", "class", "instance", "depth_m"}
    seen = {o["class"] for f in frames for o in f["objects"]}
    assert seen == {"vessel", "buoy"}
    lidar = csv_rows(run / "sensor.ego.lidar.csv")
    assert lidar[0] == ["stamp_ns", "tick", "returns", "rain_returns"] and len(lidar) == 11
    assert all(int(r[2]) > 1000 and int(r[3]) > 0 for r in lidar[1:])  # shore, boats and rain
    assert len(csv_rows(run / "sensor.ego.radar.csv")) == 11
