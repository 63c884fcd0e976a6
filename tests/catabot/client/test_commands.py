"""Commands are checked in the stack, before they leave: the checks physics would apply
(catabot/bus/checks.py) with the vessel's own thruster count, as a CommandError."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.bus.messages import ThrustCmd, TwistCmd, WaypointsCmd
from catabot.client import CommandError, Thrust, Twist, Waypoints
from catabot.client.commands import Command, kind_of, message
from catabot.client.info import parse
from catabot.world.world import World
from tests.catabot.client.fixtures import answer, scenario

EGO = parse(answer(), "test").vessels["ego"]
NAN, INF = float("nan"), float("inf")


def test_good_commands_become_their_messages() -> None:
    assert message(Thrust([0.5, -1]), EGO, tick=10, stamp_ns=100) == ThrustCmd((0.5, -1.0), 10, 100)
    assert message(Twist(1.0, -0.2), EGO) == TwistCmd(1.0, -0.2, -1, 0)
    way = message(Waypoints([(10, 0), (20, 5)], speed=1.5), EGO)
    assert way == WaypointsCmd((10.0, 0.0, 20.0, 5.0), 1.5, 2.0, "back_and_forth", -1, 0)
    planned = np.array([[10.0, 0.0], [20.0, 5.0]])  # a planner's output
    assert message(Waypoints(planned, speed=1.5), EGO) == way  # type: ignore[arg-type]
    assert message(Waypoints(list(planned), speed=1.5), EGO) == way
    assert message(Waypoints([], mode="release"), EGO).mode == "release"  # type: ignore[attr-defined]
    assert [kind_of(c) for c in (Thrust([0, 0]), Twist(0, 0), Waypoints([]))] == [
        "thrust", "twist", "waypoints"]  # fmt: skip


@pytest.mark.parametrize(
    ("command", "why"),
    [
        (Thrust([0.5]), "thrust command for vessel 'ego': 1 values for 2 thrusters"),
        (Thrust([0.5, 0.5, 0.5]), "3 values for 2 thrusters"),
        (Thrust([NAN, 0.0]), "a thrust value is not finite"),
        (Thrust([5.0, -7.0]), r"normalised, each in \[-1, 1\]: \(5.0, -7.0\)"),
        (Thrust([1.0, -1.0001]), r"each in \[-1, 1\]"),
        (Thrust(["fast", 0.0]), "a value must be a number, not str 'fast'"),  # type: ignore[list-item]
        (Twist("1", 0.0), "surge must be a number, not str '1'"),  # type: ignore[arg-type]
        (Twist(1.0, True), "yaw_rate must be a number, not bool"),
        (Waypoints([(1, "2")]), "points.0's y must be a number"),  # type: ignore[list-item]
        (Twist(INF, 0.0), "twist command for vessel 'ego': surge inf m/s"),
        (Twist(1.0, NAN), "not finite"),
        (Twist(1e308, 0.0), "surge 1e[+]308 m/s: at most 50 m/s either way"),
        (Twist(-50.5, 0.0), "at most 50 m/s"),
        (Twist(1.0, 7.0), r"yaw rate 7.0 rad/s: at most 2π \(6.283\) rad/s"),
        (Waypoints([(1, 2)], speed=1e308), "speed 1e[+]308 m/s and tolerance 2.0 m: at most 50"),
        (Waypoints([(1, 2)], tolerance=5e3), "at most 50 m/s and 1000 m"),
        (Waypoints([(1e300, 2)]), "each coordinate within ±1e[+]07 m of the origin"),
        (Waypoints([(1, 2, 3)]), r"points.0: a waypoint is \(x, y\) in m, not \(1, 2, 3\)"),
        (
            Waypoints([10, 0, 20, 0]),  # type: ignore[list-item]
            r"points.0: a waypoint is \(x, y\) in m, not 10; give points as \[\(x0, y0\), ",
        ),  # it said "object of type 'int' has no len()"
        (
            Waypoints([], mode="loop"),
            r"points: give at least one \(x, y\) point, or mode 'release'",
        ),
        (Waypoints([(1, 2)], speed=0), "speed 0.0 must be a finite number >= 0.01"),
        (Waypoints([(1, 2)], tolerance=-1), "tolerance -1.0 must be a finite number >= 0.1"),
        (Waypoints([(1, 2)], tolerance=1e-300), "tolerance 1e-300 must be"),  # circles for ever
        (Waypoints([(1, 2)], speed=5e-324), "speed 5e-324 must be"),  # parks the boat
        (Waypoints([(1, NAN)]), r"points.0: \(1.0, nan\) is not finite"),  # not the wire's words
        (Waypoints([(1, 2)], mode="zigzag"), "mode 'zigzag' is not one of"),
        (Waypoints([(k, 0) for k in range(1001)]), "1001 waypoints: at most 1000 in one path"),
    ],
)
def test_bad_commands_are_refused_in_the_stack(command: Command, why: str) -> None:
    with pytest.raises(CommandError, match=why):
        message(command, EGO)


def test_something_else_is_no_command() -> None:
    with pytest.raises(CommandError, match="ThrustCmd is not a command: send Thrust, Twist"):
        kind_of(ThrustCmd((0.0, 0.0)))  # type: ignore[arg-type]


def test_the_bus_refuses_every_free_command_for_a_vessel_a_controller_drives() -> None:
    """Any client may publish, not only ours: the streams' own checks (what physics and the
    recorder apply at the sample) refuse a free twist, thrust or path for a vessel whose
    lockstep controller drives it, and nothing for a vessel without one."""
    world = World.resolve(scenario())
    checks = {s.key: s.check for s in [*world.streams.commands, *world.streams.waypoints]}
    keys = world.keys
    for key, msg in (
        (keys.cmd_thrust("ego"), ThrustCmd((0.5, 0.5))),
        (keys.cmd_waypoints("ego"), WaypointsCmd((1.0, 2.0), 1.0, 2.0, "loop")),
    ):
        check = checks[key]
        assert check is not None
        with pytest.raises(ValueError, match="'ego' is driven in lockstep by 'stack' \\(twist"):
            check(msg)
    other = checks[keys.cmd_thrust("other")]
    assert other is not None
    other(ThrustCmd((0.5, 0.5)))
    with pytest.raises(ValueError, match="normalised"):
        other(ThrustCmd((1.5, 0.5)))


def test_a_path_is_for_traffic_boats_a_scenario_vessel_takes_only_a_release() -> None:
    """A path sent to the ego was accepted and then silently had no effect."""
    world = World.resolve(scenario())
    checks = {s.key: s.check for s in world.streams.waypoints}
    path = WaypointsCmd((1.0, 2.0, 3.0, 4.0), 1.0, 2.0, "loop")
    ego_free = checks[world.keys.cmd_waypoints("other")]
    assert ego_free is not None
    with pytest.raises(ValueError, match="'other' is a scenario vessel: it follows no path"):
        ego_free(path)
    ego_free(WaypointsCmd((), 1.0, 1.0, "release"))
    boat = checks[world.keys.cmd_waypoints("boat_000")]
    assert boat is not None
    boat(path)
