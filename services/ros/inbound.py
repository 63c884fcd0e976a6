"""Commands from ROS: `cmd_vel`, `thrust` and `waypoints` of every vessel, in every
convention of the gateway.

One wildcard subscriber per convention and command (`**/cmd_vel`, and its rmw_zenoh form
with the Twist type and hash) instead of one per vessel: with 100 boats that is 6 instead of
600. Each vessel's command topics are still announced (graph tokens), so ROS tools list them
and the bridge creates its DDS readers. Callbacks only queue the sample (no Zenoh call and no
decoding on Zenoh's threads); the gateway decodes on its own thread. A sample on an unknown
topic, a malformed payload or a value out of range is logged at most once per topic per
second per topic and kind, counted (log/ros.rejected.json, the run's summary) and ignored.
"""

from __future__ import annotations

import logging
import queue
from collections.abc import Callable
from dataclasses import dataclass

import zenoh

from catabot.bus.keys import ROOT
from catabot.bus.messages import Message
from catabot.bus.rejections import Rejected, Rejections
from catabot.config.ros import RosConfig
from catabot.ros2.commands import CommandError, Malformed, command
from catabot.ros2.names import COMMANDS, Names
from catabot.ros2.wire import DATA, Convention, parse_attachment
from catabot.world.world import Body
from services.ros.wire import Wire

log = logging.getLogger("ros.inbound")

UNKNOWN = "ROS command on an unknown topic"  # the reasons refusals are counted by
MALFORMED = "malformed ROS command"
REFUSED = "ROS command refused"


@dataclass(frozen=True)
class Command:
    """A checked command for one vessel: the ROS command name and its bus message, None
    for one refused (already counted): a lockstep stack's refused reply is still its reply."""

    vessel: str
    name: str  # cmd_vel, thrust, waypoints
    message: Message | None


@dataclass(frozen=True)
class _Route:
    vessel: str
    name: str
    topic: str
    thrusters: int
    rmw: bool  # an rmw_zenoh key: its publishers attach (sequence, stamp, gid)


class Inbound:
    def __init__(
        self,
        wire: Wire,
        names: Names,
        vessels: list[Body],
        ros: RosConfig,
        on_sample: Callable[[], None] = lambda: None,
        *,
        rejections: Rejections,
    ) -> None:
        self.ros, self.rejections = ros, rejections
        self._samples: queue.SimpleQueue[tuple[str, bytes, bytes | None]] = queue.SimpleQueue()
        self._told_attachment: set[str] = set()  # topics warned of a missing attachment
        self._on_sample = on_sample
        self._routes: dict[str, _Route] = {}
        for vessel in vessels:
            for name, (topic, typename) in names.command_topics(vessel.id).items():
                for convention in wire.conventions:
                    key = wire.key(convention, topic, typename)
                    rmw = convention is Convention.RMW
                    self._routes[key] = _Route(vessel.id, name, topic, len(vessel.model.thrusters),
                                               rmw)  # fmt: skip
                    wire.announce(convention, "MS", topic, typename, DATA)
        self._subscribers = [
            wire.session.declare_subscriber(_wildcard(wire, convention, name, typename), self._push)
            for convention in wire.conventions
            for name, typename in COMMANDS.items()
        ]

    def _push(self, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        if key.startswith(ROOT + "/"):  # `**/thrust` matches CataBot's own command keys too
            return
        attached = None if sample.attachment is None else sample.attachment.to_bytes()
        self._samples.put((key, sample.payload.to_bytes(), attached))
        self._on_sample()

    def take(self) -> list[Command]:
        """Every command received so far, checked, in arrival order."""
        out: list[Command] = []
        while True:
            try:
                key, payload, attached = self._samples.get_nowait()
            except queue.Empty:
                return out
            out += self._checked(key, payload, attached)

    def wait(self, timeout_s: float) -> list[Command]:
        """The next sample's command (blocking up to `timeout_s`), then all that queued."""
        try:
            key, payload, attached = self._samples.get(timeout=max(timeout_s, 0.0))
        except queue.Empty:
            return []
        return [*self._checked(key, payload, attached), *self.take()]

    def _checked(self, key: str, payload: bytes, attached: bytes | None) -> list[Command]:
        route = self._routes.get(key)
        if route is None:
            self.rejections.add(key, Rejected(UNKNOWN, "no vessel of this world has it"))
            return []
        if route.rmw:
            self._check_attachment(route.topic, attached)
        try:
            msg = command(
                route.name, payload, thrusters=route.thrusters, defaults=self.ros.waypoints
            )
        except CommandError as exc:
            self.refuse(route.topic, exc)
            return [Command(route.vessel, route.name, None)]
        return [Command(route.vessel, route.name, msg)]

    def _check_attachment(self, topic: str, attached: bytes | None) -> None:
        """Taken all the same, but said once a topic: real rmw_zenoh subscribers drop a sample
        without its 33-byte attachment, so a publisher made by hand that works here would
        fail against ROS 2 nodes."""
        try:
            parse_attachment(attached or b"")
        except ValueError as exc:
            if topic not in self._told_attachment:
                self._told_attachment.add(topic)
                log.warning("%s: taken, but %s: real rmw_zenoh subscribers drop such a sample "
                            "(attach int64 sequence, int64 ns, 0x10 and a 16-byte gid)", topic,
                            "no attachment" if attached is None else exc)  # fmt: skip

    def refuse(self, topic: str, exc: ValueError) -> None:
        """Counted and logged at most once a second per topic and kind (malformed or not)."""
        self.rejections.add(topic, Rejected(MALFORMED if isinstance(exc, Malformed) else REFUSED,
                                            str(exc)))  # fmt: skip

    def close(self) -> None:
        for sub in self._subscribers:
            sub.undeclare()


def _wildcard(wire: Wire, convention: Convention, name: str, typename: str) -> str:
    """Every key of command `name` in one convention, whatever the namespace (`**` matches
    no chunk too: the root namespace's `cmd_vel`)."""
    return wire.key(convention, "/**/" + name, typename)
