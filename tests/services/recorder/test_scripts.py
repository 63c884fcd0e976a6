"""Script steps become the commands physics follows, at the tick it follows them."""

from __future__ import annotations

from catabot.bus.messages import ThrustCmd, TwistCmd, WaypointsCmd
from catabot.config.load import parse_scenario
from catabot.world.orders import Orders
from catabot.world.world import World
from services.recorder.scripts import ScriptedCommands

SCRIPT = [
    {"t_s": 0.0, "thrust": [0.1, 0.1]},
    {"t_s": 0.015, "thrust": [0.2, 0.2]},  # between ticks 1 and 2: applied at tick 2
    {"t_s": 0.02, "thrust": [0.3, 0.3]},  # the same tick: this one wins (physics follows it)
    {"t_s": 0.05, "twist": {"surge_mps": 1.0, "yaw_rate_radps": -0.5}},
]


def test_steps_land_on_the_first_tick_at_or_after_their_time() -> None:
    world = World.resolve(parse_scenario({"vessels": [{"id": "ego", "script": SCRIPT}]}))
    scripts = ScriptedCommands(world, Orders())
    due = {k: scripts.due(k, k * 10_000_000) for k in range(8)}
    assert due[0] == [("vessel/ego/cmd/thrust", ThrustCmd((0.1, 0.1), 0, 0))]
    assert due[2] == [("vessel/ego/cmd/thrust", ThrustCmd((0.3, 0.3), 2, 20_000_000))]
    assert due[5] == [("vessel/ego/cmd/twist", TwistCmd(1.0, -0.5, 5, 50_000_000))]
    assert [k for k, d in due.items() if d] == [0, 2, 5]


def test_a_vessel_taken_over_from_the_bus_is_not_written_as_following_its_script() -> None:
    """Physics' precedence (catabot/world/orders.py): an outside thrust or twist holds the
    vessel until a WaypointsCmd hands it back; a lockstep set-point holds it for good."""
    world = World.resolve(parse_scenario({"vessels": [{"id": "ego", "script": SCRIPT}]}))
    orders = Orders()
    scripts = ScriptedCommands(world, orders)
    orders.heard("ego", ThrustCmd((0.9, 0.9)), stamp_ns=0)  # from outside: tick -1
    assert scripts.due(2, 20_000_000) == []
    orders.heard("ego", WaypointsCmd((), 1.0, 1.0, "release"), stamp_ns=0)
    assert scripts.due(2, 20_000_000) == [
        ("vessel/ego/cmd/thrust", ThrustCmd((0.3, 0.3), 2, 20_000_000))
    ]
    orders.heard("ego", TwistCmd(1.0, 0.0, 3, 30_000_000), stamp_ns=0)  # lockstep
    orders.heard("ego", WaypointsCmd((), 1.0, 1.0, "release"), stamp_ns=0)
    assert scripts.due(5, 50_000_000) == []


def test_a_boat_an_outside_command_holds_is_marked_until_a_path_or_release() -> None:
    world = World.resolve(parse_scenario({"vessels": [{"id": "ego"}], "traffic": {"count": 3}}))
    orders, boats = Orders(), world.boat_ids
    scripts = ScriptedCommands(world, orders)
    orders.heard("boat_001", TwistCmd(0.0, 0.0), stamp_ns=0)  # tick -1: from outside
    assert scripts.taken(boats).tolist() == [False, True, False]
    orders.heard("boat_001", WaypointsCmd((), 1.0, 1.0, "release"), stamp_ns=0)
    assert not scripts.taken(boats).any()


def test_a_release_writes_the_order_the_vessel_follows_again() -> None:
    """After a release physics follows the script's step in force (or rest before the
    first): the thrust CSV used to keep the outside command as its last row."""
    world = World.resolve(parse_scenario({"vessels": [
        {"id": "ego", "script": SCRIPT}, {"id": "plain"}]}))  # fmt: skip
    scripts = ScriptedCommands(world, Orders())
    assert scripts.resumed("ego", 3, 30) == ("vessel/ego/cmd/thrust", ThrustCmd((0.3, 0.3), 3, 30))
    assert scripts.resumed("ego", 9, 90) == ("vessel/ego/cmd/twist", TwistCmd(1.0, -0.5, 9, 90))
    assert scripts.resumed("ego", 5, 50) is None  # a step begins then: `due` writes it
    assert scripts.resumed("plain", 3, 30) == (
        "vessel/plain/cmd/thrust", ThrustCmd((0.0, 0.0), 3, 30))  # fmt: skip
