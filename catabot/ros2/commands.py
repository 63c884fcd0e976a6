"""ROS 2 commands back to bus messages, checked at the sample (anything from the bus may
come from a buggy or hostile client): `cmd_vel` (geometry_msgs/Twist) -> TwistCmd,
`thrust` (std_msgs/Float64MultiArray) -> ThrustCmd, `waypoints` (nav_msgs/Path) ->
WaypointsCmd. A payload that is not CDR of the topic's type, or values out of range, raise
CommandError naming what is wrong; the gateway logs it and goes on.

A Twist drives the velocity controller with linear.x (surge, m/s) and angular.z (yaw rate,
rad/s); its other four values have no meaning for a surface vessel and are ignored. A Path
gives its poses' x, y in `map` (its header's frame must be `map` or empty) with the speed,
tolerance and mode of `ros.waypoints`; an empty Path hands the vessel back to its scenario.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from catabot.bus.messages import Message, ThrustCmd, TwistCmd, WaypointsCmd
from catabot.config.ros import WaypointDefaults
from catabot.errors import CataBotError
from catabot.ros2 import types
from catabot.ros2.cdr import ENCAPSULATION
from catabot.ros2.names import MAP

MAX_PAYLOAD = 1 << 20  # a Path of ~8000 poses; anything bigger is not a command
MAX_WAYPOINTS = 1000
MAX_SURGE_MPS = 50.0  # plausible set-points: a command beyond them is a wrong payload, not
MAX_YAW_RATE_RADPS = 2 * math.pi  # an order (the controller clamps what thrust can do)
MAX_COORDINATE_M = 1e7
STAMPED = "geometry_msgs/msg/TwistStamped"  # refused on cmd_vel, by name


class CommandError(CataBotError, ValueError):
    """A command payload that cannot be taken (malformed, wrong type, out of range)."""


class Malformed(CommandError):
    """A payload that is not CDR of the topic's type (as against values out of range)."""


def decode(payload: bytes, typename: str) -> Any:
    """The message in `payload`, strictly: CDR little-endian of `typename` and nothing else
    (re-encoding it gives the payload back, but for the final padding to a 4-byte boundary:
    a Twist's 52 bytes take none, so a String one byte longer no longer read as a Twist)."""
    if len(payload) > MAX_PAYLOAD:
        raise Malformed(f"{len(payload)} bytes: too big for a {typename}")
    if payload[:4] != ENCAPSULATION:
        raise Malformed(f"not little-endian CDR (header {payload[:4].hex() or 'missing'})")
    try:
        msg = types.deserialize(payload, typename)
        again = types.serialize(msg, typename)
    except Exception as exc:  # rosbags raises several types for truncated or garbled data
        raise Malformed(f"not a {typename}: {type(exc).__name__}: {exc}") from None
    if len(payload) - len(again) not in (0, -len(again) % 4) or payload[: len(again)] != again:
        raise Malformed(f"not a {typename} ({len(payload)} bytes, {len(again)} expected)")
    return msg


def twist(payload: bytes) -> TwistCmd:
    try:
        msg = decode(payload, types.TWIST)
    except Malformed as exc:
        raise Malformed(f"{exc}{_stamped_hint(payload)}") from None
    surge, yaw_rate = float(msg.linear.x), float(msg.angular.z)
    if not (math.isfinite(surge) and math.isfinite(yaw_rate)):  # "out of range: nan" read oddly
        raise CommandError(f"twist not finite: linear.x {surge}, angular.z {yaw_rate}")
    if not (abs(surge) <= MAX_SURGE_MPS and abs(yaw_rate) <= MAX_YAW_RATE_RADPS):
        raise CommandError(
            f"twist out of range: linear.x {surge} (|x| <= {MAX_SURGE_MPS} m/s), angular.z "
            f"{yaw_rate} (|z| <= {MAX_YAW_RATE_RADPS:.4f} rad/s)"
        )
    return TwistCmd(surge=surge, yaw_rate=yaw_rate)


def _stamped_hint(payload: bytes) -> str:
    """Newer Nav2 may publish TwistStamped on cmd_vel: said so, not only "size mismatch"."""
    try:
        decode(payload, STAMPED)
    except Malformed:
        return ""
    return (f"; it is a {STAMPED}: cmd_vel takes {types.TWIST} (Nav2: "
            "enable_stamped_cmd_vel: false)")  # fmt: skip


def thrust(payload: bytes, thrusters: int) -> ThrustCmd:
    values = np.asarray(decode(payload, types.FLOAT64_ARRAY).data, dtype=np.float64)
    if len(values) != thrusters:
        raise CommandError(f"{len(values)} thrust values for {thrusters} thrusters")
    if not (np.isfinite(values).all() and (np.abs(values) <= 1.0).all()):
        raise CommandError(f"thrust values must be finite and in [-1, 1] (got {values.tolist()})")
    return ThrustCmd(thrust=tuple(values.tolist()))


def waypoints(payload: bytes, defaults: WaypointDefaults) -> WaypointsCmd:
    msg = decode(payload, types.PATH)
    if msg.header.frame_id not in ("", MAP):
        raise CommandError(f"a path in frame {msg.header.frame_id!r}: give it in {MAP!r}")
    if len(msg.poses) > MAX_WAYPOINTS:
        raise CommandError(f"{len(msg.poses)} poses: at most {MAX_WAYPOINTS}")
    for pose in msg.poses:
        if pose.header.frame_id not in ("", MAP):
            raise CommandError(f"a pose in frame {pose.header.frame_id!r}: give it in {MAP!r}")
    points = [v for p in msg.poses for v in (float(p.pose.position.x), float(p.pose.position.y))]
    if not all(abs(v) <= MAX_COORDINATE_M for v in points):  # NaN fails too
        raise CommandError(f"a waypoint beyond {MAX_COORDINATE_M:g} m or not finite")
    if not points:
        return WaypointsCmd(points=(), speed=0.0, tolerance=0.0, mode="release")
    return WaypointsCmd(
        points=tuple(points),
        speed=defaults.speed_mps,
        tolerance=defaults.tolerance_m,
        mode=defaults.mode,
    )


def command(name: str, payload: bytes, *, thrusters: int, defaults: WaypointDefaults) -> Message:
    """The bus message of a payload on command topic `name` (names.COMMANDS)."""
    if name == "cmd_vel":
        return twist(payload)
    if name == "thrust":
        return thrust(payload, thrusters)
    if name == "waypoints":
        return waypoints(payload, defaults)
    raise CommandError(f"no command named {name!r}")
