"""The gateway in process, against a second Zenoh session playing ROS: it wants (subscribes
to) only the streams someone's topics are built from, puts only to watched keys, routes
commands to the bus (free-running, or held for a lockstep controller), and complains about
bad ones at most once a second per topic."""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest
import zenoh
from rosbags.typesys import Stores, get_typestore

from catabot.bus import codec
from catabot.bus.messages import Message, ThrustCmd, Tick, TwistCmd
from catabot.bus.rejections import Rejections
from catabot.bus.session import Connection, free_port, open_session
from catabot.config.load import parse_scenario
from catabot.ros2.types import TWIST
from catabot.ros2.wire import Convention, attachment
from catabot.world.world import World
from services.ros.gateway import Gateway
from services.ros.inbound import MALFORMED, REFUSED
from tests.catabot.ros2.world_fixture import scenario

ROSBAGS = get_typestore(Stores.ROS2_JAZZY)


def _until(check: Callable[[], bool], limit_s: float = 5.0) -> bool:
    end = time.monotonic() + limit_s
    while not check() and time.monotonic() < end:
        time.sleep(0.02)
    return check()


@pytest.fixture
def sessions() -> Iterator[tuple[zenoh.Session, zenoh.Session]]:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    ours = open_session(Connection(listen=(endpoint,), timestamping=True))
    ros = open_session(Connection(connect=(endpoint,)))
    yield ours, ros
    ros.close()
    ours.close()


def _twist(x: float) -> bytes:
    v3 = ROSBAGS.types["geometry_msgs/msg/Vector3"]
    msg = ROSBAGS.types["geometry_msgs/msg/Twist"](
        linear=v3(x=x, y=0.0, z=0.0), angular=v3(x=0.0, y=0.0, z=0.0)
    )
    return bytes(ROSBAGS.serialize_cdr(msg, "geometry_msgs/msg/Twist"))


def test_wants_only_what_someone_subscribes_to(sessions: Any) -> None:
    ours, ros = sessions
    world = World.resolve(parse_scenario(scenario(mode="bridge")))
    gateway = Gateway(world, world.scenario.ros, ours, rejections=_refused())  # type: ignore[arg-type]
    try:
        assert gateway.wanted() == frozenset()
        sub = ros.declare_subscriber("ego/lidar/points", lambda s: None)
        lidar = world.keys.sensor("ego", "lidar")
        assert _until(lambda: gateway.wanted() == {lidar})
        tf = ros.declare_subscriber("tf", lambda s: None)
        assert _until(lambda: gateway.wanted() == {lidar, world.keys.world_states()})
        sub.undeclare()
        tf.undeclare()
        assert _until(lambda: gateway.wanted() == frozenset())
    finally:
        gateway.close()


def test_a_subscriber_there_before_the_gateway_is_served_without_an_error(
    sessions: Any, caplog: pytest.LogCaptureFixture
) -> None:
    """A route's matching listener fired while its topic's routes were still being made:
    a trial's ROS side, subscribed first, got seven AttributeError tracebacks in ros.log."""
    ours, ros = sessions
    sub = ros.declare_subscriber("**", lambda s: None)
    world = World.resolve(parse_scenario(scenario(mode="both")))
    with caplog.at_level(logging.ERROR):
        gateway = Gateway(world, world.scenario.ros, ours, rejections=_refused())  # type: ignore[arg-type]
        try:
            assert _until(lambda: world.keys.world_states() in gateway.wanted())
        finally:
            gateway.close()
            sub.undeclare()
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR]


