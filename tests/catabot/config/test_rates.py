"""Rates are whole numbers of ticks (catabot/config/rates.py): every rate a scenario sets is
refused with its field named when it is not, and turned into ticks one way."""

from __future__ import annotations

from typing import Any

import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import parse_scenario
from catabot.config.rates import guidance_period_ticks, traffic_record_period


def _base() -> dict[str, Any]:
    sensors = [{"name": "imu", "type": "imu", "rate_hz": 100.0},
               {"name": "gps", "type": "gps", "rate_hz": 10.0}]  # fmt: skip
    return {"name": "test", "duration_s": 1.0, "dt_ns": 10_000_000,
            "vessels": [{"id": "ego", "sensors": sensors}]}  # fmt: skip


def _error(data: dict[str, Any]) -> str:
    with pytest.raises(ScenarioError) as info:
        parse_scenario(data)
    return str(info.value)


def test_sensor_rate_not_a_whole_number_of_ticks() -> None:
    data = _base()
    data["vessels"][0]["sensors"][1]["rate_hz"] = 30.0  # period 33333333 ns at dt 10 ms
    msg = _error(data)
    assert "vessels.0.sensors.1.rate_hz" in msg
    assert "ego/gps" in msg
    assert "33333333" in msg
    assert "whole number of ticks" in msg
    assert "100 Hz divided by a whole number" in msg  # the allowed rates
    assert "the nearest are 33.33 Hz (every 3 ticks) and 25 Hz (every 4)" in msg


def test_sensor_rate_3_hz_refused() -> None:
    data = _base()
    data["vessels"][0]["sensors"][1]["rate_hz"] = 3.0
    msg = _error(data)
    assert "ego/gps" in msg and "whole number of ticks" in msg


def test_sensor_period_not_a_whole_number_of_ns() -> None:
    data = _base()
    data["dt_ns"] = 33_333_333  # 30 Hz is then one tick, but 1/30 s is no whole number of ns
    data["vessels"][0]["sensors"] = [{"name": "imu", "type": "imu", "rate_hz": 30.0}]
    msg = _error(data)
    assert "vessels.0.sensors.0.rate_hz (ego/imu)" in msg
    assert "not a whole number of ns" in msg


def test_slow_sensor_rates_are_accepted() -> None:
    data = _base()
    data["duration_s"] = 100.0
    data["vessels"][0]["sensors"][1]["rate_hz"] = 0.1
    data["vessels"][0]["sensors"][0]["rate_hz"] = 0.001
    scenario = parse_scenario(data)
    assert [s.period_ns for s in scenario.vessels[0].sensors] == [10**12, 10**10]


def test_sensor_rate_of_exactly_one_tick_and_of_many() -> None:
    data = _base()
    data["vessels"][0]["sensors"][0]["rate_hz"] = 100.0
    data["vessels"][0]["sensors"][1]["rate_hz"] = 2.5
    scenario = parse_scenario(data)
    assert [s.period_ns for s in scenario.vessels[0].sensors] == [10_000_000, 400_000_000]


@pytest.mark.parametrize(
    ("rate", "says"),
    [(30.0, "not a whole number of ticks"), (0.0, "must be > 0"), ("fast", "must be a number")],
)
def test_a_guidance_rate_that_is_not_a_whole_number_of_ticks(rate: object, says: str) -> None:
    data = _base()
    data["traffic"] = {"count": 2, "guidance_hz": rate}
    error = _error(data)
    assert "traffic.guidance_hz" in error and says in error, error


def test_the_guidance_rate_sets_the_period_of_the_set_points() -> None:
    data = _base()
    data["traffic"] = {"count": 2, "guidance_hz": 25.0}
    assert guidance_period_ticks(parse_scenario(data)) == 4
    data["traffic"] = {"count": 0, "guidance_hz": 30.0}  # no boats: nothing to refuse
    assert parse_scenario(data).traffic.guidance_hz == 30.0


def test_the_traffic_recording_rate_sets_the_period_of_traffic_and_buoy_rows() -> None:
    data = _base()
    data["buoys"] = [{"id": "b0", "x_m": 20.0, "y_m": 0.0}]
    assert traffic_record_period(parse_scenario(data)) == 10  # 10 Hz by default
    data["recording"] = {"traffic_rate_hz": 25.0}
    assert traffic_record_period(parse_scenario(data)) == 4
    data["recording"] = {"traffic_rate_hz": None}
    assert traffic_record_period(parse_scenario(data)) == 1  # every tick


@pytest.mark.parametrize(
    ("rate", "says"),
    [(30.0, "not a whole number of ticks"), (0.0, "must be > 0"), ("fast", "must be a number")],
)
def test_a_traffic_recording_rate_that_is_not_whole_ticks_is_refused(
    rate: object, says: str
) -> None:
    data = _base()
    data["traffic"] = {"count": 2}
    data["recording"] = {"traffic_rate_hz": rate}
    error = _error(data)
    assert "recording.traffic_rate_hz" in error and says in error, error


def test_a_traffic_recording_rate_is_not_checked_without_traffic_or_buoys() -> None:
    data = _base()
    data["recording"] = {"traffic_rate_hz": 30.0}  # no body it would apply to
    assert parse_scenario(data).recording.traffic_rate_hz == 30.0


def test_a_rate_faster_than_the_clock_is_told_the_fastest() -> None:
    data = _base()
    data["vessels"][0]["sensors"][1]["rate_hz"] = 400.0
    assert "the fastest is 100 Hz (every tick)" in _error(data)


@pytest.mark.parametrize("rate", [1e-300, 1e-12])
def test_a_rate_too_slow_for_the_clock_is_named(rate: float) -> None:
    """1e-300 Hz overflowed to a traceback; 1e-12 Hz gave one sample, at tick 0."""
    data = _base()
    data["vessels"][0]["sensors"][0]["rate_hz"] = rate
    msg = _error(data)
    assert "vessels.0.sensors.0.rate_hz (ego/imu): " in msg
    assert f"{rate:g} Hz is too slow" in msg
