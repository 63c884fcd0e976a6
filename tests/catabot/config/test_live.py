"""Run-time settings (catabot/config/live.py): the keys a scenario offers, the values each
allows (the scenario's own rules), and the scenario's `settings` timeline."""

from __future__ import annotations

from typing import Any

import pytest

from catabot.bus.settings import Schedule
from catabot.config import live
from catabot.config.base import ScenarioError
from catabot.config.load import parse_scenario
from catabot.config.scenario import Scenario


def _data(**top: Any) -> dict[str, Any]:
    sensors = [
        {"name": "lidar", "type": "lidar", "rate_hz": 10.0},
        {"name": "cam.front", "type": "camera", "rate_hz": 5.0},
    ]
    return {"name": "live", "duration_s": 5.0, "vessels": [{"id": "ego.1", "sensors": sensors}],
            "traffic": {"count": 2}, **top}  # fmt: skip


def _scenario(**top: Any) -> Scenario:
    return parse_scenario(_data(**top), source="test")


def test_keys_of_a_scenario_name_its_sensors_cameras_and_boats() -> None:
    keys = live.keys_of(_scenario())
    assert list(keys)[:5] == ["rain", "wind.speed_mps", "wind.toward_rad", "current", "waves"]
    assert keys["sensor.ego.1.cam.front.outputs.depth"].output == "depth"  # dots in names
    assert keys["sensor.ego.1.lidar.enabled"].owner == "ego.1"
    assert "sensor.ego.1.lidar.outputs.color" not in keys  # only cameras have outputs
    assert keys["traffic.boat_001.behaviour"].kind == "behaviour"


@pytest.mark.parametrize(
    ("key", "value", "text"),
    [
        ("rain", 25, "25.0"),
        ("wind.speed_mps", 12.5, "12.5"),
        ("wind.toward_rad", -1, "-1.0"),
        ("current", [0.5, 0], "[0.5,0.0]"),
        ("waves", "heavy", '"heavy"'),
        ("sensor.ego.1.lidar.enabled", False, "false"),
        ("sensor.ego.1.cam.front.outputs.color", True, "true"),
        ("traffic.boat_000.behaviour", "hold", '"hold"'),
    ],
)
def test_values_are_checked_and_made_canonical(key: str, value: Any, text: str) -> None:
    assert live.check(_scenario(), key, value) == text


@pytest.mark.parametrize(
    ("key", "value", "allowed"),
    [
        ("rain", 80, "from 0 to 50"),
        ("rain", "lots", "from 0 to 50"),
        ("rain", None, "from 0 to 50"),
        ("wind.speed_mps", -1, "from 0 to 80"),
        ("current", [11, 0], "at most 10 m/s"),
        ("current", 3, "[east, north]"),
        ("waves", "huge", "'calm', 'medium', 'heavy'"),
        ("waves", None, "'calm', 'medium', 'heavy'"),
        ("waves", ["heavy"], "'calm', 'medium', 'heavy'"),
        ("sensor.ego.1.lidar.enabled", "yes", "true or false"),
        ("sensor.ego.1.lidar.enabled", 1, "true or false"),
        ("traffic.boat_000.behaviour", "dance", "'circle', 'waypoints', 'hold'"),
        ("rain", True, "a number, not true or false"),  # pydantic's lax float took it as 1.0
        ("wind.speed_mps", False, "a number, not true or false"),
        ("current", [True, False], "a number, not true or false"),
    ],
)
def test_bad_values_name_what_is_allowed(key: str, value: Any, allowed: str) -> None:
    with pytest.raises(live.SettingError, match="not allowed") as exc:
        live.check(_scenario(), key, value)
    assert allowed in str(exc.value) and key in str(exc.value)


