"""Same scenario and seed, same recorded bytes: peer-to-peer twice, and through a router."""

from __future__ import annotations

import time
from pathlib import Path

from conftest import basic_scenario, catabot, files_of, only_run_dir, scenario_file, start

from catabot.bus.session import free_port


def _record(tmp: Path, scenario: Path, tag: str, *extra: str) -> dict[str, bytes]:
    out = tmp / tag
    out.mkdir()
    result = catabot("run", str(scenario), "--out", str(out), "--quiet", *extra)
    assert result.returncode == 0, result.stderr
    return files_of(only_run_dir(out))


def _scenario(tmp: Path) -> Path:
    data = basic_scenario("determinism", duration_s=4.0)
    data["vessels"][0]["sensors"] = [
        {"name": "imu", "type": "imu", "rate_hz": 50.0},
        {"name": "gps", "type": "gps", "rate_hz": 5.0},
    ]
    data["vessels"][0]["task"] = {  # metrics.json's goal, route and encounter figures too
        "goal": {"x_m": 3.0, "y_m": 0.0, "radius_m": 1.0},
        "route": [[0.0, 0.0], [10.0, 2.0]],
    }
    data["buoys"] = [{"id": "mark", "x_m": 8.0, "y_m": 3.0}]
    data["vessels"].append(
        {
            "id": "other",
            "pose": {"x_m": 20.0, "y_m": 5.0},
            "script": [{"t_s": 0.0, "twist": {"surge_mps": 0.8, "yaw_rate_radps": 0.1}}],
        }
    )
    return scenario_file(tmp, data)


def test_two_runs_record_identical_bytes(tmp_path: Path) -> None:
    scenario = _scenario(tmp_path)
    first = _record(tmp_path, scenario, "a")
    second = _record(tmp_path, scenario, "b")
    assert set(first) >= {"vessel.ego.state.csv", "sensor.ego.imu.csv", "run.mcap"}
    assert b'"encounters": [' in first["metrics.json"] and b"cpa_m" in first["metrics.json"]
    assert first == second


def test_router_run_records_the_same_bytes_as_peer_to_peer(tmp_path: Path) -> None:
    scenario = _scenario(tmp_path)
    peer = _record(tmp_path, scenario, "peer")
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    router = start("router", "--listen", endpoint)
    try:
        time.sleep(1.0)
        assert router.poll() is None, router.communicate()
        routed = _record(tmp_path, scenario, "routed", "--connect", endpoint)
    finally:
        router.terminate()
        router.wait(timeout=10)
    assert peer == routed
