"""A LiDAR in the rain through `catabot run`: PointCloud2 in the MCAP, a summary CSV, buoys."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from conftest import basic_scenario, catabot, csv_rows, only_run_dir, scenario_file

from catabot.run.recorded import RecordedRun
from services.recorder.mcap_read import read_mcap_messages


def test_lidar_in_rain_is_recorded_as_point_clouds(tmp_path: Path, out: Path) -> None:
    data = basic_scenario("lidar", duration_s=1.0, rain={"rate_mm_h": 25.0})
    data["buoys"] = [{"id": "b1", "x_m": 8.0, "y_m": 0.0}]
    data["vessels"][0]["sensors"] = [{"name": "lidar", "type": "lidar", "rate_hz": 10.0}]
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    run = only_run_dir(out)
    messages = read_mcap_messages(run / "run.mcap")
    clouds = [m for m in messages if m.topic == "/ego/lidar/points"]
    assert len(clouds) == 10
    assert {m.schema_name for m in clouds} == {"sensor_msgs/msg/PointCloud2"}
    cloud = clouds[0].decoded
    assert cloud.header.frame_id == "ego/lidar" and cloud.point_step == 24
    assert [f.name for f in cloud.fields][:4] == ["x", "y", "z", "intensity"]
    assert cloud.width > 1000 and len(cloud.data) == cloud.width * 24
    labels = np.frombuffer(bytes(cloud.data), dtype=np.uint8).reshape(-1, 24)[:, 18]
    assert 4 in set(labels.tolist())  # the buoy is seen, with its class
    rows = csv_rows(run / "sensor.ego.lidar.csv")
    assert rows[0] == ["stamp_ns", "tick", "returns", "rain_returns"]
    assert len(rows) == 11 and all(int(r[2]) > 1000 for r in rows[1:])
    assert sum(int(r[3]) for r in rows[1:]) > 0  # 25 mm/h: some returns are raindrops
    buoy = {r[0] for r in csv_rows(run / "vessel.b1.state.csv")[1:]}  # recorded at 10 Hz
    assert {r[0] for r in rows[2:]} <= buoy  # each scan after t = 0 joins on stamp_ns
    tf = [m for m in messages if m.topic == "/tf"]
    assert len(tf) == len(rows[1:]) * 10 + 1  # every tick, and the start state at t = 0
    assert tf[0].schema_name == "tf2_msgs/msg/TFMessage"
    frames = [t.child_frame_id for t in tf[0].decoded.transforms]
    assert "ego/base_link" in frames and "b1/base_link" in frames  # buoys only there
    between = [t.child_frame_id for t in tf[-2].decoded.transforms]  # tick 98
    assert between == ["ego/base_link"]  # buoys at recording.traffic_rate_hz (10 Hz)
    last = tf[-1].decoded  # tick 99, stamped 1.0 s: every body, on the LiDAR's grid
    assert "b1/base_link" in [t.child_frame_id for t in last.transforms]
    assert (last.transforms[0].header.stamp.sec, last.transforms[0].header.stamp.nanosec) == (1, 0)
    assert "/b1/odom" not in {m.topic for m in messages}


def test_a_lambertian_lidar_sees_calm_water_only_near_it(tmp_path: Path, out: Path) -> None:
    """Two LiDARs 1 m up on one vessel, the paper's model and `reflection: "lambertian"`: the
    second's water returns end at 10.8 m (README: Z^3 < s h / (pi t)); both see the buoy."""
    data = basic_scenario("lambert", duration_s=0.3)
    data["buoys"] = [{"id": "b1", "x_m": 20.0, "y_m": 0.0}]
    lidar = {"type": "lidar", "rate_hz": 10.0, "params": {"mount_xyz": [0.0, 0.0, 1.0]}}
    data["vessels"][0]["sensors"] = [
        {**lidar, "name": "paper"},
        {**lidar, "name": "lambert", "params": {**lidar["params"], "reflection": "lambertian"}},
    ]
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    run = RecordedRun(only_run_dir(out))
    for sensor in run.world.sensors:
        scans = list(run.lidar_scans(sensor))
        assert len(scans) == 3
        water = np.concatenate([np.linalg.norm(s.points[s.cls == 1], axis=1) for s in scans])
        buoy = sum(int((s.cls == 4).sum()) for s in scans)
        name, far = sensor.config.name, water.max()
        assert buoy > 0, name
        assert far < 10.9 if name == "lambert" else far > 70.0, (name, far)
