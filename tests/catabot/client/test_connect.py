"""Finding a world and joining it, against the conductor's real `world/info` queryable in
this process (no run): the errors a stack meets before it steps, each naming what is wrong."""

from __future__ import annotations

import json
import re
import time
from collections.abc import Iterator
from typing import Any

import pytest
import zenoh

from catabot.bus.keys import Keys
from catabot.bus.session import Connection, free_port, open_session
from catabot.bus.settings import Schedule
from catabot.client import (
    Client,
    ClientError,
    CommandError,
    NoData,
    NotAParticipant,
    NotItsVessel,
    SeveralVessels,
    SeveralWorlds,
    SimulatorNotFound,
    Thrust,
    TooLate,
    Twist,
    UnknownSensor,
    UnknownVessel,
    Waypoints,
)
from catabot.run.world_info import WorldInfoDesk, describe
from catabot.world.world import World
from tests.catabot.client.fixtures import ROSTER, scenario


class Served:
    """A world's `world/info` desk on its own session, listening on its own port."""

    def __init__(self, name: str, **top: Any) -> None:
        self.endpoint = f"tcp/127.0.0.1:{free_port()}"
        self.session = open_session(Connection(listen=(self.endpoint,)))
        world = scenario(name, **top)
        self.schedule = Schedule(ticks=world.ticks)
        self.desk = WorldInfoDesk(self.session, world, ROSTER, self.schedule)
        assert self.desk.served.wait(30)

    def close(self) -> None:
        self.desk.close()
        self.session.close()


@pytest.fixture
def served() -> Iterator[Served]:
    s = Served("info")
    yield s
    s.close()


def test_no_simulation_is_a_clear_error_after_the_timeout() -> None:
    lonely = f"tcp/127.0.0.1:{free_port()}"
    started = time.monotonic()
    with pytest.raises(SimulatorNotFound, match=r"no simulation of any world answered on "
                       r"catabot/\*/world/info within 0.6 s \(connect \['tcp/127"):  # fmt: skip
        Client.connect(lonely, timeout_s=0.6)  # a string is one endpoint, not its letters
    assert 0.6 <= time.monotonic() - started < 5.0
    with pytest.raises(SimulatorNotFound, match="no simulation of world 'harbour'"):
        Client.connect(timeout_s=0.3, world="harbour")


def test_the_one_world_is_found_and_several_must_be_chosen(served: Served) -> None:
    with Client.connect([served.endpoint], timeout_s=10) as sim:
        assert sim.info.name == "info" and list(sim.info.vessels) == ["ego", "other"]
    second = Served("info2")
    try:
        both = [served.endpoint, second.endpoint]
        with pytest.raises(SeveralWorlds, match=r"several simulations answer \(info, info2\)"):
            Client.connect(both, timeout_s=10).close()
        with Client.connect(both, world="info2", timeout_s=10) as sim:
            assert sim.info.name == "info2"
        with pytest.raises(SimulatorNotFound, match=r"world 'inf0' answered .*; running there: "
                           "info, info2"):  # fmt: skip
            Client.connect(both, world="inf0", timeout_s=1)
    finally:
        second.close()


def test_a_reply_for_another_worlds_key_or_not_json_is_ignored(served: Served) -> None:
    data = json.dumps({"v": 1, "world": "info"})

    def liar(query: zenoh.Query) -> None:
        query.reply("catabot/fake/world/info", data)  # claims world 'info' on another key

    def junk(query: zenoh.Query) -> None:
        query.reply("catabot/junk/world/info", b"\xff not json")

    fakes = [served.session.declare_queryable("catabot/fake/world/info", liar),
             served.session.declare_queryable("catabot/junk/world/info", junk)]  # fmt: skip
    try:
        with Client.connect([served.endpoint], timeout_s=10) as sim:
            assert sim.info.name == "info" and sim.info.vessels["ego"].thrusters == 2
    finally:
        for fake in fakes:
            fake.undeclare()


def test_a_participant_of_two_vessels_cannot_join_as_a_client_of_one() -> None:
    """The second vessel would get no commands, and physics wait for them to the deadline."""
    stack = {"participant": "stack", "rate_hz": 10.0}
    vessels = [{"id": "ego", "controller": stack},
               {"id": "ego2", "pose": {"x_m": 20.0, "y_m": 0.0}, "controller": stack}]  # fmt: skip
    served = Served("pair", vessels=vessels, traffic={"count": 0})
    said = "participant 'stack' controls vessels ego, ego2 in world 'pair', and a joined"
    try:
        with (
            Client.connect([served.endpoint], timeout_s=10) as sim,
            pytest.raises(SeveralVessels, match=said),
        ):
            sim.join("stack")
    finally:
        served.close()


def test_a_controller_joined_to_another_vessel_than_its_own_is_refused_at_join() -> None:
    """It was taken, its own vessel got no commands, and the run stopped at tick 0 with
    "drives no vessel's commands" and advice to send free commands (which are refused)."""
    vessels = [{"id": "alpha", "controller": {"participant": "stack_a", "rate_hz": 10.0}},
               {"id": "bravo", "pose": {"x_m": 20.0, "y_m": 0.0},
                "controller": {"participant": "stack_b", "rate_hz": 10.0}}]  # fmt: skip
    served = Served("two", vessels=vessels, traffic={"count": 0})
    said = (
        "participant 'stack_a' controls vessel 'alpha', not 'bravo': join with "
        "vessel='alpha' (--vessel alpha); 'stack_b' controls 'bravo'"
    )
    try:
        with Client.connect([served.endpoint], timeout_s=10) as sim:
            with pytest.raises(NotItsVessel, match=re.escape(said)):
                sim.join("stack_a", vessel="bravo")
            with pytest.raises(UnknownVessel, match="no vessel 'zulu'"):
                sim.join("stack_a", vessel="zulu")
    finally:
        served.close()


