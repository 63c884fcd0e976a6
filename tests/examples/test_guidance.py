"""The example stacks' GPS conversion, line-of-sight guidance and thrust mixing."""

from __future__ import annotations

import math

import numpy as np
import pytest
from guidance import Catamaran, LocalFrame, line_of_sight, next_leg, steer, wrap

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
