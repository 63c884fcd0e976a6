"""The commands a stack sends: Thrust, Twist, Waypoints, checked before they leave.

Physics refuses a command it cannot take (catabot/bus/checks.py) and logs why; a stack would
only see its vessel not move. So the client runs the same checks on the message it is
about to send, with this vessel's thruster count, and raises `CommandError` in the stack.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from catabot.bus import checks
from catabot.bus.messages import Message, ThrustCmd, TwistCmd, WaypointsCmd
from catabot.client.errors import CommandError
from catabot.client.info import VesselInfo


@dataclass(frozen=True)
class Thrust:
    """One value per thruster, -1 (full reverse) .. 1 (full forward); the vessel's
    `thrusters` tells how many (the catamaran: 0 port, 1 starboard)."""

    values: Sequence[float]


@dataclass(frozen=True)
class Twist:
    """Surge speed (m/s, forward) and yaw rate (rad/s, positive turns left) for the
    vessel's velocity controller."""

    surge: float
    yaw_rate: float


@dataclass(frozen=True)
class Waypoints:
    """A path in `map` (ENU, m) to follow at `speed` m/s, each point reached within
    `tolerance` m; `mode` "back_and_forth", "loop", or "release" (hand the vessel back)."""

    points: Sequence[tuple[float, float]]
    speed: float = 1.0
    tolerance: float = 2.0
    mode: str = "back_and_forth"


Command = Thrust | Twist | Waypoints
KINDS: dict[type, str] = {Thrust: "thrust", Twist: "twist", Waypoints: "waypoints"}


def kind_of(command: Command) -> str:
    kind = KINDS.get(type(command))
    if kind is None:
        raise CommandError(
            f"{type(command).__name__} is not a command: send Thrust, Twist or Waypoints "
            "(catabot.client)"
        )
    return kind


def message(command: Command, vessel: VesselInfo, *, tick: int = -1, stamp_ns: int = 0) -> Message:
    """The bus message of `command` for `vessel`, checked as physics will check it."""
    kind = kind_of(command)
    try:
        if isinstance(command, Thrust):
            msg: Message = ThrustCmd(_floats(command.values), tick, stamp_ns)
            checks.thrust(vessel.thrusters)(msg)
        elif isinstance(command, Twist):
            surge, rate = _number(command.surge, "surge"), _number(command.yaw_rate, "yaw_rate")
            msg = TwistCmd(surge, rate, tick, stamp_ns)
            checks.twist(msg)
        else:
            assert isinstance(command, Waypoints)
            points = _path(command)
            speed, tol = _number(command.speed, "speed"), _number(command.tolerance, "tolerance")
            msg = WaypointsCmd(points, speed, tol, str(command.mode), tick, stamp_ns)
            checks.waypoints(msg)
    except (TypeError, ValueError) as exc:
        raise CommandError(f"{kind} command for vessel {vessel.id!r}: {exc}") from None
    return msg


def _number(value: object, what: str) -> float:
    """A real number as a float: float("1") had turned a string into a command that the
    bus refuses from anyone else (and True into 1.0)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{what} must be a number, not {type(value).__name__} {value!r}")
    return float(value)


def _floats(values: Sequence[float]) -> tuple[float, ...]:
    return tuple(_number(v, "a value") for v in values)


def _path(command: Waypoints) -> tuple[float, ...]:
    """The points as the wire's flat x0, y0, x1, ... after checking them as given: the
    bus's words for a flat list ("need x0, y0, x1, ...") answered a list of pairs."""
    pairs = [_pair(i, p) for i, p in enumerate(list(command.points))]
    if not pairs and command.mode != "release":
        raise ValueError("points: give at least one (x, y) point, or mode 'release'")
    for i, (x, y) in enumerate(pairs):
        if not (math.isfinite(x) and math.isfinite(y)):
            raise ValueError(f"points.{i}: ({x}, {y}) is not finite")
    return tuple(c for pair in pairs for c in pair)


def _pair(i: int, point: Any) -> tuple[float, float]:
    """A pair: a tuple, a list or a NumPy row (a planner's output is an array)."""
    if isinstance(point, str | bytes) or not hasattr(point, "__len__") or len(point) != 2:
        raise ValueError(f"points.{i}: a waypoint is (x, y) in m, not {point!r}; give "
                         "points as [(x0, y0), (x1, y1), ...]")  # fmt: skip
    return _number(point[0], f"points.{i}'s x"), _number(point[1], f"points.{i}'s y")
