"""Who drives a vessel: external command > traffic set-point > script, and the release."""

from __future__ import annotations

import logging

import pytest

from catabot.bus.messages import ThrustCmd, TwistCmd, WaypointsCmd
from catabot.config.load import parse_scenario
from catabot.run.advice import advice_of
from catabot.world.world import World
from services.physics.commands import CommandBook, Order
from tests.services.physics.helpers import vessels


def _book() -> CommandBook:
    return CommandBook(vessels({"id": "boat_000"}))


def test_traffic_set_points_drive_a_boat_until_an_external_command_takes_it() -> None:
    book = _book()
    book.take("boat_000", [TwistCmd(5.0, 0.26, tick=0)])
    assert book.order("boat_000", 0) == Order(twist=(5.0, 0.26))
    book.take("boat_000", [TwistCmd(1.0, 0.0, tick=-1), TwistCmd(5.0, 0.3, tick=1)])
    assert book.order("boat_000", 0) == Order(twist=(1.0, 0.0))  # the set-point waits
    book.take("boat_000", [ThrustCmd((0.2, 0.2))])
    assert book.order("boat_000", 0) == Order(thrust=(0.2, 0.2))


def test_a_waypoints_command_hands_the_boat_back() -> None:
    book = _book()
    book.take("boat_000", [TwistCmd(5.0, 0.26, tick=3), TwistCmd(0.0, 0.0, tick=-1)])
    release = WaypointsCmd(points=(), speed=0.0, tolerance=0.0, mode="release")
    book.take("boat_000", [release])
    assert book.order("boat_000", 0) == Order(twist=(5.0, 0.26))


def test_a_released_vessel_rests_until_its_script_says_otherwise() -> None:
    """An outside thrust held until a release used to stay on the thrusters of a vessel with
    no script step in force (none yet, or no script): it was never unset."""
    book = CommandBook(vessels({"id": "plain"}, {"id": "late", "script": [
        {"t_s": 1.0, "thrust": [0.4, 0.4]}]}))  # fmt: skip
    release = WaypointsCmd(points=(), speed=0.0, tolerance=0.0, mode="release")
    for vid in ("plain", "late"):
        book.take(vid, [ThrustCmd((-0.5, -0.5))])
    assert book.orders(0)[0] == {0: (-0.5, -0.5), 1: (-0.5, -0.5)}
    book.take("plain", [release])
    book.take("late", [release])
    assert book.orders(10_000_000)[0] == {0: (0.0, 0.0), 1: (0.0, 0.0)}
    assert book.orders(20_000_000)[0] == {1: (0.0, 0.0)}  # plain: set once, then left
    assert book.orders(1_000_000_000)[0] == {1: (0.4, 0.4)}


def test_a_takeover_from_outside_is_told_once_until_the_vessel_is_handed_back(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """A client on the run's endpoint (another stack, a forgotten teleop) steered a vessel
    and nothing said so: only its recorded commands showed it afterwards. The vessel's own
    lockstep thrust controller is not an outsider (every thrust stack was told it was)."""
    book = _book()
    release = WaypointsCmd(points=(), speed=0.0, tolerance=0.0, mode="release")
    with caplog.at_level(logging.INFO, logger="physics.commands"):
        book.take("boat_000", [TwistCmd(5.0, 0.26, tick=3)], stamp_ns=30_000_000)  # lockstep
        book.take("boat_000", [ThrustCmd((0.1, 0.1), tick=4)], stamp_ns=40_000_000)  # its own
        book.take("boat_000", [release], stamp_ns=50_000_000)
        book.take("boat_000", [ThrustCmd((0.2, 0.2))], stamp_ns=1_230_000_000)
        book.take("boat_000", [ThrustCmd((0.3, 0.3))], stamp_ns=1_240_000_000)  # still held
        book.take("boat_000", [release, TwistCmd(1.0, 0.0)], stamp_ns=2_000_000_000)
    told = [advice_of(f" INFO {r.getMessage()}") for r in caplog.records]
    assert told == [  # it has no command_timeout_s: none is offered
        "boat_000: taken over by an outside thrust at t = 1.23 s; it holds the vessel until a "
        "release (waypoints)",
        "boat_000: handed back (waypoints) at t = 2 s, to its script (rest without one)",
        "boat_000: taken over by an outside twist at t = 2 s; it holds the vessel until a "
        "release (waypoints)",
    ]


def test_a_traffic_boat_taken_over_goes_back_to_its_guidance_after_the_timeout(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """A boat's take-over said it held until "its command_timeout_s", which a boat could not
    have: a crashed controller left it driving to the end. `traffic.command_timeout_s`."""
    world = World.resolve(parse_scenario({
        "vessels": [{"id": "ego"}], "traffic": {"count": 1, "command_timeout_s": 0.5},
    }))  # fmt: skip
    book = CommandBook(world.vessels)
    book.take("boat_000", [TwistCmd(4.0, 0.1, tick=0)])  # the traffic's set-point
    with caplog.at_level(logging.INFO, logger="physics.commands"):
        book.take("boat_000", [TwistCmd(1.0, 0.0)], stamp_ns=1_000_000_000)
        assert book.orders(1_490_000_000)[2].tolist() == [[1.0, 0.0]]
        assert book.orders(1_510_000_000)[2].tolist() == [[4.0, 0.1]]  # its guidance again
    told = [advice_of(f" INFO {r.getMessage()}") for r in caplog.records]
    assert told[0].endswith(
        "until a release (waypoints) or 0.5 s without one (traffic.command_timeout_s)"
    )
    assert "handed back at t = 1.51 s to the traffic's guidance" in caplog.records[-1].getMessage()


def test_a_dropped_stacks_vessel_is_handed_back_and_the_console_told(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """clock.policy drop: the boat of a crashed stack sailed on at its last thrust."""
    book = CommandBook(vessels({"id": "a"}, {"id": "b", "pose": {"x_m": 20.0}}))
    book.take("a", [ThrustCmd((0.6, 0.6), tick=7)], stamp_ns=70_000_000)
    book.take("b", [TwistCmd(1.0, 0.1, tick=7)], stamp_ns=70_000_000)
    with caplog.at_level(logging.INFO, logger="physics.commands"):
        book.drop("stack", ["a", "b"], 1_400_000_000)
    assert book.orders(1_400_000_000)[0] == {0: (0.0, 0.0), 1: (0.0, 0.0)}  # rest: no script
    assert [advice_of(f" INFO {r.getMessage()}") for r in caplog.records] == [
        "stack left the run at t = 1.4 s (clock.policy drop): a, b back to script (rest "
        "without one)"
    ]