@pytest.mark.parametrize(
    "key", ["snow", "sensor.ego.1.radar.enabled", "traffic.boat_009.behaviour", "", 3]
)
def test_unknown_keys_list_the_keys_of_the_run(key: Any) -> None:
    with pytest.raises(live.SettingError, match="unknown setting") as exc:
        live.check(_scenario(), key, 1)
    assert "rain, wind.speed_mps" in str(exc.value) and "catabot get" in str(exc.value)


def test_command_line_values() -> None:
    assert live.parse_value("25") == 25 and live.parse_value("off") is False
    assert live.parse_value("[0.5, 0]") == [0.5, 0] and live.parse_value("hold") == "hold"
    assert live.parse_value("true") is True and live.parse_value("ON") is True
    with pytest.raises(live.SettingError, match=r"'\[nan,0\]' is not JSON \(Expecting value"):
        live.parse_value("[nan,0]")  # was sent as the text "[nan,0]": "must be a list"


def test_a_mistyped_key_is_told_the_key_it_is_near() -> None:
    with pytest.raises(
        live.SettingError, match=r"unknown setting 'rian' \(did you mean 'rain'\?\)"
    ):
        live.check(_scenario(), "rian", 1)


@pytest.mark.parametrize(("waves", "shown"), [
    ({}, "calm"), ({"preset": "medium"}, "medium"),
    ({"significant_height_m": 0.5, "peak_period_s": 6.0}, "Hs 0.5 m, Tp 6 s (the scenario's)"),
])  # fmt: skip
def test_the_sea_is_shown_as_it_is(waves: dict[str, Any], shown: str) -> None:
    values = live.initial_values(_scenario(water={"waves": waves}))
    assert values["waves"] == shown  # was "as in the scenario"


def test_the_timeline_is_checked_like_the_rest_of_the_scenario() -> None:
    with pytest.raises(ScenarioError, match=r"settings\.1: unknown setting 'snow'"):
        _scenario(
            settings=[{"t_s": 1, "key": "rain", "value": 5}, {"t_s": 2, "key": "snow", "value": 1}]
        )
    with pytest.raises(ScenarioError, match=r"settings\.0: rain: 99 is not allowed"):
        _scenario(settings=[{"t_s": 1, "key": "rain", "value": 99}])
    twice = [{"t_s": 3, "key": "current", "value": [0.5, 0]},
             {"t_s": 2.995, "key": "current", "value": [-0.5, 0]}]  # fmt: skip
    with pytest.raises(ScenarioError, match=r"settings\.1: 'current' at 2.995 s: settings\.0 "
                       r"sets it at the same tick; which should win\? give one"):  # fmt: skip
        _scenario(settings=twice)  # the last one won, unsaid
    _scenario(settings=[twice[0], {"t_s": 3, "key": "rain", "value": 5}])  # another key: fine
    late = _scenario(settings=[{"t_s": 5, "key": "rain", "value": 1}])  # past the end: taken
    assert Schedule(live.timeline(late), ticks=late.ticks).in_force() == []  # never applied


def test_the_timeline_on_the_clock_and_back() -> None:
    scenario = _scenario(settings=[{"t_s": 2.004, "key": "rain", "value": 5},
                                   {"t_s": 0.31, "key": "waves", "value": "medium"}])  # fmt: skip
    changes = live.timeline(scenario)
    assert [(c.tick, c.key, c.value) for c in changes] == [
        (31, "waves", '"medium"'),
        (201, "rain", "5.0"),
    ]
    entries = [live.entry(c, scenario.dt_ns) for c in changes]
    assert entries[1] == {"t_s": 2.01, "key": "rain", "value": 5.0}
    again = _scenario(settings=entries)  # the run folder's timeline gives the same ticks
    assert live.timeline(again) == changes


def test_initial_values() -> None:
    values = live.initial_values(_scenario(rain={"rate_mm_h": 3.0}))
    assert values["rain"] == 3.0 and values["current"] == [0.0, 0.0]
    assert values["sensor.ego.1.cam.front.outputs.normals"] is True
    assert values["traffic.boat_000.behaviour"] == "as planned"
