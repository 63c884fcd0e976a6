"""Sensor parameters that cannot go together, or with their rate, are refused by field."""

from __future__ import annotations

import re
from typing import Any

import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import parse_scenario


def _radar(rate_hz: float, **params: Any) -> dict[str, Any]:
    radar = {"name": "radar", "type": "radar", "rate_hz": rate_hz, "params": params}
    return {"name": "r", "vessels": [{"id": "ego", "sensors": [radar]}]}


@pytest.mark.parametrize(
    ("rate_hz", "params", "message"),
    [
        (10.0, {"rotation_period_s": 0.001}, "params.rotation_period_s: must be >= 0.25"),
        (1.0, {"rotation_period_s": 0.5}, "vessels.0.sensors.0.params (ego/radar): "
         "rotation_period_s 0.5: one sample sweeps at most one turn, so at least "
         "1 / rate_hz = 1 s"),
    ],
)  # fmt: skip
def test_a_radar_turning_faster_than_it_is_sampled_is_refused(
    rate_hz: float, params: dict[str, Any], message: str
) -> None:
    """A 1 ms turn ran: 48 000 beams a sample, a real-time factor of 0.0."""
    with pytest.raises(ScenarioError) as info:
        parse_scenario(_radar(rate_hz, **params))
    assert message in str(info.value)


def test_the_ppi_persists_a_turn_and_a_half_unless_told() -> None:
    (radar,) = parse_scenario(_radar(10.0, rotation_period_s=2.5)).vessels[0].sensors
    assert radar.typed_params().fade == 3.75
    (radar,) = parse_scenario(_radar(10.0, fade_s=0.5)).vessels[0].sensors
    assert radar.typed_params().fade == 0.5


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"elevations_deg": [-5, 0]}, "elevations_deg: -5 is not 0-60 deg"),
        ({"elevations_deg": []}, "elevations_deg: needs at least 1 item"),
        ({"fan_target_height_m": 5}, "fan_target_height_m: 5 m is not below the antenna (3 m)"),
        ({"fan_min_range_m": 300}, "fan_min_range_m: 300 m is not within range_m (250 m)"),
        ({"range_m": 1e9}, "range_m: must be <= 100000"),
    ],
)
def test_radar_geometry_the_descriptions_gave_is_checked(
    params: dict[str, Any], message: str
) -> None:
    """Each had run without a word (a fan above the antenna silently turned the fan off)."""
    with pytest.raises(ScenarioError, match=re.escape(message)):
        parse_scenario(_radar(10.0, **params))


def test_a_vector_given_too_few_values_is_one_problem() -> None:
    """`antenna_offset.2: required field missing` read as a missing field named 2."""
    gps = {"name": "gps", "type": "gps", "rate_hz": 10.0, "params": {"antenna_offset": [1.0]}}
    with pytest.raises(ScenarioError) as info:
        parse_scenario({"vessels": [{"id": "ego", "sensors": [gps]}]})
    assert str(info.value).endswith("params.antenna_offset: needs 3 values, got 1")
