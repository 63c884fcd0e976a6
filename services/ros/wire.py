"""The gateway's side of Zenoh: one `Outlet` per ROS topic, in every convention of
`ros.mode`, with the graph tokens that make `ros2 topic list` show it (catabot/ros2/wire.py
says what each convention expects).

Outlets put only while someone subscribes to their key (a matching listener keeps that
known, as physics does for observer outputs): with nobody listening the gateway costs the
conversion of what it must convert and no put. Puts never block (congestion control DROP):
a slow ROS subscriber must not hold the simulation. Latched topics (`/tf_static`, `/buoys`)
are advanced publishers with a cache of one, which both the bridge and rmw_zenoh query for
their TRANSIENT_LOCAL subscribers, so a late subscriber still gets the message.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

import zenoh
from zenoh.ext import CacheConfig, declare_advanced_publisher

from catabot.config.ros import RosConfig
from catabot.ros2.wire import (
    DATA,
    Convention,
    Qos,
    RmwNode,
    attachment,
    bridge_key,
    bridge_token,
    conventions,
    gid,
    rmw_key,
)


class Wire:
    """The gateway's Zenoh presence: its node in the ROS graph and its tokens."""

    def __init__(self, session: zenoh.Session, ros: RosConfig) -> None:
        self.session, self.ros = session, ros
        self.conventions = conventions(ros.mode)
        self.zid = str(session.zid())
        self.node = RmwNode(ros.domain_id, self.zid, ros.node)
        self._entities = 0
        self._tokens: list[Any] = []
        self.version = 0  # counts changes of who subscribes to what (Outlet.sends)
        if Convention.RMW in self.conventions:
            self._declare(self.node.token())

    def key(self, convention: Convention, topic: str, typename: str) -> str:
        if convention is Convention.BRIDGE:
            return bridge_key(topic, self.ros.bridge_namespace)
        return rmw_key(self.ros.domain_id, topic, typename)

    def announce(
        self, convention: Convention, kind: str, topic: str, typename: str, qos: Qos
    ) -> str:
        """Declare the graph token of a publisher (MP) or subscription (MS); returns it."""
        if convention is Convention.BRIDGE:
            key = self.key(convention, topic, typename)
            token = bridge_token(self.zid, kind, key, typename, qos)
        else:
            self._entities += 1
            token = self.node.entity_token(self._entities, kind, topic, typename, qos)
        self._declare(token)
        return token

    def _declare(self, token: str) -> None:
        self._tokens.append(self.session.liveliness().declare_token(token))

    def close(self) -> None:
        for token in self._tokens:
            token.undeclare()
        self._tokens.clear()


class _Route:
    """One convention's key of an outlet: its publisher and, for rmw_zenoh, the attachment.
    `on_change` runs (on a Zenoh thread) when a first subscriber comes or the last goes."""

    def __init__(
        self,
        wire: Wire,
        convention: Convention,
        topic: str,
        typename: str,
        qos: Qos,
        on_change: Callable[[], None],
    ) -> None:
        self._on_change = on_change
        key = wire.key(convention, topic, typename)
        token = wire.announce(convention, "MP", topic, typename, qos)
        self.gid = gid(token) if convention is Convention.RMW else b""
        self.sequence = 0
        if qos.transient_local:
            self.publisher: Any = declare_advanced_publisher(
                wire.session, key, cache=CacheConfig(qos.depth), publisher_detection=True
            )
            self.matching = True  # always put: the cache must hold the latest
        else:
            self.publisher = wire.session.declare_publisher(key)
            self.matching = bool(self.publisher.matching_status.matching)
            self.listener = self.publisher.declare_matching_listener(self._on_matching)

    def _on_matching(self, status: Any) -> None:
        self.matching = bool(status.matching)
        self._on_change()

    def put(self, data: bytes) -> None:
        if not self.gid:
            self.publisher.put(data)
            return
        self.sequence += 1
        self.publisher.put(data, attachment=attachment(self.sequence, time.time_ns(), self.gid))


class Outlet:
    """One ROS topic of one type, published in every convention of the gateway. `sends` (a
    put per route someone subscribes to: the publisher's own for the bridge, one adding the
    attachment for rmw_zenoh) is kept by the matching listeners, so a tick asks nothing of
    Zenoh for a topic nobody watches, and a put is one Python call (101 odometry a tick)."""

    def __init__(self, wire: Wire, topic: str, typename: str, qos: Qos = DATA) -> None:
        self.topic, self.type, self.wire = topic, typename, wire
        self.sends: list[Callable[[bytes], None]] = []
        self._lock, self._ready = threading.Lock(), False  # listeners fire from Zenoh's threads
        self.routes = [
            _Route(wire, c, topic, typename, qos, self._refresh) for c in wire.conventions
        ]
        with self._lock:
            self._ready = True
        self._refresh()

    def _refresh(self) -> None:
        """One refresh at a time, none before every route is made: a listener that fired
        while they were made (a ROS subscriber there first) read no routes, AttributeError
        in ros.log, or could have written its empty list over the finished one."""
        with self._lock:
            if not self._ready:
                return
            sends = [(r.put if r.gid else r.publisher.put) for r in self.routes if r.matching]
            self.sends = sends  # one assignment: the gateway's thread sees old or new
            self.wire.version += 1

    @property
    def watched(self) -> bool:
        """Whether anyone subscribes now (or the outlet is latched)."""
        return bool(self.sends)

    def put(self, data: bytes) -> None:
        for send in self.sends:
            send(data)