def test_free_commands_go_to_the_bus_and_bad_ones_are_refused(
    sessions: Any, caplog: pytest.LogCaptureFixture
) -> None:
    ours, ros = sessions
    world = World.resolve(parse_scenario(scenario(mode="bridge")))
    got: list[Message] = []
    key = world.keys.cmd_twist("ego")
    bus = ros.declare_subscriber(
        key, lambda s: got.append(codec.decode(s.payload.to_bytes(), TwistCmd))
    )
    gateway = Gateway(world, world.scenario.ros, ours, rejections=_refused())  # type: ignore[arg-type]
    try:
        time.sleep(0.3)  # the wildcard subscribers reach the other session
        with caplog.at_level(logging.WARNING, logger="ros.inbound"):
            for _ in range(20):
                ros.put("ego/cmd_vel", b"junk")
            ros.put("ego/cmd_vel", _twist(1.25))
            ros.put("nobody/cmd_vel", _twist(1.0))
            assert _until(lambda: (gateway.commands(), bool(got))[1])
        assert got == [TwistCmd(surge=1.25, yaw_rate=0.0)]  # tick -1: free-running
        junk = [r for r in caplog.records if "on /ego/cmd_vel" in r.getMessage()]
        assert len(junk) == 1 and "not little-endian CDR" in junk[0].getMessage()
        assert any("nobody/cmd_vel" in r.getMessage() for r in caplog.records)
        caplog.clear()
        with caplog.at_level(logging.WARNING, logger="ros.inbound"):
            ros.put(world.keys.cmd_thrust("ego"), b"\x00")  # CataBot's own key, `**/thrust`
            time.sleep(0.3)
            gateway.commands()
        assert not caplog.records  # not a ROS topic: nothing said, nothing queued
    finally:
        bus.undeclare()
        gateway.close()


def test_an_rmw_command_without_its_attachment_is_taken_and_said_once(
    sessions: Any, caplog: pytest.LogCaptureFixture
) -> None:
    """A hand-made rmw_zenoh publisher with no attachment worked here and would fail against
    real ROS 2 nodes (their subscribers drop such samples): taken, and said once a topic."""
    ours, ros = sessions
    world = World.resolve(parse_scenario(scenario(mode="rmw_zenoh")))
    got: list[Message] = []
    bus = ros.declare_subscriber(
        world.keys.cmd_twist("ego"),
        lambda s: got.append(codec.decode(s.payload.to_bytes(), TwistCmd)),
    )
    gateway = Gateway(world, world.scenario.ros, ours, rejections=_refused())  # type: ignore[arg-type]
    key = gateway.wire.key(Convention.RMW, "/ego/cmd_vel", TWIST)
    try:
        time.sleep(0.3)  # the wildcard subscribers reach the other session
        with caplog.at_level(logging.WARNING, logger="ros.inbound"):
            ros.put(key, _twist(1.0))
            ros.put(key, _twist(2.0), attachment=b"xyz")
            ros.put(key, _twist(3.0), attachment=attachment(1, 5, bytes(16)))
            assert _until(lambda: (gateway.commands(), len(got) == 3)[1])
        assert [g.surge for g in got] == [1.0, 2.0, 3.0]  # type: ignore[attr-defined]
        said = [r.getMessage() for r in caplog.records]
        assert said == [
            "/ego/cmd_vel: taken, but no attachment: real rmw_zenoh subscribers drop such a "
            "sample (attach int64 sequence, int64 ns, 0x10 and a 16-byte gid)"
        ]
    finally:
        bus.undeclare()
        gateway.close()


def _lockstep(
    ours: zenoh.Session, refused: Rejections, *, reply_timeout_s: float = 0.3
) -> tuple[World, Gateway, list[tuple[str, Message]]]:
    """A gateway that drives vessel `other` by thrust in the lockstep, and what it sends."""
    data = scenario(mode="bridge", lockstep=True, reply_timeout_s=reply_timeout_s)
    data["vessels"][1]["controller"] = {"participant": "ros", "rate_hz": 10, "command": "thrust"}
    world = World.resolve(parse_scenario(data))
    sent: list[tuple[str, Message]] = []
    gateway = Gateway(world, world.scenario.ros, ours, lambda k, m: sent.append((k, m)),  # type: ignore[arg-type]
                      rejections=refused)  # fmt: skip
    return world, gateway, sent


