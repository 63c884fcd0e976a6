"""The example stacks' GPS conversion, line-of-sight guidance and thrust mixing."""

from __future__ import annotations

import math

import numpy as np
import pytest
from guidance import (
    Catamaran,
    LocalFrame,
    goal_of,
    line_of_sight,
    next_leg,
    route_of,
    steer,
    wrap,
)

from catabot.world.geo import EnuFrame


@pytest.mark.parametrize("lat", [0.0, 40.7003, 70.0, -33.9])
def test_local_frame_agrees_with_the_simulators_exact_enu_frame(lat: float) -> None:
    frame, exact = LocalFrame(lat, -74.017, 3.0), EnuFrame(lat, -74.017, 3.0)
    angles = np.linspace(0, math.tau, 12, endpoint=False)
    for d in (100.0, 500.0, 2000.0):
        tolerance = 1.2 * d**2 * max(math.tan(math.radians(abs(lat))), 0.1) / (2 * 6.371e6)
        east, north = d * np.cos(angles), d * np.sin(angles)
        la, lo, _ = exact.to_geodetic(east, north, np.zeros_like(east))
        got = np.array([frame.to_local(a, o) for a, o in zip(la, lo, strict=True)])
        error = np.hypot(got[:, 0] - east, got[:, 1] - north).max()
        assert error < tolerance, (lat, d, error)  # the parallel curving off the plane


def test_local_frame_round_trips_and_crosses_the_antimeridian() -> None:
    frame = LocalFrame(10.0, 179.9995)
    lat, lon = frame.to_fix(120.0, -30.0)
    wrapped = (lon + 180.0) % 360.0 - 180.0
    assert lon > 180.0 and wrapped < -179.99  # 120 m east of the origin is across the line
    east, north = frame.to_local(lat, wrapped)
    assert east == pytest.approx(120.0, abs=1e-6) and north == pytest.approx(-30.0, abs=1e-6)


def test_local_frame_of_a_scenario_without_origin_says_so() -> None:
    assert (
        LocalFrame.of_scenario({"origin": {"latitude_deg": 1, "longitude_deg": 2}}).altitude_m == 0
    )
    with pytest.raises(SystemExit, match="no usable `origin`"):
        LocalFrame.of_scenario({"name": "x"})


def test_line_of_sight_steers_back_onto_the_leg() -> None:
    on, cross, along = line_of_sight((5.0, 0.0), (0.0, 0.0), (10.0, 0.0), 4.0)
    assert (on, cross, along) == (0.0, 0.0, 0.5)
    left, cross, _ = line_of_sight((5.0, 4.0), (0.0, 0.0), (10.0, 0.0), 4.0)
    assert cross == 4.0 and left == pytest.approx(-math.pi / 4)  # left of the path: turn right
    right, cross, _ = line_of_sight((5.0, -4.0), (0.0, 0.0), (10.0, 0.0), 4.0)
    assert cross == -4.0 and right == pytest.approx(math.pi / 4)
    north, _, _ = line_of_sight((0.0, 3.0), (0.0, 0.0), (0.0, 10.0), 4.0)
    assert north == pytest.approx(math.pi / 2)
    with pytest.raises(ValueError, match="two different points"):
        line_of_sight((0.0, 0.0), (1.0, 1.0), (1.0, 1.0), 4.0)


def test_next_leg_switches_when_close_or_past_the_end() -> None:
    path = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)]
    assert next_leg((5.0, 0.0), path, 0, 2.0) == 0
    assert next_leg((8.5, 0.5), path, 0, 2.0) == 1  # within the acceptance radius
    assert next_leg((12.0, 5.0), path, 0, 2.0) == 1  # past the first leg's end
    assert next_leg((10.0, 9.0), path, 1, 2.0) == 2  # done


def test_steer_and_wrap() -> None:
    assert wrap(3 * math.pi) == pytest.approx(-math.pi)
    assert steer(math.radians(170), math.radians(-170), 1.0, 1.0) == pytest.approx(
        math.radians(-20)
    )
    assert steer(2.0, 0.0, 1.0, 0.3) == 0.3


def test_catamaran_thrust_balances_its_damping() -> None:
    boat = Catamaran()
    port, starboard = boat.thrust(1.0, 0.0, 0.0)
    assert port == starboard == pytest.approx((12 + 14) / 36 / 2)
    port, starboard = boat.thrust(0.5, 0.2, 0.2)  # a left turn: starboard pushes harder
    assert starboard - port == pytest.approx((80 * 0.2 + 15 * 0.04) / (0.4 * 36))
    port, starboard = boat.thrust(0.5, 0.2, 0.0)  # turning too slowly: more difference
    assert starboard - port > (80 * 0.2 + 15 * 0.04) / (0.4 * 36)
    assert boat.thrust(5.0, 0.0, 0.0) == [1.0, 1.0]


def test_goal_and_route_come_from_the_flags_or_the_scenarios_task() -> None:
    scenario = {"vessels": [{"id": "ego", "task": {"goal": {"x_m": 9, "y_m": -2, "radius_m": 3},
                                                   "route": [[0, 0], [5, 0], [5, 5]]}},
                            {"id": "other"}]}  # fmt: skip
    assert goal_of(None, scenario, "ego") == (9.0, -2.0)
    assert goal_of([1.0, 2.0], scenario, "ego") == (1.0, 2.0)
    assert route_of(None, scenario, "ego") == [(0.0, 0.0), (5.0, 0.0), (5.0, 5.0)]
    assert route_of([0, 0, 3, 4], scenario, "other") == [(0.0, 0.0), (3.0, 4.0)]
    with pytest.raises(SystemExit, match="no goal: give --goal X Y or a task"):
        goal_of(None, scenario, "other")
    with pytest.raises(SystemExit, match="no path: give --waypoints"):
        route_of(None, scenario, "other")
    with pytest.raises(SystemExit, match="pairs X Y, at least two"):
        route_of([0, 0, 3], scenario, "ego")
    with pytest.raises(SystemExit, match="repeats the point"):
        route_of([0, 0, 0, 0, 1, 1], scenario, "ego")
