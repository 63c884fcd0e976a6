"""Scenario checks found by users' trials: a mount no sensor has, a boat pinned twice, a
duration of part of a tick."""

from __future__ import annotations

from typing import Any

import pytest

from tests.catabot.config.test_scenario import _base, _error


@pytest.mark.parametrize(
    ("kind", "params", "said"),
    [
        ("lidar", {"mount_pitch_deg": 120}, "mount_pitch_deg: must be <= 90 (got 120)"),
        ("radar", {"antenna_height_m": -1}, "antenna_height_m: must be > 0 (got -1)"),
    ],
)
def test_a_mount_no_sensor_has_is_refused(kind: str, params: dict[str, Any], said: str) -> None:
    data = _base()
    data["vessels"][0]["sensors"][1] = {"name": "s", "type": kind, "rate_hz": 10, "params": params}
    assert said in _error(data)


@pytest.mark.parametrize(
    ("boats", "said"),
    [
        ([{"index": 3}], "traffic: boats: index 3 is not below count 3"),
        ([{"index": 1, "behaviour": "hold"}, {"index": 1, "behaviour": "circle"}],
         "traffic: boats.1: index 1 is pinned by boats.0 already; one entry a boat"),
    ],
)  # fmt: skip
def test_a_pinned_boat_is_one_of_the_count_and_pinned_once(
    boats: list[dict[str, Any]], said: str
) -> None:
    data = _base() | {"traffic": {"count": 3, "boats": boats}}
    assert said in _error(data)


def test_a_duration_of_part_of_a_tick_is_refused() -> None:
    """It was cut to whole ticks unsaid: metrics.json's 1.0 s looked like a short run."""
    data = _base() | {"duration_s": 1.005}
    said = "duration_s: 1.005 s is not a whole number of ticks of 0.01 s (the run would end at 1 s)"
    assert said in _error(data)
