"""A stand-in for a ROS 2 stack speaking Zenoh (no ROS 2 is installed here): it subscribes and
publishes the way zenoh-bridge-ros2dds or rmw_zenoh do, with payloads built and read by
rosbags (an implementation no one here wrote) and keys spelled out from the conventions
(../shared/reference/ros2-over-zenoh.md), not from catabot.ros2.wire."""

from __future__ import annotations

import json
import struct
import threading
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import zenoh
from rosbags.typesys import Stores, get_typestore
from zenoh.ext import HistoryConfig, declare_advanced_subscriber

ROSBAGS = get_typestore(Stores.ROS2_JAZZY)
T = ROSBAGS.types


def rmw_key(topic: str, typename: str, domain: int = 0) -> str:
    """`<domain>/<topic>/<pkg>::msg::dds_::<Type>_/<RIHS01 hash>` (rmw_zenoh's design.md)."""
    pkg, _, name = typename.split("/")
    dds = f"{pkg}::msg::dds_::{name}_"
    return f"{domain}/{topic.strip('/')}/{dds}/{ROSBAGS.hash_rihs01(typename)}"


def bridge_key(topic: str) -> str:
    return topic.strip("/")


@dataclass(frozen=True)
class Sample:
    key: str
    payload: bytes
    attachment: bytes | None
    at: float


class RosClient:
    def __init__(self, endpoint: str) -> None:
        cfg = zenoh.Config()
        cfg.insert_json5("mode", '"peer"')
        cfg.insert_json5("scouting/multicast/enabled", "false")
        cfg.insert_json5("connect/endpoints", json.dumps([endpoint]))
        cfg.insert_json5("listen/endpoints", '["tcp/127.0.0.1:0"]')
        self.session = zenoh.open(cfg)
        self.samples: dict[str, list[Sample]] = {}
        self._lock = threading.Lock()
        self._subs: list[Any] = []
        self._gid = bytes(range(16))
        self._seq = 0

    def subscribe(self, key: str, *, transient_local: bool = False) -> list[Sample]:
        """Collect every sample on `key` (a list that fills as they come). A TRANSIENT_LOCAL
        subscriber (/tf_static) also gets what was published before it, from the
        publisher's cache, as rmw_zenoh and the bridge ask for it: an advanced subscriber
        with history that detects late publishers."""
        got = self.samples.setdefault(key, [])

        def on_sample(sample: zenoh.Sample) -> None:
            att = sample.attachment.to_bytes() if sample.attachment is not None else None
            with self._lock:
                got.append(
                    Sample(str(sample.key_expr), sample.payload.to_bytes(), att, time.time())
                )

        if transient_local:
            history = HistoryConfig(detect_late_publishers=True, max_samples=1)
            self._subs.append(
                declare_advanced_subscriber(self.session, key, on_sample, history=history)
            )
        else:
            self._subs.append(self.session.declare_subscriber(key, on_sample))
        return got

    def put(self, key: str, payload: bytes, *, rmw: bool = False) -> None:
        """A sample as a ROS publisher sends it; rmw_zenoh's carries the 33-byte attachment."""
        if rmw:
            self._seq += 1
            att = struct.pack("<qqB", self._seq, time.time_ns(), 16) + self._gid
            self.session.put(key, payload, attachment=att)
        else:
            self.session.put(key, payload)

    def tokens(self, selector: str) -> list[str]:
        return [
            str(r.ok.key_expr) for r in self.session.liveliness().get(selector, timeout=2.0) if r.ok
        ]

    def close(self) -> None:
        for sub in self._subs:
            sub.undeclare()
        self.session.close()


def twist(surge: float, yaw_rate: float) -> bytes:
    v3 = T["geometry_msgs/msg/Vector3"]
    msg = T["geometry_msgs/msg/Twist"](
        linear=v3(x=surge, y=0.0, z=0.0), angular=v3(x=0.0, y=0.0, z=yaw_rate)
    )
    return bytes(ROSBAGS.serialize_cdr(msg, "geometry_msgs/msg/Twist"))


def decode(payload: bytes, typename: str) -> Any:
    return ROSBAGS.deserialize_cdr(payload, typename)


def stamp_ns(header: Any) -> int:
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def float64s(values: Any) -> np.ndarray:
    return np.asarray(values, dtype=np.float64)
