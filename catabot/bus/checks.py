"""What each stream of a world may carry, checked where a sample arrives (`Stream.check`).

The codec has already checked every field's type; these check what only the world knows
(which bodies, how many thrusters) and values the services cannot use (a NaN command, a
path with an odd number of coordinates). A sample that fails is refused and counted by the
receiving participant (catabot/bus/inbox.py), so no step ever sees it. They live in the bus
layer because a client (catabot/client/) runs the same checks on what it is about to send,
so a bad command is an error in the stack's own process, not a silent drop in physics.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from catabot.bus.codec import finite
from catabot.bus.messages import (
    BodyStates,
    ThrustCmd,
    TwistBatch,
    TwistCmd,
    WaypointsCmd,
    check_ids,
)

Check = Callable[[Any], None]
PATH_MODES = ("loop", "back_and_forth", "release")
MAX_WAYPOINTS = 1000  # a path widens the traffic's path table for every boat (10^6 stalled it)
# Finite is not enough: a surge of 1e308 m/s overflowed the velocity controller to a NaN
# thrust, refused every tick after the command had been accepted and recorded.
MAX_SPEED_MPS = 50.0  # faster than any surface vessel CataBot models
MAX_RATE_RADPS = 2 * math.pi  # a turn a second
MAX_COORDINATE_M = 1e7  # a waypoint within 10 000 km of the world's origin
MAX_TOLERANCE_M = 1e3
MIN_TOLERANCE_M = 0.1  # 1e-300 was taken: a boat steering for a point that close circles it
MIN_PATH_SPEED_MPS = 0.01  # slower, a path parks the boat (5e-324 m/s was taken)


def body_states(ids: tuple[str, ...]) -> Check:
    """Every body of the world, in its rows, with arrays of the right shapes."""

    def check(msg: BodyStates) -> None:
        check_ids("world/states", msg.tick, msg.ids, ids)
        n = len(ids)
        for name, width in (("position", 3), ("orientation", 4), ("linear_velocity", 3)):
            value = getattr(msg, name)
            if value.shape != (n, width) or value.dtype != np.float64:
                raise ValueError(
                    f"{name} is {value.dtype} {value.shape}, not float64 ({n}, {width})"
                )
        for value in msg.arrays()[3:]:
            if value.shape != (n, 3):
                raise ValueError(f"a velocity or acceleration array is {value.shape}, not ({n}, 3)")

    return check


def twist_batch(boats: tuple[str, ...]) -> Check:
    def check(msg: TwistBatch) -> None:
        msg.check(boats)

    return check


def thrust(thrusters: int) -> Check:
    """One finite value in [-1, 1] per thruster. Refused, not clamped: what is recorded is
    what physics applied, as for a scenario's script and the ROS gateway's commands."""

    def check(msg: ThrustCmd) -> None:
        if len(msg.thrust) != thrusters:
            raise ValueError(f"{len(msg.thrust)} values for {thrusters} thrusters")
        if not finite(msg.thrust):
            raise ValueError(f"a thrust value is not finite: {msg.thrust}")
        if not all(-1.0 <= v <= 1.0 for v in msg.thrust):
            raise ValueError(f"thrust values are normalised, each in [-1, 1]: {msg.thrust}")

    return check


def twist(msg: TwistCmd) -> None:
    if not finite((msg.surge, msg.yaw_rate)):
        raise ValueError(f"surge {msg.surge} m/s, yaw rate {msg.yaw_rate} rad/s: not finite")
    if abs(msg.surge) > MAX_SPEED_MPS:
        raise ValueError(f"surge {msg.surge} m/s: at most {MAX_SPEED_MPS:g} m/s either way")
    if abs(msg.yaw_rate) > MAX_RATE_RADPS:
        raise ValueError(f"yaw rate {msg.yaw_rate} rad/s: at most 2π (6.283) rad/s either way")


def waypoints(msg: WaypointsCmd) -> None:
    """A release, or a path of finite points x0, y0, x1, y1, ... with speed and tolerance > 0."""
    if msg.mode not in PATH_MODES:
        raise ValueError(f"mode {msg.mode!r} is not one of {PATH_MODES}")
    if msg.mode == "release":
        return
    pts = msg.points
    if len(pts) < 2 or len(pts) % 2 or not finite(pts):
        raise ValueError("points: need x0, y0, x1, ...: an even number of finite values")
    if len(pts) > 2 * MAX_WAYPOINTS:
        raise ValueError(f"{len(pts) // 2} waypoints: at most {MAX_WAYPOINTS} in one path")
    if max(abs(v) for v in pts) > MAX_COORDINATE_M:
        raise ValueError(f"points: each coordinate within ±{MAX_COORDINATE_M:g} m of the origin")
    for name, value, least in (("speed", msg.speed, MIN_PATH_SPEED_MPS),
                               ("tolerance", msg.tolerance, MIN_TOLERANCE_M)):  # fmt: skip
        if not (finite(value) and value >= least):  # the one that is wrong, named alone
            raise ValueError(f"{name} {value} must be a finite number >= {least:g}")
    if msg.speed > MAX_SPEED_MPS or msg.tolerance > MAX_TOLERANCE_M:
        raise ValueError(
            f"speed {msg.speed} m/s and tolerance {msg.tolerance} m: at most "
            f"{MAX_SPEED_MPS:g} m/s and {MAX_TOLERANCE_M:g} m"
        )


def driven(vessel: str, participant: str, command: str, *, kind: str) -> Check:
    """Every free `kind` command refused for a vessel a lockstep controller drives: whoever
    sent it would change a run that is to be reproducible (the controller's own key is
    clocked: only its participant may produce it)."""

    def check(_msg: Any) -> None:
        raise ValueError(
            f"vessel {vessel!r} is driven in lockstep by {participant!r} ({command}): a free "
            f"{kind} command would change the run"
        )

    return check


def release_only(vessel: str) -> Check:
    """A scenario vessel takes a release (it ends an outside thrust or twist) but no path:
    physics follows paths for traffic boats only, and a path sent to the ego was accepted
    and then silently had no effect."""

    def check(msg: WaypointsCmd) -> None:
        waypoints(msg)
        if msg.mode != "release":
            raise ValueError(
                f"{vessel!r} is a scenario vessel: it follows no path from the bus (traffic "
                'boats do); mode "release" hands it back to its script'
            )

    return check
