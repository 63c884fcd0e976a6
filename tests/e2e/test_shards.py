"""The sensors service split over processes (`sensors.shards`): the same bytes for any
number, each shard a participant of its own, a shard started wrongly refused by name."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from conftest import basic_scenario, catabot, files_of, only_run_dir, scenario_file

from catabot.config.load import parse_scenario
from catabot.run.service import own_name
from catabot.world.world import World

pytestmark = pytest.mark.timeout(240)


def fleet(shards: int, guides: int = 1) -> dict[str, Any]:
    vessels = []
    for i in range(4):
        sensors: list[dict[str, Any]] = [
            {"name": "gps", "type": "gps", "rate_hz": 10.0},
            {"name": "imu", "type": "imu", "rate_hz": 50.0},
        ]
        if i % 2 == 0:
            sensors.append({"name": "lidar", "type": "lidar", "rate_hz": 10.0,
                            "params": {"channels": 8, "columns": 128}})  # fmt: skip
        vessels.append({"id": f"v{i}", "pose": {"x_m": 20.0 * i}, "sensors": sensors,
                        "script": [{"t_s": 0.2, "thrust": [0.5, 0.7]}]})  # fmt: skip
    traffic = {"count": 5, "shards": guides, "behaviour_mix": {"circle": 0.6, "waypoints": 0.4}}
    return {"name": "shards", "seed": 5, "duration_s": 1.5, "traffic": traffic,
            "sensors": {"shards": shards}, "vessels": vessels}  # fmt: skip


def test_any_number_of_sensor_and_traffic_shards_records_the_same_bytes(tmp_path: Path) -> None:
    recorded = {}
    for shards, guides in ((1, 1), (3, 2)):  # uneven splits of 10 sensors and 5 boats
        out = tmp_path / f"out{shards}"
        scenario = scenario_file(tmp_path, fleet(shards, guides), name=f"s{shards}.json")
        done = catabot("run", str(scenario), "--out", str(out), "--quiet")
        assert done.returncode == 0, done.stdout + done.stderr
        run = only_run_dir(out)
        recorded[shards] = files_of(run)
        logs = {p.stem for p in (run / "log").glob("*.log")}
        assert logs >= ({"sensors"} if shards == 1 else {f"sensors.{i}" for i in range(shards)})
        assert logs >= ({"traffic"} if guides == 1 else {f"traffic.{i}" for i in range(guides)})
    assert len(recorded[1]) > 10
    assert recorded[3] == recorded[1]


def test_a_shard_started_without_its_place_is_refused(tmp_path: Path) -> None:
    scenario = scenario_file(tmp_path, fleet(2))
    alone = catabot("service", "sensors", "--scenario", str(scenario), timeout=60)
    assert alone.returncode == 2
    assert "splits sensors over 2 processes (sensors.shards): start each with --shard I/2" in (
        alone.stderr
    )
    wrong = catabot("service", "sensors", "--scenario", str(scenario), "--shard", "1/3")
    assert wrong.returncode == 2 and "--shard 1/3" in wrong.stderr
    junk = catabot("service", "sensors", "--scenario", str(scenario), "--shard", "2/2")
    assert junk.returncode == 2 and "use I/N with 0 <= I < N" in junk.stderr


def test_a_service_the_scenario_does_not_run_is_refused(tmp_path: Path) -> None:
    """Traffic on a scenario without boats crashed with a KeyError traceback; sensors on one
    without sensors joined, refused the clock's grants and exited 0."""
    scenario = scenario_file(tmp_path, basic_scenario("bare"))
    for service, why in (("traffic", "traffic.count is 0"), ("sensors", "no vessel has sensors")):
        got = catabot("service", service, "--scenario", str(scenario), timeout=60)
        assert got.returncode == 2, got.stderr
        assert f"scenario 'bare' does not run {service} ({why}); it runs physics" in got.stderr
    world = World.resolve(parse_scenario(basic_scenario("bare")))
    assert own_name("ros", world, None) == "ros"  # the gateway runs on any scenario
    assert own_name("recorder", world, None) == "recorder"
