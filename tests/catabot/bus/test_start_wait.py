"""A participant's wait for tick 0 (catabot/bus/start_wait.py): it asks the conductor's
world/info for the scenario digest, and believes only the conductor's own session."""

from __future__ import annotations

import json
import queue
import time
from typing import Any

import pytest
import zenoh

from catabot.bus import start_wait
from catabot.bus.clock import CONDUCTOR
from catabot.bus.identity import Roster
from catabot.bus.start_wait import StartWait, digest_in
from tests.catabot.bus.lockstep_world import World


def _answer(session: zenoh.Session, key: str, digest: str) -> zenoh.Queryable[None]:
    body = json.dumps({"v": 1, "clock": {"digest": digest}})
    return session.declare_queryable(key, lambda query: query.reply(key, body))


def _waiter(world: World, roster: Roster) -> tuple[StartWait, queue.SimpleQueue[Any]]:
    events: queue.SimpleQueue[Any] = queue.SimpleQueue()
    waiter = StartWait(world.open(), world.keys, "physics", roster=roster, events=events,
                       digest="aaaaaaaaaaaa")  # fmt: skip
    return waiter, events


def _heard(events: queue.SimpleQueue[Any], wait_s: float = 2.0) -> list[Any]:
    time.sleep(wait_s)
    got = []
    while not events.empty():
        got.append(events.get())
    return got


def _asked_until_told(waiter: StartWait, events: queue.SimpleQueue[Any]) -> Any:
    """The first event, asking again every second as the notes do: a queryable declared
    a moment ago may not have reached the asker's router yet (a loaded CI machine), and
    one fixed wait lost the answer."""
    for _ in range(30):
        waiter.idle(set())
        try:
            return events.get(timeout=1.0)
        except queue.Empty:
            continue
    raise AssertionError("no answer in 30 s")


def test_the_conductors_other_digest_is_told_and_a_strangers_is_not(
    world: World, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(start_wait, "NOTE_EVERY_S", 0.0)
    key = world.keys.world_info()
    stranger = world.open()
    keep = [_answer(stranger, key, "ffffffffffff")]  # anyone may declare the queryable
    roster = Roster({CONDUCTOR: str(world.conductor_session.zid())})
    waiter, events = _waiter(world, roster)
    waiter.idle(set())
    assert _heard(events) == []  # the stranger's answer, not the conductor's
    keep.append(_answer(world.conductor_session, key, "bbbbbbbbbbbb"))
    assert _asked_until_told(waiter, events) == ("digest", "", b"bbbbbbbbbbbb", "")


def test_the_same_digest_or_no_conductor_yet_is_no_news(
    world: World, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(start_wait, "NOTE_EVERY_S", 0.0)
    keep = _answer(world.conductor_session, world.keys.world_info(), "aaaaaaaaaaaa")
    waiter, events = _waiter(world, Roster())  # the conductor's token not seen yet
    waiter.idle(set())
    waiter.roster.bind(CONDUCTOR, str(world.conductor_session.zid()))
    waiter.idle(set())
    assert _heard(events) == [] and keep is not None


@pytest.mark.parametrize(
    "payload", [b"", b"not json", b"[]", b'{"clock": 3}', b'{"clock": {"digest": 7}}']
)
def test_a_malformed_answer_has_no_digest(payload: bytes) -> None:
    assert digest_in(payload) == ""
