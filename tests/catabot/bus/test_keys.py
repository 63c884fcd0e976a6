"""Every key of a world is built in one place, as DESIGN.md §3 spells it."""

from __future__ import annotations

import pytest

from catabot.bus.keys import KeyNameError, Keys, check_name

BAD_NAMES = ["a/b", "*", "a*", "**", "$x", "a$", "a b", " ", "", "a?b", "a#b"]


def test_every_builder_matches_the_design_table() -> None:
    k = Keys("harbour")
    assert k.prefix == "catabot/harbour"
    assert k.all() == "catabot/harbour/**"
    assert k.tick() == "catabot/harbour/clock/tick"
    assert k.ack("physics") == "catabot/harbour/clock/ack/physics"
    assert k.acks() == "catabot/harbour/clock/ack/*"
    assert k.end() == "catabot/harbour/clock/end"
    assert k.live("sensors", "a1b2") == "catabot/harbour/live/sensors/a1b2"
    assert k.lives() == "catabot/harbour/live/*/*"
    assert k.vessel_state("ego") == "catabot/harbour/vessel/ego/state"
    assert k.vessel_states() == "catabot/harbour/vessel/*/state"
    assert k.cmd_thrust("ego") == "catabot/harbour/vessel/ego/cmd/thrust"
    assert k.cmd_twist("ego") == "catabot/harbour/vessel/ego/cmd/twist"
    assert k.cmd_waypoints("ego") == "catabot/harbour/vessel/ego/cmd/waypoints"
    assert k.cmds() == "catabot/harbour/vessel/*/cmd/*"
    assert k.sensor("ego", "imu") == "catabot/harbour/sensor/ego/imu"
    assert k.env_state() == "catabot/harbour/env/state"
    assert k.config("rain") == "catabot/harbour/config/rain"


def test_allowed_name_characters() -> None:
    for name in ("ego", "robot_0", "boat-12", "v1.2", "A_b-C.9"):
        assert check_name("vessel", name) == name
        assert Keys(name).vessel_state(name) == f"catabot/{name}/vessel/{name}/state"


@pytest.mark.parametrize("name", BAD_NAMES)
def test_world_name_refused(name: str) -> None:
    with pytest.raises(KeyNameError, match=r"^world name .* is not allowed in a key"):
        Keys(name)


@pytest.mark.parametrize("name", BAD_NAMES)
@pytest.mark.parametrize(
    ("kind", "build"),
    [
        ("vessel", lambda k, n: k.vessel_state(n)),
        ("vessel", lambda k, n: k.cmd_thrust(n)),
        ("vessel", lambda k, n: k.cmd_twist(n)),
        ("vessel", lambda k, n: k.cmd_waypoints(n)),
        ("vessel", lambda k, n: k.sensor(n, "imu")),
        ("sensor", lambda k, n: k.sensor("ego", n)),
        ("participant", lambda k, n: k.ack(n)),
        ("participant", lambda k, n: k.live(n, "a1b2")),
        ("config", lambda k, n: k.config(n)),
    ],
)
def test_chunk_names_refused_naming_the_kind(name: str, kind: str, build) -> None:
    with pytest.raises(KeyNameError) as info:
        build(Keys("w"), name)
    msg = str(info.value)
    assert msg.startswith(f"{kind} name {name!r}")
    assert "letters, digits" in msg


def test_non_string_name_refused() -> None:
    with pytest.raises(KeyNameError, match="vessel name 3"):
        check_name("vessel", 3)  # type: ignore[arg-type]


def test_key_error_is_a_value_error() -> None:
    assert issubclass(KeyNameError, ValueError)


def test_relative() -> None:
    k = Keys("w")
    assert k.relative(k.sensor("ego", "gps")) == "sensor/ego/gps"
    assert k.relative(k.tick()) == "clock/tick"
    with pytest.raises(KeyNameError, match=r"not in world 'w'"):
        k.relative("catabot/other/clock/tick")
    with pytest.raises(KeyNameError, match="not in world"):
        k.relative("catabot/w")  # the prefix alone is not a key of the world
    with pytest.raises(KeyNameError, match="not in world"):
        k.relative("catabot/ww/clock/tick")  # a world whose name merely starts the same


def test_participant_of() -> None:
    k = Keys("w")
    assert k.participant_of(k.ack("physics")) == "physics"
    assert k.member_of(k.live("recorder", "a1b2")) == ("recorder", "a1b2")
    assert k.member_of(k.live("conductor", "ff")) == ("conductor", "ff")
    with pytest.raises(KeyNameError, match="not a liveliness token"):
        k.member_of(k.ack("physics"))


def test_vessel_of_reads_the_vessel_id_back_from_a_key() -> None:
    keys = Keys("w")
    assert keys.vessel_of(keys.cmd_twist("boat_007")) == "boat_007"
    assert keys.vessel_of(keys.sensor("ego", "lidar")) == "ego"
    with pytest.raises(KeyNameError, match="names no vessel"):
        keys.vessel_of(keys.tick())
