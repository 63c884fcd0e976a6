"""Scenario loading and validation: every error names the field (DESIGN.md §6)."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import BUNDLED, load_scenario, parse_scenario
from catabot.config.scenario import Scenario


def _base() -> dict[str, Any]:
    return {
        "name": "test",
        "duration_s": 1.0,
        "dt_ns": 10_000_000,
        "vessels": [
            {
                "id": "ego",
                "script": [{"t_s": 0.0, "thrust": [0.5, 0.5]}],
                "sensors": [
                    {"name": "imu", "type": "imu", "rate_hz": 100.0},
                    {"name": "gps", "type": "gps", "rate_hz": 10.0},
                ],
            }
        ],
    }


def _error(data: dict[str, Any]) -> str:
    with pytest.raises(ScenarioError) as info:
        parse_scenario(data)
    return str(info.value)


def test_bundled_default_loads() -> None:
    scenario = load_scenario()
    assert isinstance(scenario, Scenario)
    assert scenario.name == "default"
    assert scenario.dt_ns == 10_000_000
    assert scenario.duration_ns == 60 * 1_000_000_000
    assert scenario.ticks == 6000
    assert [v.id for v in scenario.vessels] == ["ego"]
    assert {s.name: s.period_ns for s in scenario.vessels[0].sensors} == {
        "imu": 10_000_000,
        "gps": 100_000_000,
    }


def test_bundled_scenario_by_name_and_by_path() -> None:
    assert load_scenario("default") == load_scenario()
    assert load_scenario(BUNDLED / "default.json") == load_scenario()


def test_minimal_scenario_takes_defaults() -> None:
    scenario = parse_scenario({"vessels": [{"id": "a"}]})
    assert scenario.name == "default"
    assert scenario.clock.policy == "abort"
    assert scenario.ticks == 6000
    assert scenario.vessels[0].model == "catabot"


def test_scenario_is_frozen() -> None:
    scenario = parse_scenario(_base())
    with pytest.raises(ValueError):
        scenario.seed = 3  # type: ignore[misc]


def test_unknown_top_level_field() -> None:
    data = _base()
    data["durration_s"] = 3
    msg = _error(data)
    assert "durration_s: unknown field" in msg


def test_unknown_nested_field() -> None:
    data = _base()
    data["vessels"][0]["sensors"][1]["noize"] = False
    assert "vessels.0.sensors.1.noize: unknown field" in _error(data)


@pytest.mark.parametrize("value", ["abc", [1], {"s": 1}, None])
def test_wrong_type_for_duration(value: object) -> None:
    data = _base()
    data["duration_s"] = value
    msg = _error(data)
    assert "duration_s:" in msg
    assert "must be a number" in msg


@pytest.mark.parametrize("value", [-1.0, 0])
def test_negative_or_zero_duration(value: float) -> None:
    data = _base()
    data["duration_s"] = value
    msg = _error(data)
    assert "duration_s: must be > 0" in msg
    assert f"(got {value!r})" in msg


def test_duration_shorter_than_one_tick() -> None:
    data = _base()
    data["duration_s"] = 0.005
    msg = _error(data)
    assert msg.startswith("scenario <data>: duration_s:")  # the file named, as every error
    assert "shorter than one tick" in msg


def test_bad_policy_lists_allowed_values() -> None:
    data = _base()
    data["clock"] = {"policy": "ignore"}
    msg = _error(data)
    assert "clock.policy:" in msg
    assert "'abort'" in msg and "'drop'" in msg
    assert "'ignore'" in msg


def test_vessel_id_with_slash() -> None:
    data = _base()
    data["vessels"][0]["id"] = "ego/1"
    msg = _error(data)
    assert "vessels.0.id:" in msg
    assert "vessel name 'ego/1' is not allowed in a key" in msg


def test_world_name_with_wildcard() -> None:
    data = _base()
    data["name"] = "run*"
    msg = _error(data)
    assert "name:" in msg and "world name 'run*'" in msg


def test_sensor_name_with_space() -> None:
    data = _base()
    data["vessels"][0]["sensors"][0]["name"] = "front imu"
    msg = _error(data)
    assert "vessels.0.sensors.0.name:" in msg and "sensor name 'front imu'" in msg


def test_duplicate_vessel_ids() -> None:
    data = _base()
    data["vessels"].append(copy.deepcopy(data["vessels"][0]))
    msg = _error(data)
    assert "vessels:" in msg
    assert "vessel ids must be unique" in msg and "'ego', 'ego'" in msg


def test_duplicate_sensor_names() -> None:
    data = _base()
    data["vessels"][0]["sensors"][1]["name"] = "imu"
    msg = _error(data)
    assert "vessels.0.sensors:" in msg
    assert "sensor names must be unique" in msg and "'imu', 'imu'" in msg


def test_script_step_with_thrust_and_twist() -> None:
    data = _base()
    data["vessels"][0]["script"].append(
        {"t_s": 1.0, "thrust": [0.1, 0.1], "twist": {"surge_mps": 1.0, "yaw_rate_radps": 0.0}}
    )
    msg = _error(data)
    assert "vessels.0.script.1:" in msg
    assert "exactly one of 'thrust' or 'twist'" in msg


def test_script_step_with_no_command() -> None:
    data = _base()
    data["vessels"][0]["script"] = [{"t_s": 0.0}]
    assert "vessels.0.script.0: give exactly one of" in _error(data)


@pytest.mark.parametrize("thrust", [[1.5, 0.0], [0.0, -1.01]])
def test_thrust_out_of_range(thrust: list[float]) -> None:
    data = _base()
    data["vessels"][0]["script"][0]["thrust"] = thrust
    msg = _error(data)
    assert (
        f"vessels.0.script.0.thrust: commands are normalised: each in [-1, 1] (got {thrust})" in msg
    )


def test_unknown_sensor_type_lists_allowed() -> None:
    data = _base()
    data["vessels"][0]["sensors"][1]["type"] = "sonar"
    msg = _error(data)
    assert "vessels.0.sensors.1.type:" in msg
    assert "'imu'" in msg and "'gps'" in msg and "'sonar'" in msg


def test_missing_vessels() -> None:
    data = _base()
    del data["vessels"]
    assert "vessels: required field missing" in _error(data)


def test_empty_vessels() -> None:
    data = _base()
    data["vessels"] = []
    assert "vessels:" in _error(data)


def test_several_problems_are_reported_together() -> None:
    data = _base()
    data["seed"] = "x"
    data["clock"] = {"deadline_s": -1}
    msg = _error(data)
    assert "seed:" in msg and "clock.deadline_s:" in msg


def test_invalid_json_file(tmp_path: Path) -> None:
    path = tmp_path / "bad.json"
    path.write_text('{"vessels": [}')
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert str(path) in str(info.value)
    assert "not valid JSON" in str(info.value)


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "nowhere.json"
    with pytest.raises(ScenarioError, match="does not exist") as info:
        load_scenario(path)
    assert "nowhere.json" in str(info.value)
    with pytest.raises(ScenarioError, match=r"does not exist \(bundled scenarios: default, "):
        load_scenario("no-such-bundled-scenario")
    with pytest.raises(ScenarioError, match="'harbor' does not exist \\(did you mean 'harbour'"):
        load_scenario("harbor")


def test_file_errors_name_the_file(tmp_path: Path) -> None:
    data = _base()
    data["clock"] = {"policy": "stop"}
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert str(path) in str(info.value) and "clock.policy" in str(info.value)


def test_file_round_trip(tmp_path: Path) -> None:
    path = tmp_path / "s.json"
    path.write_text(json.dumps(_base()))
    assert load_scenario(path) == parse_scenario(_base())
    assert load_scenario(str(path)).ticks == 100


@pytest.mark.parametrize("window", [0, -3, 2.5, "ten"])
def test_a_clock_window_that_is_not_a_positive_whole_number(window: object) -> None:
    data = _base()
    data["clock"] = {"window_ticks": window}
    assert "clock.window_ticks:" in _error(data)


@pytest.mark.parametrize("delay", [-1, 2.5, "eight", 1001])
def test_a_setpoint_delay_that_is_not_a_whole_number_of_ticks(delay: object) -> None:
    data = _base()
    data["traffic"] = {"count": 2, "setpoint_delay_ticks": delay}
    assert "traffic.setpoint_delay_ticks:" in _error(data)


def test_seconds_given_to_a_nanosecond_field_are_named_as_such() -> None:
    data = _base() | {"dt_ns": 0.01}
    assert "dt_ns: must be an integer (got 0.01); dt_ns is in nanoseconds: 0.01 s is 10000000" in (
        _error(data)
    )
    assert "nanoseconds" not in _error(_base() | {"dt_ns": 2.5e6})  # a fraction of a ns only


@pytest.mark.parametrize(
    ("path", "value", "message"),
    [
        (("duration_s",), True, "duration_s: must be a number (got true)"),
        (("vessels", 0, "pose"), {"x_m": False}, "pose.x_m: must be a number (got false)"),
        (("traffic",), {"count": True}, "traffic.count: must be an integer (got true)"),
        (("rain",), {"rate_mm_h": True}, "rain.rate_mm_h: must be a number (got true)"),
        (("vessels", 0, "script", 0, "thrust"), [0.5, True], "thrust.1: must be a number"),
        (("wind",), {"speed_mps": "10"}, 'wind.speed_mps: must be a number (got the text "10")'),
        (
            ("vessels", 0, "sensors", 0, "params"),
            {"gyro_sigma": True},
            "sensors.0.params.gyro_sigma: must be a number (got true)",
        ),
    ],
)
def test_true_false_or_text_is_not_a_number(
    path: tuple[Any, ...], value: Any, message: str
) -> None:
    """pydantic's lax mode took true as 1.0 (a run in 1 mm/h rain nobody asked for) and "10"
    as 10, where the JSON Schema an editor checks against says `number`."""
    assert message in _error(_with(_base(), path, value))


@pytest.mark.parametrize(
    ("section", "value", "message"),
    [
        (("vessels", 0, "pose"), {"x_m": 0, "y_m": 0, "yaw_rad": 90}, "pose.yaw_rad: angles are"),
        (("wind",), {"speed_mps": 3, "toward_rad": -270}, "wind.toward_rad: angles are radians"),
        (("water",), {"waves": {"direction_rad": 7}}, "waves.direction_rad: angles are radians"),
        (("water",), {"waves": {"peak_period_s": 8000}}, "peak_period_s: must be <= 30"),
        (
            ("vessels", 0, "script"),
            [{"t_s": 0, "twist": {"surge_mps": 1e308, "yaw_rate_radps": 0}}],
            "script.0.twist.surge_mps: must be <= 50 (got 1e+308)",
        ),
    ],
)
def test_angles_in_degrees_and_periods_in_ms_are_caught(
    section: tuple[Any, ...], value: Any, message: str
) -> None:
    """Unit mistakes that used to run: a yaw of 90 rad, a wave period of 8000 s, a
    set-point of 1e308 m/s (the controller's thrust overflowed to NaN)."""
    assert message in _error(_with(_base(), section, value))


def _with(root: dict[str, Any], path: tuple[Any, ...], value: Any) -> dict[str, Any]:
    """`root` with the field at `path` (keys and list indices) set to `value`."""
    target: Any = root
    for part in path[:-1]:
        target = target[part]
    target[path[-1]] = value
    return root


def test_a_value_is_shown_in_the_files_own_words() -> None:
    """JSON's null and true were shown as Python's None and True."""
    data = _base()
    data["traffic"] = {"count": 1, "region": None}
    data["duration_s"] = True
    msg = _error(data)
    assert "traffic.region: must be an object (got null)" in msg
    assert "duration_s: must be a number (got true)" in msg


def test_a_command_timeout_beyond_a_day_is_refused() -> None:
    """1e300 s passed and overflowed in physics and the recorder (ns in an int)."""
    vessel = {"vessels": [{"id": "e", "command_timeout_s": 1e300}]}
    assert "vessels.0.command_timeout_s: must be <= 86400" in _error(vessel)
    boats = {"vessels": [{"id": "e"}], "traffic": {"count": 1, "command_timeout_s": 1e300}}
    assert "traffic.command_timeout_s: must be <= 86400" in _error(boats)
