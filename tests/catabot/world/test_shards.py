"""Sensors shared out between processes: whole vessels, balanced by rays, the same split in
every process; the scenario refuses more shards than carriers."""

from __future__ import annotations

from typing import Any

import pytest

from catabot.config.load import parse_scenario
from catabot.config.scenario import ScenarioError
from catabot.world.shards import split, vessel_costs
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


def test_shards_are_participants_and_produce_their_vessels_streams() -> None:
    world = _world(2, [GPS], [LIDAR, GPS])
    assert world.services == ["physics", "sensors.0", "sensors.1", "recorder"]
    producers = {s.key: s.producer for s in world.streams.sensors}
    assert producers == world.sensor_owners
    owners = {key.split("/")[-2]: name for key, name in producers.items()}
    assert owners == {"v0": "sensors.1", "v1": "sensors.0"}  # the LiDAR carrier first


def test_a_vessels_sensors_stay_together() -> None:
    world = _world(3, [GPS, LIDAR], [CAMERA, GPS], [GPS], [LIDAR])
    by_vessel: dict[str, set[str]] = {}
    for key, name in world.sensor_owners.items():
        by_vessel.setdefault(key.split("/")[-2], set()).add(name)
    assert all(len(names) == 1 for names in by_vessel.values())
    assert len({next(iter(n)) for n in by_vessel.values()}) == 3  # every shard has work


def test_costs_count_rays_a_second() -> None:
    world = _world(1, [GPS], [LIDAR], [CAMERA])
    costs = vessel_costs(world.sensors, world.scenario.dt_ns)
    assert costs["v1"] == pytest.approx(32 * 512 * 10 + 1e4)
    assert costs["v2"] == pytest.approx(640 * 480 * 10 + 1e4)
    assert costs["v0"] < costs["v1"] < costs["v2"]


def test_split_is_longest_first_to_the_least_loaded() -> None:
    owner = split({"a": 5.0, "b": 4.0, "c": 3.0, "d": 3.0, "e": 3.0}, 2)
    loads = [sum(c for v, c in zip("abcde", (5, 4, 3, 3, 3), strict=True) if owner[v] == i)
             for i in range(2)]  # fmt: skip
    assert sorted(loads) == [8, 10]  # the best is 9 / 9: LPT stays within 4/3 of it
    assert split({"a": 1.0, "b": 1.0}, 2) == {"a": 0, "b": 1}  # ties: lower index, world order


def test_more_shards_than_carriers_is_refused_by_name() -> None:
    with pytest.raises(ScenarioError, match=r"sensors\.shards.*3 shards for 2 vessel"):
        _world(3, [GPS], [GPS])
    with pytest.raises(ScenarioError, match=r"sensors\.shards"):
        _world(0, [GPS])
