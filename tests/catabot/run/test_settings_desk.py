"""The conductor's settings desk over a real Zenoh session: answers, changes on the clock,
and refusals (an unknown key, a bad value, junk payloads) that leave the schedule alone."""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Any

import pytest
import zenoh

from catabot.bus.keys import Keys
from catabot.bus.session import Connection, free_port, open_session
from catabot.bus.settings import Schedule
from catabot.config.load import parse_scenario
from catabot.run.settings_cli import _due
from catabot.run.settings_desk import MAX_QUERY_BYTES, SettingsDesk

KEYS = Keys("desk")


@pytest.fixture
def desk() -> Iterator[tuple[SettingsDesk, zenoh.Session]]:
    scenario = parse_scenario({"name": "desk", "duration_s": 1.0, "vessels": [{"id": "ego"}]},
                              source="test")  # fmt: skip
    session = open_session(Connection(listen=(f"tcp/127.0.0.1:{free_port()}",)))
    schedule = Schedule(ticks=scenario.ticks)
    schedule.grant(9)
    desk = SettingsDesk(session, KEYS, scenario, schedule)
    try:
        yield desk, session
    finally:
        desk.close()
        session.close()


def _ask(session: zenoh.Session, key: str, payload: bytes | str | None = None) -> tuple[bool, Any]:
    replies = list(session.get(key, payload=payload, timeout=2.0))
    assert len(replies) == 1
    reply = replies[0]
    if reply.ok is not None:
        return True, json.loads(reply.ok.payload.to_bytes())
    assert reply.err is not None
    return False, json.loads(reply.err.payload.to_bytes())["error"]


def test_get_and_set(desk: tuple[SettingsDesk, zenoh.Session]) -> None:
    d, session = desk
    ok, answer = _ask(session, "catabot/*/config/settings")
    assert ok and answer["world"] == "desk" and answer["settings"]["rain"] == 0.0
    ok, done = _ask(session, KEYS.config("set"), json.dumps({"key": "rain", "value": 25}))
    assert ok and done == {"key": "rain", "value": 25.0, "tick": 10, "t_s": 0.1}
    answer = _ask(session, KEYS.config("settings"))[1]
    assert answer["settings"]["rain"] == 25.0 and answer["now"]["rain"] == 0.0  # not yet
    assert _due(answer, "rain") == "; 25.0 from t = 0.1 s" and _due(answer, "current") == ""
    assert d.schedule.grant(10) == ('[10,"rain","25.0"]',)
    assert _ask(session, KEYS.config("settings"))[1]["now"]["rain"] == 25.0


@pytest.mark.parametrize(
    ("key", "payload", "why"),
    [
        ("set", json.dumps({"key": "snow", "value": 1}), "unknown setting 'snow'"),
        ("set", json.dumps({"key": "rain", "value": -1}), "from 0 to 50"),
        (
            "set",
            json.dumps({"key": "rain"}),
            'a set takes a JSON object {"key": ..., "value": ...}',
        ),
        ("set", json.dumps([1, 2]), "a set takes a JSON object"),
        ("set", b"\xff\xfe", "not JSON"),
        ("set", "[" * 100_000, "bytes; at most"),
        ("set", "{" * 3000, "not JSON"),
        ("set", None, "not JSON"),
        ("other", None, "no such settings query"),
    ],
)
def test_refusals_change_nothing(
    desk: tuple[SettingsDesk, zenoh.Session], key: str, payload: Any, why: str
) -> None:
    d, session = desk
    ok, error = _ask(session, KEYS.config(key), payload)
    assert not ok and why in error
    assert d.schedule.in_force() == [] and sum(d.rejections.totals.values()) == 1
    assert MAX_QUERY_BYTES < 100_000


def test_a_wildcard_query_gets_the_settings_on_their_own_key(
    desk: tuple[SettingsDesk, zenoh.Session],
) -> None:
    """`catabot/**` made the desk reply on `config/**`, which Zenoh refused: no answer."""
    _, session = desk
    replies = list(session.get("catabot/**", timeout=2.0))
    assert len(replies) == 1 and replies[0].ok is not None
    assert str(replies[0].ok.key_expr) == KEYS.config("settings")
    assert json.loads(replies[0].ok.payload.to_bytes())["world"] == "desk"


def test_a_drawn_boat_shows_its_planned_behaviour_once_the_plan_is_known() -> None:
    """`catabot get` showed every drawn boat as "as planned"; the world info desk resolves
    the plan on its own thread, and from then on the desk shows what each boat was drawn."""
    traffic = {"count": 2, "boats": [{"index": 1, "behaviour": "hold"}]}
    data = {"name": "desk", "duration_s": 1.0, "vessels": [{"id": "ego"}], "traffic": traffic}
    scenario = parse_scenario(data, source="test")
    session = open_session(Connection(listen=(f"tcp/127.0.0.1:{free_port()}",)))
    plan: dict[str, str] = {}
    desk = SettingsDesk(
        session, KEYS, scenario, Schedule(ticks=scenario.ticks), planned=lambda: plan
    )
    try:
        shown = desk.in_force()["settings"]
        assert shown["traffic.boat_000.behaviour"] == "as planned"
        plan.update({"boat_000": "circle", "boat_001": "hold"})
        shown = desk.in_force()["settings"]
        assert (shown["traffic.boat_000.behaviour"], shown["traffic.boat_001.behaviour"]) == (
            "circle", "hold")  # fmt: skip
    finally:
        desk.close()
        session.close()