def test_a_lockstep_controller_takes_the_reply_to_its_tick(sessions: Any) -> None:
    ours, ros = sessions
    world, gateway, sent = _lockstep(ours, _refused())
    try:
        gateway.commands(Tick("r", 0, 0, 10_000_000))  # nobody on /clock: neutral, at once
        assert sent == [(world.keys.cmd_thrust("other"), ThrustCmd((0.0, 0.0), 0, 0))]
        clock = ros.declare_subscriber("clock", lambda _: None)  # the stack, on sim time
        deadline = time.monotonic() + 10.0
        while not gateway.clock.watched and time.monotonic() < deadline:
            time.sleep(0.01)
        layout = ROSBAGS.types["std_msgs/msg/MultiArrayLayout"](dim=[], data_offset=0)
        msg = ROSBAGS.types["std_msgs/msg/Float64MultiArray"](
            layout=layout, data=np.array([0.5, -0.5])
        )
        ros.put("other/thrust", bytes(ROSBAGS.serialize_cdr(msg, "std_msgs/msg/Float64MultiArray")))
        gateway.commands(Tick("r", 5, 50_000_000, 10_000_000))  # not a controller tick
        assert len(sent) == 1
        gateway.commands(Tick("r", 10, 100_000_000, 10_000_000))  # waits for the reply
        assert sent[-1] == (world.keys.cmd_thrust("other"), ThrustCmd((0.5, -0.5), 10, 100_000_000))
        gateway.commands(Tick("r", 20, 200_000_000, 10_000_000))  # silent: the last holds
        assert sent[-1][1] == ThrustCmd((0.5, -0.5), 20, 200_000_000)
        clock.undeclare()
    finally:
        gateway.close()


def _matched(session: zenoh.Session, key: str) -> zenoh.Publisher:
    """A publisher the gateway's subscriber has matched: a put before that was lost now and
    then on a loaded machine (the reply never came)."""
    pub = session.declare_publisher(key)
    assert _until(lambda: pub.matching_status.matching), f"nobody subscribes to {key}"
    return pub


def test_a_second_reply_to_one_clock_is_refused_and_the_first_taken(sessions: Any) -> None:
    """The newest reply was taken: which of two came last varied, and so did the run."""
    ours, ros = sessions
    refused = _refused()
    _, gateway, sent = _lockstep(ours, refused)
    layout = ROSBAGS.types["std_msgs/msg/MultiArrayLayout"](dim=[], data_offset=0)
    array = ROSBAGS.types["std_msgs/msg/Float64MultiArray"]
    pub = _matched(ros, "other/thrust")
    try:
        for value in (0.5, 0.25):
            msg = array(layout=layout, data=np.array([value, value]))
            pub.put(bytes(ROSBAGS.serialize_cdr(msg, "std_msgs/msg/Float64MultiArray")))
        both = lambda: (gateway.commands(), refused.totals == {REFUSED: 1})[1]  # noqa: E731
        assert _until(both)  # both here before the tick takes them (0.3 s was not, loaded)
        gateway.commands(Tick("r", 0, 0, 10_000_000))
        assert sent[-1][1] == ThrustCmd((0.5, 0.5), 0, 0)
        assert refused.totals == {REFUSED: 1}
    finally:
        gateway.close()


def test_a_malformed_reply_is_the_reply_the_last_command_holds_at_once(sessions: Any) -> None:
    """A refused reply left the gateway waiting the whole reply_timeout_s (here 8 s) at
    every such tick, for a reply that had come; it is now the reply, refused and counted."""
    ours, ros = sessions
    refused = _refused()
    world, gateway, sent = _lockstep(ours, refused, reply_timeout_s=8.0)
    clock = ros.declare_subscriber("clock", lambda _: None)  # the stack, on sim time
    try:
        assert _until(lambda: gateway.clock.watched)
        _matched(ros, "other/thrust").put(b"junk")  # the reply to tick 10's /clock, malformed
        start = time.monotonic()
        gateway.commands(Tick("r", 10, 100_000_000, 10_000_000))
        assert time.monotonic() - start < 4.0
        assert sent[-1] == (world.keys.cmd_thrust("other"), ThrustCmd((0.0, 0.0), 10, 100_000_000))
        assert refused.totals == {MALFORMED: 1}
    finally:
        clock.undeclare()
        gateway.close()


