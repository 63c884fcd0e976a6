"""The gateway's observer believes nothing for its key alone: a wildcard put, states from a
session that is not physics, a malformed payload and states of other bodies are refused and
counted, never raised into the gateway; physics' own states pass."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from dataclasses import replace

import pytest
import zenoh

from catabot.bus import codec
from catabot.bus.identity import Roster
from catabot.bus.outputs import Outputs
from catabot.bus.session import Connection, free_port, open_session
from services.ros.observer import Observer
from tests.catabot.ros2.world_fixture import world

WORLD = world()


@pytest.fixture
def physics_and_outsider() -> Iterator[tuple[zenoh.Session, zenoh.Session, zenoh.Session]]:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    gateway = open_session(Connection(listen=(endpoint,)))
    physics = open_session(Connection(connect=(endpoint,)))
    outsider = open_session(Connection(connect=(endpoint,)))
    yield gateway, physics, outsider
    for session in (outsider, physics, gateway):
        session.close()


def test_only_physics_states_reach_the_gateway(
    physics_and_outsider: tuple[zenoh.Session, zenoh.Session, zenoh.Session],
) -> None:
    gateway, physics, outsider = physics_and_outsider
    states_key = WORLD.streams.states.key
    roster = Roster({"physics": str(physics.info.zid())})
    observer = Observer(gateway, WORLD.keys, [WORLD.streams.states], lambda: frozenset(
        [states_key]), threading.Event(), roster=roster)  # fmt: skip
    observer._subscribe(frozenset([states_key]))
    time.sleep(0.5)  # the subscription reaches the other sessions
    good = codec.encode(WORLD.start_states())
    other_bodies = replace(WORLD.start_states(), ids=("x",) * len(WORLD.bodies))
    Outputs(outsider).put(outsider.declare_publisher(states_key), good)  # not physics
    outsider.put(WORLD.keys.prefix + "/**", b"\x01")  # a wildcard
    sign = Outputs(physics)
    publisher = physics.declare_publisher(states_key)
    for payload in (b"\x93garbage", codec.encode(other_bodies), good):
        sign.put(publisher, payload)
    time.sleep(0.5)
    received = observer._drain()
    assert [m.ids for m in received[states_key]] == [WORLD.body_ids]
    assert observer.rejections.totals == {
        "not from its producer": 1, "not a stream key": 1, "malformed": 1,
        "invalid content": 1}  # fmt: skip
    observer.close()
