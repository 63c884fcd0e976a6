"""The one precedence rule: outside > lockstep set-point > script, a release handing an
outside command's vessel back (physics applies it; the recorder writes and meters by it)."""

from __future__ import annotations

from catabot.bus.messages import ThrustCmd, TwistCmd, VesselState, WaypointsCmd
from catabot.world.orders import Orders

RELEASE = WaypointsCmd((), 1.0, 1.0, "release")
PATH = WaypointsCmd((1.0, 2.0, 5.0, 2.0), 1.0, 1.0, "loop")


def test_a_vessel_follows_its_script_until_the_bus_commands_it() -> None:
    orders = Orders()
    assert orders.follows_script("ego") and orders.in_force("ego") is None
    assert not orders.heard("ego", RELEASE, stamp_ns=0)  # nobody held it: nothing changes
    assert orders.heard("ego", ThrustCmd((0.5, 0.5)), stamp_ns=0)
    assert orders.in_force("ego") == ThrustCmd((0.5, 0.5)) and not orders.follows_script("ego")


def test_an_outside_command_outranks_a_set_point_until_released() -> None:
    orders = Orders()
    set_point = TwistCmd(1.0, 0.0, 4, 40_000_000)
    orders.heard("ego", set_point, stamp_ns=0)
    orders.heard("ego", TwistCmd(0.0, 0.1), stamp_ns=0)  # tick -1: from outside
    orders.heard(
        "ego", TwistCmd(2.0, 0.0, 5, 50_000_000), stamp_ns=0
    )  # a later set-point: still held
    assert orders.in_force("ego") == TwistCmd(0.0, 0.1)
    assert orders.heard("ego", PATH, stamp_ns=0)  # a path releases as a release does
    assert orders.in_force("ego") == TwistCmd(2.0, 0.0, 5, 50_000_000)


def test_a_set_point_steers_for_good_and_other_messages_change_nothing() -> None:
    orders = Orders()
    orders.heard("ego", TwistCmd(1.0, 0.0, 0, 0), stamp_ns=0)
    assert not orders.heard("ego", RELEASE, stamp_ns=0)
    assert not orders.follows_script("ego")
    zero = (0.0, 0.0, 0.0)
    state = VesselState(0, 0, zero, (0.0, 0.0, 0.0, 1.0), zero, zero, zero, zero)
    assert not orders.heard("ego", state, stamp_ns=0)
    assert orders.follows_script("other")


def test_a_stale_outside_command_expires_and_a_renewed_or_lockstep_one_does_not() -> None:
    orders = Orders({"ego": 400_000_000})  # command_timeout_s 0.4
    orders.heard("ego", ThrustCmd((0.5, 0.5)), stamp_ns=1_000_000_000)
    orders.heard("other", ThrustCmd((0.5, 0.5)), stamp_ns=1_000_000_000)  # no timeout
    assert orders.expire(1_390_000_000) == []
    orders.heard("ego", ThrustCmd((0.6, 0.6)), stamp_ns=1_200_000_000)  # renewed
    assert orders.expire(1_590_000_000) == []
    assert orders.expire(1_600_000_000) == ["ego"] and orders.follows_script("ego")
    assert orders.in_force("other") is not None  # held until a release
    orders.heard("ego", ThrustCmd((0.5, 0.5), tick=3), stamp_ns=2_000_000_000)  # lockstep
    assert orders.expire(9_000_000_000) == []


def test_a_dropped_controller_no_longer_holds_its_vessel_but_an_outside_command_does() -> None:
    """clock.policy drop: a crashed stack's last command held its boat to the end."""
    orders = Orders()
    orders.heard("thrust", ThrustCmd((0.6, 0.6), tick=7), stamp_ns=0)  # lockstep thrust
    orders.heard("twist", TwistCmd(1.0, 0.0, 7, 70_000_000), stamp_ns=0)  # a set-point
    orders.heard("outside", ThrustCmd((0.2, 0.2)), stamp_ns=0)  # tick -1
    for vessel in ("thrust", "twist", "outside"):
        orders.drop(vessel)
    assert orders.follows_script("thrust") and orders.follows_script("twist")
    assert orders.in_force("outside") == ThrustCmd((0.2, 0.2))
