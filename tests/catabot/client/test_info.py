"""The `world/info` answer as the client reads it: every field a stack needs, typed, equal
to what the resolved World says; a malformed or foreign answer is a clear ClientError."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from catabot.bus.messages import LidarScan, TwistCmd
from catabot.client import ClientError, NotAParticipant, UnknownSensor
from catabot.client.client import _controller_of
from catabot.client.free import unpaced
from catabot.client.info import parse
from catabot.config.load import parse_scenario
from catabot.run.world_info import describe
from catabot.world.world import World
from tests.catabot.client.fixtures import DEG, ROSTER, answer, scenario


def test_the_answer_describes_the_resolved_world() -> None:
    info, world = parse(answer(), "test"), World.resolve(scenario())
    assert (info.name, info.seed, info.dt_s, info.duration_s, info.ticks) == (
        "info",
        5,
        0.01,
        2.0,
        200,
    )
    assert info.limits == world.clock_limits
    assert info.participants == tuple(world.participants)
    assert info.external == ("watcher", "stack")
    assert dict(info.roster) == ROSTER.fixed
    assert info.body_ids == world.body_ids
    assert info.traffic == ("boat_000", "boat_001") and list(info.vessels) == ["ego", "other"]
    assert [(b.id, b.row, b.x_m, b.y_m) for b in info.buoys] == [("b1", 4, 30.0, -5.0)]
    assert info.states_stream() == world.streams.states  # key, producer, period, stamp
    assert info.granted == -1 and info.scenario["name"] == "info"


def test_start_states_are_the_worlds() -> None:
    info, world = parse(answer(), "test"), World.resolve(scenario())
    start, expected = info.start, world.start_states()
    assert start.ids == expected.ids and start.tick == -1
    for got, want in zip(start.arrays(), expected.arrays(), strict=True):
        np.testing.assert_array_equal(got, want)


def test_a_vessel_its_controller_and_sensors() -> None:
    ego = parse(answer(), "test").vessels["ego"]
    assert (ego.model, ego.row, ego.thrusters, ego.command) == ("catabot", 0, 2, "twist")
    assert ego.controller is not None
    assert (ego.controller.participant, ego.controller.period_ticks) == ("stack", 5)
    control = ego.control_stream()
    assert control is not None and control.message is TwistCmd and control.producer == "stack"
    assert control.key == "catabot/info/vessel/ego/cmd/twist" and control.period == 5
    lidar = ego.sensor("lidar")
    assert (lidar.type, lidar.rate_hz, lidar.period_ticks, lidar.message) == (
        "lidar",
        10.0,
        10,
        LidarScan,
    )
    assert lidar.frame == "ego/lidar" and lidar.key == "catabot/info/sensor/ego/lidar"
    assert lidar.mount_xyz == (0.5, 0.0, 1.5)
    assert lidar.mount_rpy == pytest.approx((0.0, -10 * DEG, 90 * DEG))
    assert lidar.params["channels"] == 32  # every default filled in
    assert ego.sensor("gps").stream().producer == "sensors"
    with pytest.raises(UnknownSensor, match="no sensor 'radar'; its sensors: gps, lidar"):
        ego.sensor("radar")
    other = parse(answer(), "test").vessels["other"]
    assert other.controller is None and other.control_stream() is None and other.sensors == {}


def _without(data: dict[str, Any], *path: str) -> dict[str, Any]:
    node = data
    for key in path[:-1]:
        node = node[key]
    del node[path[-1]]
    return data


@pytest.mark.parametrize(
    ("spoil", "why"),
    [
        (lambda d: d.update(v=2), "layout version 2"),
        (lambda d: _without(d, "clock"), "KeyError 'clock'"),
        (lambda d: d["vessels"][0]["controller"].update(command="fly"), "command 'fly'"),
        (lambda d: d["vessels"][0]["sensors"][0].update(message="nope"), "KeyError 'nope'"),
        (lambda d: d.update(bodies="x"), "TypeError"),
        (lambda d: d["clock"].update(ticks="many"), "ValueError"),
        (lambda d: d["clock"].update(deadline_s=0), "deadline_s 0.0: must be a finite number > 0"),
        (lambda d: d["clock"].update(deadline_s=None), "TypeError"),
        (lambda d: d["roster"].update(physics="0xZZ"), "RosterError zid '0xZZ' is not"),
    ],
)
def test_a_malformed_answer_is_a_clear_error(spoil: Any, why: str) -> None:
    data = answer()
    spoil(data)
    with pytest.raises(
        ClientError, match=f"malformed world info from catabot/info/world/info: .*{why}"
    ):
        parse(data, "catabot/info/world/info")


def test_start_states_off_rest_and_sharded_producers_are_the_worlds() -> None:
    data = scenario().model_dump(mode="json")
    data["vessels"][0]["pose"] |= {"z_m": 0.3, "roll_rad": 0.1, "pitch_rad": -0.05}
    data["vessels"][0]["velocity"] = {"surge_mps": 1.5, "yaw_rate_radps": 0.2}
    data["sensors"] = {"shards": 2}
    world = World.resolve(parse_scenario(data))
    info = parse(describe(world, ROSTER), "test")
    for got, want in zip(info.start.arrays(), world.start_states().arrays(), strict=True):
        np.testing.assert_array_equal(got, want)
    producers = {s.key: s.producer for v in info.vessels.values() for s in v.sensors.values()}
    assert producers == world.sensor_owners and set(producers.values()) == {
        "sensors.0",
        "sensors.1",
    }


def test_a_free_stack_is_told_when_the_run_is_not_paced_to_the_wall_clock() -> None:
    """A 10 Hz free stack beside a run at 7.6x real time sent 34 commands in 30 simulated
    seconds and took its boat over late, and nothing said why."""
    fast = parse(answer(), "test")
    assert "runs as fast as it can (no clock.realtime_factor)" in unpaced(fast)
    assert "--realtime 1" in unpaced(fast)
    paced = parse(describe(World.resolve(scenario(clock={"realtime_factor": 1.0})), ROSTER), "t")
    assert unpaced(paced) == ""


def test_no_participant_named_is_the_worlds_only_controller_seat() -> None:
    """`run_lockstep(None, step)` on a one-stack world failed: "vessel None has no
    controller participant"; with no vessel named, the world's only seat is taken."""
    info = parse(answer(), "test")
    assert _controller_of(info, None) == "stack" and _controller_of(info, "ego") == "stack"
    with pytest.raises(NotAParticipant, match="vessel 'other' of world 'info' has no controller"):
        _controller_of(info, "other")
    seats = [{"id": v, "controller": {"participant": f"{v}_stack"}} for v in ("a", "b")]
    two = parse_scenario({"name": "two", "vessels": seats}, source="test")
    data = describe(World.resolve(two), ROSTER)
    with pytest.raises(NotAParticipant, match="has 2 controller participants, not one"):
        _controller_of(parse({**data, "granted": -1}, "test"), None)
