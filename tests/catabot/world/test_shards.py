"""Sensors shared out between processes: balanced by rays a second, the same split in every
process; the scenario refuses more shards than sensors."""

from __future__ import annotations

from typing import Any

import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import parse_scenario
from catabot.world.shards import sensor_costs, split
from catabot.world.world import World

GPS = {"name": "gps", "type": "gps", "rate_hz": 10.0}
LIDAR = {"name": "lidar", "type": "lidar", "rate_hz": 10.0}
CAMERA = {"name": "cam", "type": "camera", "rate_hz": 10.0}


def _world(shards: int, *kits: list[dict[str, Any]]) -> World:
    vessels = [
        {"id": f"v{i}", "pose": {"x_m": 30.0 * i}, "sensors": kit} for i, kit in enumerate(kits)
    ]
    return World.resolve(parse_scenario({"name": "w", "sensors": {"shards": shards},
                                          "vessels": vessels}))  # fmt: skip


def test_one_shard_is_the_sensors_service_itself() -> None:
    world = _world(1, [GPS], [LIDAR])
    assert set(world.sensor_owners.values()) == {"sensors"}
    assert world.services == ["physics", "sensors", "recorder"]


def test_shards_are_participants_and_produce_their_streams() -> None:
    world = _world(2, [GPS], [LIDAR, GPS])
    assert world.services == ["physics", "sensors.0", "sensors.1", "recorder"]
    producers = {s.key: s.producer for s in world.streams.sensors}
    assert producers == world.sensor_owners
    assert producers == {
        "catabot/w/sensor/v1/lidar": "sensors.0",  # the most expensive first
        "catabot/w/sensor/v0/gps": "sensors.1",
        "catabot/w/sensor/v1/gps": "sensors.1",
    }


def test_one_vessels_camera_and_lidar_run_side_by_side() -> None:
    world = _world(2, [CAMERA, LIDAR, GPS])
    owners = {key.rsplit("/", 1)[1]: name for key, name in world.sensor_owners.items()}
    assert owners["cam"] != owners["lidar"]


def test_costs_count_rays_a_second() -> None:
    world = _world(1, [GPS], [LIDAR], [CAMERA])
    costs = sensor_costs(world.sensors, world.scenario.dt_ns)
    assert costs["catabot/w/sensor/v1/lidar"] == pytest.approx(32 * 512 * 10 + 1e4)
    assert costs["catabot/w/sensor/v2/cam"] == pytest.approx(640 * 480 * 10 + 1e4)
    assert costs["catabot/w/sensor/v0/gps"] == pytest.approx(1e4)


def test_split_is_longest_first_to_the_least_loaded() -> None:
    costs = {"a": 5.0, "b": 4.0, "c": 3.0, "d": 3.0, "e": 3.0}
    owner = split(costs, 2)
    loads = sorted(sum(c for k, c in costs.items() if owner[k] == i) for i in range(2))
    assert loads == [8, 10]  # the best is 9 / 9: LPT stays within 4/3 of it
    assert split({"a": 1.0, "b": 1.0}, 2) == {"a": 0, "b": 1}  # ties: lower index, world order


def test_more_shards_than_sensors_is_refused_by_name() -> None:
    with pytest.raises(ScenarioError, match=r"sensors\.shards.*3 shards for 2 sensor"):
        _world(3, [GPS], [GPS])
    with pytest.raises(ScenarioError, match=r"sensors\.shards"):
        _world(0, [GPS])


def test_traffic_shards_guide_contiguous_blocks_on_keys_of_their_own() -> None:
    data = {"name": "w", "vessels": [{"id": "ego"}], "traffic": {"count": 7, "shards": 3}}
    world = World.resolve(parse_scenario(data))
    assert list(world.traffic_blocks.values()) == [
        ("boat_000", "boat_001"), ("boat_002", "boat_003"), ("boat_004", "boat_005", "boat_006"),
    ]  # fmt: skip
    assert world.services == ["physics", "traffic.0", "traffic.1", "traffic.2", "recorder"]
    streams = world.streams.twists
    assert [s.key for s in streams] == [f"catabot/w/world/cmd/twist/{i:02d}" for i in range(3)]
    assert [s.producer for s in streams] == ["traffic.0", "traffic.1", "traffic.2"]


def test_more_traffic_shards_than_boats_is_refused_by_name() -> None:
    data = {"name": "w", "vessels": [{"id": "ego"}], "traffic": {"count": 2, "shards": 3}}
    with pytest.raises(ScenarioError, match=r"traffic\.shards: 3 shards for 2 boat"):
        parse_scenario(data)


def test_the_vessels_a_participant_drives_are_its_controllers_and_its_shards_boats() -> None:
    """What a drop hands back (clock.policy drop), in row order."""
    stack = {"participant": "stack", "rate_hz": 10.0}
    vessels = [{"id": "ego", "controller": stack}, {"id": "b", "pose": {"x_m": 20.0}}]
    data = {"name": "w", "vessels": vessels, "traffic": {"count": 4, "shards": 2}}
    world = World.resolve(parse_scenario(data))
    assert world.driven_by(["traffic.1", "stack"]) == ["ego", "boat_002", "boat_003"]
    assert world.driven_by(["recorder"]) == []
