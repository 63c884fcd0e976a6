"""The `ros` section of a scenario: the ROS 2 gateway (services/ros, DESIGN.md §8).

With a `ros` section `catabot run` starts the gateway, which publishes the world as ROS 2
topics on Zenoh and takes `cmd_vel`, `thrust` and `waypoints` back, in the key convention of
`zenoh-bridge-ros2dds`, of `rmw_zenoh` or both. Names are checked here, before anything
starts: a ROS name that a ROS tool refuses would otherwise surface as a topic nobody sees.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any, Literal

from pydantic import Field, StrictBool, StrictInt, field_validator

from catabot.config.base import FieldProblem, Strict

GATEWAY = "ros"  # the gateway's service and participant name
_TOKEN = r"[A-Za-z_][A-Za-z0-9_]*"
_NAMESPACE = re.compile(rf"^/?({_TOKEN}(/{_TOKEN})*)?/?$")
_NODE = re.compile(rf"^{_TOKEN}$")


def ros_token(name: str) -> bool:
    """Whether `name` can be one token of a ROS 2 name (a namespace, node or topic part)."""
    return bool(_NODE.match(name))


def namespace(text: str) -> str:
    """A ROS namespace in its canonical form: '/' for none, else '/a/b' (no trailing '/')."""
    if not _NAMESPACE.match(text):
        raise ValueError(
            f"{text!r} is not a ROS namespace: '/'-separated tokens of letters, digits and "
            "'_', none starting with a digit"
        )
    return "/" + text.strip("/")


class WaypointDefaults(Strict):
    """What a `nav_msgs/Path` does not say about the path it gives (WaypointsCmd fields)."""

    speed_mps: float = Field(2.0, gt=0, description="speed along a path from ROS")
    tolerance_m: float = Field(2.0, gt=0, description="a point is reached within this")
    mode: Literal["loop", "back_and_forth"] = "back_and_forth"


class RosConfig(Strict):
    mode: Literal["bridge", "rmw_zenoh", "both"] = Field(
        "both", description="key convention: zenoh-bridge-ros2dds, rmw_zenoh (Jazzy+), or both"
    )
    lockstep: StrictBool = Field(
        False,
        description="join the lockstep: nothing is dropped, and vessels whose controller is "
        "'ros' take ROS commands at the same tick on every run",
    )
    domain_id: StrictInt = Field(0, ge=0, le=232, description="ROS_DOMAIN_ID (rmw_zenoh keys)")
    bridge_namespace: str = Field(
        "/", description="the bridge's own namespace (its -n flag): prefixes every bridge key"
    )
    namespaces: dict[str, str] = Field(
        {}, description="vessel id -> ROS namespace (default '/<id>'; '/' for the root)"
    )
    clock_hz: float | None = Field(None, gt=0, description="/clock rate; null: every tick")
    traffic: StrictBool = Field(True, description="publish every traffic boat's odom too")
    node: str = Field("catabot", description="the ROS node name in the graph")
    reply_timeout_s: float = Field(
        5.0, gt=0, description="lockstep: wait this long for a controller's command per period"
    )
    waypoints: WaypointDefaults = WaypointDefaults()

    @field_validator("bridge_namespace")
    @classmethod
    def _bridge_namespace(cls, v: str) -> str:
        return namespace(v)

    @field_validator("namespaces")
    @classmethod
    def _namespaces(cls, v: dict[str, str]) -> dict[str, str]:
        return {vessel: namespace(ns) for vessel, ns in v.items()}

    @field_validator("node")
    @classmethod
    def _node(cls, v: str) -> str:
        if not ros_token(v):
            raise ValueError(f"{v!r} is not a ROS node name (letters, digits, '_')")
        return v

    def namespace_of(self, vessel: str) -> str:
        return self.namespaces.get(vessel, "/" + vessel)


def check_ros(
    ros: RosConfig | None, vessels: Sequence[Any], boats: Sequence[str], deadline_s: float
) -> None:
    """The cross-section rules (FieldProblem names the field): every vessel and sensor name
    is a ROS name (they name topics), namespaces name known vessels and no two vessels share
    one, a controller named 'ros' needs the gateway in the lockstep, and the gateway's wait
    for a reply ends before the clock's deadline would end the run."""
    for i, vessel in enumerate(vessels):
        c = vessel.controller
        if c is not None and c.participant == GATEWAY and not (ros and ros.lockstep):
            raise FieldProblem(
                f"vessels.{i}.controller.participant",
                f'{GATEWAY!r} is the ROS gateway: add "ros": {{"lockstep": true}}',
            )
    if ros is None:
        return
    if ros.lockstep and ros.reply_timeout_s >= deadline_s:
        raise FieldProblem(
            "ros.reply_timeout_s", f"must be below clock.deadline_s ({deadline_s} s)"
        )
    ids = [v.id for v in vessels]
    for i, vessel in enumerate(vessels):
        for j, sensor in enumerate(vessel.sensors):
            if not ros_token(sensor.name):
                raise FieldProblem(f"vessels.{i}.sensors.{j}.name", _not_ros(sensor.name))
    for vessel in ros.namespaces:
        if vessel not in ids and vessel not in boats:
            raise FieldProblem(f"ros.namespaces.{vessel}", "names no vessel or traffic boat")
    for i, vessel_id in enumerate(ids):
        if vessel_id not in ros.namespaces and not ros_token(vessel_id):
            raise FieldProblem(f"vessels.{i}.id", _not_ros(vessel_id) + " (or set ros.namespaces)")
    spaces = [ros.namespace_of(v) for v in [*ids, *boats]]
    shared = sorted({ns for ns in spaces if spaces.count(ns) > 1})
    if shared:
        raise FieldProblem("ros.namespaces", f"two vessels share the namespace {shared[0]!r}")


def _not_ros(name: str) -> str:
    return f"{name!r} names ROS topics: use letters, digits and '_', not starting with a digit"
