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
    assert not orders.heard("ego", RELEASE)  # nobody held it: nothing changes
    assert orders.heard("ego", ThrustCmd((0.5, 0.5)))
    assert orders.in_force("ego") == ThrustCmd((0.5, 0.5)) and not orders.follows_script("ego")


def test_an_outside_command_outranks_a_set_point_until_released() -> None:
    orders = Orders()
    set_point = TwistCmd(1.0, 0.0, 4, 40_000_000)
    orders.heard("ego", set_point)
    orders.heard("ego", TwistCmd(0.0, 0.1))  # tick -1: from outside
    orders.heard("ego", TwistCmd(2.0, 0.0, 5, 50_000_000))  # a later set-point: still held
    assert orders.in_force("ego") == TwistCmd(0.0, 0.1)
    assert orders.heard("ego", PATH)  # a path releases as a release does
    assert orders.in_force("ego") == TwistCmd(2.0, 0.0, 5, 50_000_000)


def test_a_set_point_steers_for_good_and_other_messages_change_nothing() -> None:
    orders = Orders()
    orders.heard("ego", TwistCmd(1.0, 0.0, 0, 0))
    assert not orders.heard("ego", RELEASE)
    assert not orders.follows_script("ego")
    zero = (0.0, 0.0, 0.0)
    state = VesselState(0, 0, zero, (0.0, 0.0, 0.0, 1.0), zero, zero, zero, zero)
    assert not orders.heard("ego", state)
    assert orders.follows_script("other")
