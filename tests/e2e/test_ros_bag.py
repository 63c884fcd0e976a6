"""A recorded harbour run with every sensor is a ROS 2 bag: rosbags' AnyReader (not our
reader) opens run.mcap, decodes every message, and every frame id in it reaches `map`
through /tf and /tf_static."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from conftest import catabot, only_run_dir, scenario_file
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from catabot.config.load import load_scenario

EVERY_SENSOR = [
    {"name": "imu", "type": "imu", "rate_hz": 100.0},
    {"name": "gps", "type": "gps", "rate_hz": 10.0},
    {"name": "lidar", "type": "lidar", "rate_hz": 10.0},
    {"name": "radar", "type": "radar", "rate_hz": 10.0, "params": {"rotation_period_s": 0.5}},
    {"name": "cam", "type": "camera", "rate_hz": 5.0, "params": {"width": 96, "height": 72}},
]


def _harbour() -> dict[str, Any]:
    data = json.loads(load_scenario("harbour").model_dump_json())  # paths made absolute
    data["duration_s"] = 1.2
    data["vessels"][0]["sensors"] = EVERY_SENSOR
    data["traffic"] = {"count": 2}
    return data


def _frames(msg: Any) -> list[str]:
    """Every frame id a message names (headers, children, markers)."""
    out = []
    if hasattr(msg, "header"):
        out.append(msg.header.frame_id)
    if hasattr(msg, "child_frame_id"):
        out.append(msg.child_frame_id)
    for item in [*getattr(msg, "transforms", []), *getattr(msg, "markers", [])]:
        out += _frames(item)
    return out


def test_harbour_bag_reads_with_rosbags_and_every_frame_reaches_map(
    tmp_path: Path, out: Path
) -> None:
    result = catabot("run", str(scenario_file(tmp_path, _harbour())), "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    run = only_run_dir(out)
    parent: dict[str, str] = {}
    named: set[str] = set()
    types: dict[str, str] = {}
    count = 0
    with AnyReader([run / "run.mcap"], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as bag:
        for connection, _, raw in bag.messages():
            msg = bag.deserialize(raw, connection.msgtype)
            count += 1
            types[connection.topic] = connection.msgtype
            named.update(_frames(msg))
            if connection.topic in ("/tf", "/tf_static"):
                parent.update({t.child_frame_id: t.header.frame_id for t in msg.transforms})
        assert count == bag.message_count > 500
    expected = ["/ego/odom", "/wamv/odom", "/boat_001/odom", "/buoys", "/ego/cam/camera_info",
                "/ego/radar/ppi", "/ego/lidar/points", "/ego/gps/fix", "/ego/imu/imu"]  # fmt: skip
    assert set(expected) <= set(types)
    assert all(t.split("/")[1] == "msg" for t in types.values())
    for frame in named:
        chain = [frame]
        while chain[-1] != "map":
            assert chain[-1] in parent, f"{frame} does not reach map: {chain}"
            chain.append(parent[chain[-1]])
    assert {"ego/cam_optical", "ego/lidar", "ego/radar", "b2/base_link"} <= named