def _path(points: list[tuple[float, float]]) -> bytes:
    t = ROSBAGS.types
    header = t["std_msgs/msg/Header"](
        stamp=t["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id="map"
    )
    poses = [
        t["geometry_msgs/msg/PoseStamped"](
            header=header,
            pose=t["geometry_msgs/msg/Pose"](
                position=t["geometry_msgs/msg/Point"](x=x, y=y, z=0.0),
                orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            ),
        )
        for x, y in points
    ]
    msg = t["nav_msgs/msg/Path"](header=header, poses=poses)
    return bytes(ROSBAGS.serialize_cdr(msg, "nav_msgs/msg/Path"))


def test_commands_the_bus_would_refuse_are_refused_here(
    sessions: Any, caplog: pytest.LogCaptureFixture
) -> None:
    ours, ros = sessions
    data = scenario(mode="bridge")
    data["vessels"][1]["controller"] = {"participant": "stack", "rate_hz": 10, "command": "thrust"}
    world = World.resolve(parse_scenario(data))
    got: list[str] = []
    bus = ros.declare_subscriber("catabot/**", lambda s: got.append(str(s.key_expr)))
    gateway = Gateway(world, world.scenario.ros, ours, rejections=_refused())  # type: ignore[arg-type]
    try:
        time.sleep(0.3)  # the wildcard subscribers reach the other session
        with caplog.at_level(logging.WARNING, logger="ros.inbound"):
            ros.put("ego/waypoints", _path([(5.0, 5.0)]))  # the ego follows no path
            ros.put("other/cmd_vel", _twist(1.0))  # driven in lockstep by its thrust
            ros.put("ego/waypoints", _path([]))  # a release: taken
            assert _until(lambda: (gateway.commands(), bool(got))[1])
        assert got == [world.keys.cmd_waypoints("ego")]
        said = " ".join(r.getMessage() for r in caplog.records)
        assert f"on /ego/waypoints: {REFUSED}: 'ego' is a scenario vessel" in said
        assert f"on /other/cmd_vel: {REFUSED}: vessel 'other' is driven in lockstep by" in said
    finally:
        bus.undeclare()
        gateway.close()


def test_refusals_are_counted_by_kind_and_each_kind_reported(
    sessions: Any, caplog: pytest.LogCaptureFixture
) -> None:
    """Garbage then out-of-range twists on one topic: the out-of-range line said "(9 more
    since the last report)", and the nine were the garbage."""
    ours, ros = sessions
    world = World.resolve(parse_scenario(scenario(mode="bridge")))
    refused = _refused()
    gateway = Gateway(world, world.scenario.ros, ours, rejections=refused)  # type: ignore[arg-type]
    try:
        time.sleep(0.3)
        with caplog.at_level(logging.WARNING, logger="ros"):
            for _ in range(3):
                ros.put("ego/cmd_vel", b"garbage")
            for _ in range(2):
                ros.put("ego/cmd_vel", _twist(1000.0))
            assert _until(lambda: (gateway.commands(), sum(refused.totals.values()) == 5)[1])
        assert refused.totals == {MALFORMED: 3, REFUSED: 2}
        said = [r.getMessage() for r in caplog.records]
        assert len(said) == 2 and "since the last report" not in " ".join(said), said
        assert f"{MALFORMED}: not little-endian CDR" in said[0]
        assert f"{REFUSED}: twist out of range" in said[1]
    finally:
        gateway.close()


def _refused() -> Rejections:
    return Rejections(logging.getLogger("ros"), "ros")
