"""Run-time setting changes on the clock (catabot/bus/settings.py, DESIGN.md §4): scheduled
above every grant, carried by the grant, handed to each participant's step of their tick."""

from __future__ import annotations

import threading
import time

import pytest

from catabot.bus import codec
from catabot.bus.clock import Stream
from catabot.bus.identity import Roster, new_zid
from catabot.bus.inbox import Inbox, Inputs
from catabot.bus.messages import GpsFix, Tick
from catabot.bus.settings import (
    MAX_PER_TICK,
    Change,
    Schedule,
    SettingsError,
    changes_of,
    from_wire,
)
from tests.catabot.bus.lockstep_world import DT_NS, World, _fix


def test_a_grant_carries_the_changes_of_the_ticks_it_adds() -> None:
    schedule = Schedule([Change(0, "rain", "1.0"), Change(5, "rain", "2.0"), Change(99, "x", "0")],
                        ticks=10)  # fmt: skip
    assert [from_wire(t).tick for t in schedule.grant(3)] == [0]
    assert schedule.grant(3) == ()  # a repeat of a grant carries nothing again
    assert [from_wire(t).value for t in schedule.grant(9)] == ["2.0"]
    assert [c.tick for c in schedule.applied()] == [0, 5]  # tick 99 is past the run
    assert [c.tick for c in schedule.asked()] == [0, 5, 99]  # as the scenario asked


def test_a_live_change_lands_above_every_grant() -> None:
    schedule = Schedule(ticks=100)
    schedule.grant(39)
    change = schedule.propose("rain", "25.0")
    assert change.tick == 40
    assert changes_of(schedule.grant(45)) == [change]
    assert schedule.propose("rain", "0.0").tick == 46


def test_changes_are_refused_when_too_many_or_too_late() -> None:
    schedule = Schedule(ticks=10)
    for _ in range(MAX_PER_TICK):
        schedule.propose("rain", "1.0")
    with pytest.raises(SettingsError, match="already wait for tick 0"):
        schedule.propose("rain", "1.0")
    schedule.grant(9)
    with pytest.raises(SettingsError, match="the run is ending"):
        schedule.propose("rain", "1.0")


@pytest.mark.parametrize(
    "text", ["", "[1, 2]", '[1.5, "k", "1"]', '[1, "k", "not json"]', "x" * 5000]
)
def test_malformed_changes_are_refused(text: str) -> None:
    with pytest.raises(ValueError):
        from_wire(text)


def test_every_participant_steps_each_change_at_its_tick(world: World) -> None:
    names = ["physics", "sensors"]
    seen: dict[str, dict[int, list[str]]] = {n: {} for n in names}
    schedule = Schedule([Change(0, "rain", "1.0"), Change(7, "waves", '"heavy"')], ticks=60)
    proposed: list[Change] = []

    def stepper(name: str):  # type: ignore[no-untyped-def]
        def step(tick: Tick, _: Inputs) -> None:
            if tick.settings:
                seen[name][tick.tick] = [c.key for c in changes_of(tick.settings)]
            if name == "physics" and tick.tick == 20:  # a `catabot set` from another thread
                threading.Thread(
                    target=lambda: proposed.append(schedule.propose("rain", "5.0"))
                ).start()

        return step

    for name in names:
        world.member(name, stepper(name), peers=names)
    result = world.run(names, 60, settings=schedule, window_ticks=8, deadline_s=2.0)
    assert result.error == ""
    assert len(proposed) == 1 and proposed[0].tick > 20
    expected = {0: ["rain"], 7: ["waves"], proposed[0].tick: ["rain"]}
    assert seen["physics"] == seen["sensors"] == expected
    assert schedule.applied() == [
        Change(0, "rain", "1.0"),
        Change(7, "waves", '"heavy"'),
        proposed[0],
    ]


@pytest.mark.parametrize("key", ["waves", "rain"])
def test_a_slow_change_has_its_grace_past_the_deadline(world: World, key: str) -> None:
    """A participant that takes 1.2 s over the tick carrying a change (a sea with waves:
    its kernels compile) keeps the run only where the change's grace covers it."""
    grace = {"waves": 3.0}
    schedule = Schedule([Change(5, key, '"x"')], ticks=12, grace_s=lambda k: grace.get(k, 0.0))
    assert schedule.grace(0, 4) == 0.0 and schedule.grace(5, 5) == grace.get(key, 0.0)

    def step(tick: Tick, _: Inputs) -> None:
        if tick.settings:
            time.sleep(1.2)

    world.member("sensors", step)
    result = world.run(["sensors"], 12, settings=schedule, deadline_s=0.6)
    if key == "waves":
        assert result.error == "" and result.ticks_done == 12
    else:
        assert "missed the 0.6 s deadline of tick 5" in result.error


def test_a_switched_off_stream_is_not_waited_for() -> None:
    stream = Stream("k/gps", GpsFix, "sensors", period=10)
    roster = Roster({"sensors": new_zid()})
    inbox = Inbox([stream], roster=roster, dt_ns=DT_NS)
    inbox.add("k/gps", codec.encode(_fix(0)), sender=str(roster.zid("sensors")))
    inbox.switch("k/gps", 5, on=False)  # no samples tagged 5.. on
    assert inbox.missing(30) == []
    inbox.switch("k/gps", 25, on=True)  # tagged 30 is due again
    assert inbox.missing(31) == ["k/gps"]
    assert inbox.missing(30) == []  # 20 fell in the off span: back to 0, which came
