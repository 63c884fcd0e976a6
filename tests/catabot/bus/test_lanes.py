"""Lanes by sender (catabot/bus/lanes.py): the run's own events in order, a stranger's
bounded and served in turn within a budget, so a flood cannot hold a tick behind it."""

from __future__ import annotations

import queue

import pytest

from catabot.bus import lanes
from catabot.bus.lanes import Event, Lanes

RUN = {"conductor-zid", "physics-zid"}
KNOWN: set[str] = set()  # the roster, as the last `_lanes()` made it


def _lanes() -> Lanes:
    KNOWN.clear()
    KNOWN.update(RUN)
    return Lanes(trusted=KNOWN.__contains__)


def _data(sender: str, n: int = 0, size: int = 1) -> Event:
    return ("data", f"cmd/{n}", b"x" * size, sender)


def _drain(events: Lanes) -> list[Event]:
    out = []
    while True:
        try:
            out.append(events.get(timeout=0.01))
        except queue.Empty:
            return out


def test_the_runs_own_events_keep_their_order_and_a_strangers_wait_for_a_gap() -> None:
    events = _lanes()
    events.put(_data("stranger", 0))
    for n in range(3):
        events.put(_data("physics-zid", n))
    got = _drain(events)
    assert [e[3] for e in got] == ["physics-zid"] * 3 + ["stranger"]
    assert [e[1] for e in got[:3]] == ["cmd/0", "cmd/1", "cmd/2"]


def test_a_flood_gets_one_event_in_every_few_of_the_runs_own() -> None:
    events = _lanes()
    for n in range(20):
        events.put(_data("flooder", n))
    for n in range(12):
        events.put(_data("physics-zid", n))
    senders = [e[3] for e in _drain(events)[:15]]
    assert senders == (["physics-zid"] * lanes.EVERY + ["flooder"]) * 3


def test_strangers_take_turns() -> None:
    events = _lanes()
    for n in range(3):
        events.put(_data("flooder", n))
    events.put(_data("client", 0))
    assert [e[3] for e in _drain(events)] == ["flooder", "client", "flooder", "flooder"]


def test_a_strangers_lane_is_bounded_and_the_overflow_counted() -> None:
    events = _lanes()
    for n in range(lanes.LANE_EVENTS + 10):
        events.put(_data("flooder", n))
    assert not events.admits("data", "flooder", 1)
    assert events.admits("data", "physics-zid", 1)  # the run's own: never refused
    assert events.take_dropped() == {"flooder": (10, f"cmd/{lanes.LANE_EVENTS + 9}")}
    assert events.take_dropped() == {}  # reported once
    assert len(_drain(events)) == lanes.LANE_EVENTS


def test_a_lane_is_bounded_in_bytes_too() -> None:
    events = _lanes()
    size = lanes.LANE_BYTES // 4
    for n in range(5):
        events.put(_data("flooder", n, size))
    assert events.take_dropped() == {"flooder": (1, "cmd/4")}


def test_senders_beyond_the_lanes_limit_are_dropped() -> None:
    events = _lanes()
    for n in range(lanes.LANES + 2):
        events.put(_data(f"s{n}"))
    assert sorted(events.take_dropped()) == [f"s{lanes.LANES}", f"s{lanes.LANES + 1}"]


def test_lanes_wait_once_their_budget_is_spent_and_the_runs_events_do_not() -> None:
    events = _lanes()
    for n in range(3):
        events.put(_data("flooder", n))
    first = events.get(timeout=0.01)
    events.spent(first, lanes.BUDGET)  # a tenth of this second spent on it
    with pytest.raises(queue.Empty):
        events.get(timeout=0.05)
    events.put(_data("physics-zid"))
    assert events.get(timeout=0.05)[3] == "physics-zid"
    events.spent(_data("flooder"), 5.0)  # not an event the lanes served: not counted
    assert events.get(timeout=1.5)[3] == "flooder"  # the next second's budget


def test_a_sender_that_joins_has_its_laned_events_first_in_order() -> None:
    events = _lanes()
    events.put(_data("late-zid", 0))
    events.put(_data("late-zid", 1))
    events.put(_data("physics-zid", 9))
    KNOWN.add("late-zid")  # its token, seen: the roster binds it
    events.joined("late-zid")
    events.put(_data("late-zid", 2))  # trusted now: on the run's FIFO
    got = [(e[3], e[1]) for e in _drain(events)]
    assert got == [("late-zid", "cmd/0"), ("late-zid", "cmd/1"), ("physics-zid", "cmd/9"),
                   ("late-zid", "cmd/2")]  # fmt: skip


def test_a_sleeping_reader_wakes_for_a_strangers_event() -> None:
    events = _lanes()
    events.put(_data("client"))
    assert events.get(timeout=0.5)[3] == "client"  # the poke woke it, and is never handed out
    with pytest.raises(queue.Empty):
        events.get(timeout=0.05)
    assert events.empty()


def test_the_processes_own_events_go_first_whatever_their_sender() -> None:
    events = _lanes()
    events.put(("stop", "", b"", ""))
    events.put(("join", "live/x/zid", b"", ""))
    assert [e[0] for e in _drain(events)] == ["stop", "join"]
    assert events.take_dropped() == {}
