"""A path sent to a boat from outside is said on the console, and a speed it cannot make."""

from __future__ import annotations

import logging

import pytest

from catabot.bus.messages import WaypointsCmd
from catabot.run.advice import advice_of
from services.traffic.outside import OutsidePaths

PATH = WaypointsCmd((0.0, 0.0, 40.0, 0.0), 3.0, 2.0, "loop")


def said(caplog: pytest.LogCaptureFixture) -> list[str | None]:
    lines = [advice_of(f"x {r.levelname} {r.getMessage()}\n") for r in caplog.records]
    caplog.clear()
    return lines


def test_a_takeover_and_its_release_are_said_once_each(caplog: pytest.LogCaptureFixture) -> None:
    paths = OutsidePaths(["boat_000", "boat_001"], [5.6, 5.6])
    with caplog.at_level(logging.INFO, logger="traffic"):
        paths.taken(1, PATH, 2_500_000_000)
        assert said(caplog) == ["boat_001: follows a path from outside from t = 2.5 s "
                                "(2 points, loop, 3 m/s) until a release"]  # fmt: skip
        paths.taken(1, PATH, 2_600_000_000)  # a new path while on one: no new line
        paths.released(0, 2_700_000_000)  # not on an outside path: nothing to say
        assert said(caplog) == []
        paths.released(1, 3_000_000_000)
        assert said(caplog) == ["boat_001: handed back to its scenario behaviour at t = 3 s"]


def test_a_speed_beyond_full_thrust_is_advised_once_per_speed(
    caplog: pytest.LogCaptureFixture,
) -> None:
    paths = OutsidePaths(["boat_000"], [5.6])
    fast = WaypointsCmd((0.0, 0.0, 1e4, 0.0), 50.0, 2.0, "back_and_forth")
    with caplog.at_level(logging.INFO, logger="traffic"):
        paths.taken(0, fast, 0)
        paths.taken(0, fast, 10_000_000)
        lines = said(caplog)
    assert lines[1:] == ["boat_000: its path's speed 50 m/s is beyond its top speed, "
                         "5.60 m/s at full thrust"]  # fmt: skip
