"""The two ways ROS 2 meets Zenoh, as keys, attachments and liveliness tokens
(../shared/reference/ros2-over-zenoh.md has the sources of each rule).

zenoh-bridge-ros2dds (ROS nodes on DDS, a bridge in between):
- data key: the topic without its leading '/', after the bridge's namespace if it has one
  (`/ego/odom` -> `ego/odom`; bridge `-n /bot1` -> `bot1/ego/odom`); payload: CDR with its
  4-byte header, no attachment;
- a route announced as `@/<zid>/@ros2_lv/<MP|MS>/<key>/<type>/<qos>` ('/' written '§'), which
  a bridge reads as a remote bridge's route: it creates the DDS writer or reader at once, so
  `ros2 topic list` shows the topic before anyone subscribes.

rmw_zenoh (Jazzy and later, nodes speak Zenoh themselves):
- data key: `<domain>/<topic without '/'>/<pkg>::msg::dds_::<Type>_/RIHS01_<hash>`; every
  sample carries a 33-byte attachment: int64 sequence number, int64 source timestamp (ns),
  the LEB128 length 16 and the publisher's 16-byte gid (rmw_zenoh drops samples without);
- the graph: a node token `@ros2_lv/<domain>/<zid>/<nid>/<nid>/NN/<enclave>/<ns>/<node>` and
  one per publisher or subscription `.../<nid>/<eid>/<MP|MS>/<enclave>/<ns>/<node>/<topic>/
  <type>/<hash>/<qos>`, '/' written '%', an empty part '%'.
"""

from __future__ import annotations

import hashlib
import struct
from dataclasses import dataclass
from enum import StrEnum

from catabot.ros2 import types
from catabot.ros2.names import BUOYS, TF_STATIC


class Convention(StrEnum):
    BRIDGE = "bridge"
    RMW = "rmw_zenoh"


def conventions(mode: str) -> tuple[Convention, ...]:
    """`ros.mode` -> the conventions it speaks ("both": bridge and rmw_zenoh)."""
    return (Convention.BRIDGE, Convention.RMW) if mode == "both" else (Convention(mode),)


@dataclass(frozen=True)
class Qos:
    """The few QoS settings a route announces (the rest are ROS defaults)."""

    depth: int = 10
    transient_local: bool = False  # /tf_static, /buoys: late subscribers get the last one
    reliable: bool = True


DATA = Qos(depth=10)
LATCHED = Qos(depth=1, transient_local=True)
LATCHED_TOPICS = frozenset({TF_STATIC, BUOYS})  # sent once, kept for late subscribers


def topic_qos(topic: str) -> Qos:
    """What the gateway offers on `topic` (and what run.mcap says it offered)."""
    return LATCHED if topic in LATCHED_TOPICS else DATA


def bridge_key(topic: str, bridge_namespace: str = "/") -> str:
    return "/".join(p for p in (bridge_namespace.strip("/"), topic.strip("/")) if p)


def rmw_key(domain: int, topic: str, typename: str) -> str:
    return f"{domain}/{topic.strip('/')}/{types.dds_name(typename)}/{types.rihs01(typename)}"


def bridge_qos(qos: Qos, typename: str) -> str:
    """`<K>:<rel>:<dur>:<hist>,<depth>:<user data>` with DDS (Cyclone) enum values: keyless
    (ROS topics are), RELIABLE 1 / BEST_EFFORT 0, VOLATILE 0 / TRANSIENT_LOCAL 1, KEEP_LAST 0;
    since Iron the user data carries the type hash, as ROS 2 puts it in USER_DATA."""
    rel, dur = int(qos.reliable), int(qos.transient_local)
    return f":{rel}:{dur}:0,{qos.depth}:typehash={types.rihs01(typename)};"


def bridge_token(zid: str, kind: str, key: str, typename: str, qos: Qos) -> str:
    """A bridge route token; `kind` MP (publisher) or MS (subscriber)."""
    escaped = key.replace("/", "§"), typename.replace("/", "§")
    return f"@/{zid}/@ros2_lv/{kind}/{escaped[0]}/{escaped[1]}/{bridge_qos(qos, typename)}"


def rmw_qos(qos: Qos) -> str:
    """rmw_zenoh's compact QoS: every field empty where it equals rmw_zenoh's default
    (RELIABLE, VOLATILE, KEEP_LAST, depth 42, no deadline, lifespan or liveliness lease)."""
    rel = "" if qos.reliable else "2"
    dur = "1" if qos.transient_local else ""
    depth = "" if qos.depth == 42 else str(qos.depth)
    return f"{rel}:{dur}:,{depth}:,:,:,,"


def mangle(name: str) -> str:
    """A ROS name as one key chunk: '/' -> '%', empty -> '%'."""
    return name.replace("/", "%") or "%"


@dataclass(frozen=True)
class RmwNode:
    """The gateway as an rmw_zenoh node: what its graph tokens say."""

    domain: int
    zid: str
    name: str
    namespace: str = "/"
    node_id: int = 0

    def token(self) -> str:
        return f"{self._head(self.node_id)}/NN/%/{mangle(self._ns())}/{self.name}"

    def entity_token(self, entity_id: int, kind: str, topic: str, typename: str, qos: Qos) -> str:
        """`kind` MP (publisher) or MS (subscription) of `topic` ('/'-qualified)."""
        return (
            f"{self._head(entity_id)}/{kind}/%/{mangle(self._ns())}/{self.name}/{mangle(topic)}"
            f"/{types.dds_name(typename)}/{types.rihs01(typename)}/{rmw_qos(qos)}"
        )

    def _head(self, entity_id: int) -> str:
        return f"@ros2_lv/{self.domain}/{self.zid}/{self.node_id}/{entity_id}"

    def _ns(self) -> str:
        return "" if self.namespace == "/" else self.namespace


_ATTACHMENT = struct.Struct("<qqB")
ATTACHMENT_SIZE = _ATTACHMENT.size + 16


def gid(token: str) -> bytes:
    """A publisher's 16-byte gid: a hash of its graph token (stable run to run, as
    rmw_zenoh's own gids are)."""
    return hashlib.blake2b(token.encode(), digest_size=16).digest()


def attachment(sequence: int, timestamp_ns: int, publisher_gid: bytes) -> bytes:
    """The 33 bytes rmw_zenoh expects on every sample (zenoh-ext serialization of
    (int64, int64, uint8[16]))."""
    return _ATTACHMENT.pack(sequence, timestamp_ns, 16) + publisher_gid


def parse_attachment(data: bytes) -> tuple[int, int, bytes]:
    """(sequence, timestamp ns, gid); ValueError if it is not 33 bytes of that form."""
    if len(data) != ATTACHMENT_SIZE or data[16] != 16:
        raise ValueError(f"not an rmw_zenoh attachment ({len(data)} bytes)")
    sequence, stamp, _ = _ATTACHMENT.unpack_from(data)
    return sequence, stamp, bytes(data[17:])
