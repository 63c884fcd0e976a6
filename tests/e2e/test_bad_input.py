"""Bad scenarios are refused before anything starts, with the field named."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import basic_scenario, catabot, scenario_file


def test_sensor_period_not_whole_ticks_is_refused_before_start(tmp_path: Path, out: Path) -> None:
    data = basic_scenario()
    data["vessels"][0]["sensors"] = [{"name": "imu", "type": "imu", "rate_hz": 30.0}]
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(out))
    assert result.returncode == 2
    assert "vessels.0.sensors.0.rate_hz" in result.stderr
    assert "whole number of ticks" in result.stderr
    assert list(out.iterdir()) == [], "nothing may start"


def test_bad_field_names_field_and_allowed_values(tmp_path: Path, out: Path) -> None:
    data = basic_scenario(clock={"policy": "retry"})
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(out))
    assert result.returncode == 2
    assert "clock.policy" in result.stderr and "'abort'" in result.stderr
    assert "Traceback" not in result.stderr


def test_missing_scenario_and_missing_model(tmp_path: Path, out: Path) -> None:
    result = catabot("run", str(tmp_path / "nope.json"), "--out", str(out))
    assert result.returncode == 2 and "does not exist" in result.stderr
    data = basic_scenario()
    data["vessels"][0]["model"] = "submarine"
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(out))
    assert result.returncode == 2 and "submarine" in result.stderr
    assert "Traceback" not in result.stderr


def test_schema_command_writes_a_json_schema(tmp_path: Path) -> None:
    result = catabot("scenario", "schema", "-o", str(tmp_path / "s.json"))
    assert result.returncode == 0
    assert '"title": "CataBot scenario"' in (tmp_path / "s.json").read_text()


def test_an_unknown_scheduling_policy_is_refused_before_start(
    tmp_path: Path, out: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("CATABOT_SCHED", "fifo")
    result = catabot("run", str(scenario_file(tmp_path, basic_scenario())), "--out", str(out))
    assert result.returncode == 2, result.stderr
    assert "CATABOT_SCHED='fifo'" in result.stderr and "batch, normal" in result.stderr
    assert "Traceback" not in result.stderr
    assert list(out.iterdir()) == [], "nothing may start"