def test_unknown_vessels_sensors_and_participants(served: Served) -> None:
    with Client.connect([served.endpoint], timeout_s=10) as sim:
        with pytest.raises(UnknownVessel, match="no vessel 'nope'; its vessels: ego, other; "
                           "traffic boats: boat_000"):  # fmt: skip
            sim.vessel("nope")
        boat = sim.vessel("boat_000")  # a handle: its state and commands, paths included
        assert (boat.info.kind, boat.info.sensors, boat.info.thrusters) == ("boat", {}, 2)
        with pytest.raises(UnknownSensor, match="vessel 'boat_000' has no sensor 'cam'"):
            boat.sensor("cam")
        with pytest.raises(UnknownSensor, match="vessel 'ego' has no sensor 'cam'"):
            sim.vessel("ego").sensor("cam")
        for name in ("nobody", "physics"):  # a service is no external participant
            with pytest.raises(NotAParticipant, match=f"does not expect a participant '{name}'; "
                               "it expects watcher, stack"):  # fmt: skip
                sim.join(name)
        with pytest.raises(UnknownVessel, match="no vessel 'nope'"):
            sim.join("stack", vessel="nope")
        with pytest.raises(UnknownSensor, match="no sensor 'sonar'"):
            sim.join("stack", sensors=["gps", "sonar"])
        with pytest.raises(
            CommandError, match="twist is driven in lockstep by participant 'stack'"
        ):
            sim.vessel("ego").send(Twist(1.0, 0.0))
        with pytest.raises(
            CommandError, match=r"'stack' \(twist\): a free thrust command would change"
        ):
            sim.vessel("ego").send(Thrust([0.5, 0.5]))


def test_no_name_joins_as_the_vessels_controller_participant(served: Served) -> None:
    """`--participant` left out is None, which add_stack_args says is the vessel's
    controller.participant: join(None) had been refused as "a participant None"."""
    with Client.connect([served.endpoint], timeout_s=10) as sim:
        with pytest.raises(UnknownSensor, match="no sensor 'sonar'"):  # got past the name
            sim.join(None, vessel="ego", sensors=["sonar"])
        with pytest.raises(NotAParticipant, match="vessel 'other' of world 'info' has no "
                           r"controller participant: give one \(--participant NAME; it "
                           r"expects watcher, stack\)"):  # fmt: skip
            sim.join(None, vessel="other")


def test_a_free_command_waits_for_the_runs_first_tick(served: Served) -> None:
    """Sent while the services were still subscribing, a command reached some only (the
    recorder wrote a thrust that physics never applied): send waits for the vessel's first
    state, up to the client's timeout. Here no physics runs: NoData, nothing sent."""
    with Client.connect([served.endpoint], timeout_s=1.0) as sim:
        with pytest.raises(CommandError, match="'other' follows no path from the bus"):
            sim.vessel("other").send(Waypoints([(1.0, 2.0)]))
        started = time.monotonic()
        with pytest.raises(NoData, match="no state of vessel 'other' within 1 s"):
            sim.vessel("other").send(Thrust([0.5, 0.5]))
        assert time.monotonic() - started >= 1.0


def test_a_run_that_has_started_is_too_late_to_join(served: Served) -> None:
    served.schedule.grant(3)
    late = r"has started \(tick 3 granted\): participant 'stack'"
    with Client.connect([served.endpoint], timeout_s=10) as sim, pytest.raises(TooLate, match=late):
        sim.join("stack")


def test_a_name_held_by_another_session_is_said_so_also_once_the_run_started(
    served: Served,
) -> None:
    """A second copy of a stack, started while the first stepped, was told it came too late
    and to start before the timeout: the name was the cause."""
    served.schedule.grant(3)
    first = served.session.zid()
    token = served.session.liveliness().declare_token(Keys("info").live("stack", str(first)))
    try:
        held = rf"'stack' of world 'info' is already joined by another session \({first}\)"
        with Client.connect([served.endpoint], timeout_s=10) as sim:
            time.sleep(0.5)  # the token arrives
            with pytest.raises(TooLate, match=held + ": a second copy of the stack"):
                sim.join("stack")
    finally:
        token.undeclare()


def test_a_second_different_answer_for_the_world_is_refused(served: Served) -> None:
    def impostor(query: zenoh.Query) -> None:
        data = json.loads(json.dumps(describe(World.resolve(scenario("info")), ROSTER)))
        data["roster"]["conductor"] = "1234"  # its own session as the clock
        query.reply("catabot/info/world/info", json.dumps(data))

    fake = served.session.declare_queryable("catabot/info/world/info", impostor)
    try:
        with pytest.raises(ClientError, match="two different answers on catabot/info/world/info"):
            Client.connect([served.endpoint], timeout_s=10).close()
    finally:
        fake.undeclare()


def test_a_session_opened_before_its_peer_listens_joins_within_a_second() -> None:
    """The embedded config retries a refused connection every 0.25-1 s, not Zenoh's 1-4 s:
    a client started before `catabot run` must not miss a short run."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    early = open_session(Connection(connect=(endpoint,)))
    try:
        seen = early.declare_subscriber("catabot/retry/x", zenoh.handlers.RingChannel(1))
        time.sleep(5.0)  # Zenoh's own back-off would be at 4 s by now
        late = open_session(Connection(listen=(endpoint,)))
        try:
            started = time.monotonic()
            while seen.try_recv() is None:
                assert time.monotonic() - started < 1.5, "the early session never joined"
                late.put("catabot/retry/x", b"1")
                time.sleep(0.02)
        finally:
            late.close()
    finally:
        early.close()
